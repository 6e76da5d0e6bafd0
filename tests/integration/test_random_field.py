"""Tests of bench/random_field.py: every field of a range of seeds keeps its
class's rules, the same seed gives the same file, and a trap field holds
what its docstring promises (a trap of each kind across seeds, a dead end
open towards the start, a pop-up that appears only while no vehicle within
the speed limit can be near it, the longer time limit).

Needs PyYAML (Debian's /usr/bin/python3). Run from the repository root:
    /usr/bin/python3 -m unittest -v tests/integration/test_random_field.py
"""

import collections
import math
import os
import sys
import tempfile
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO_ROOT, "bench"))

import yaml  # noqa: E402

import random_field as rf  # noqa: E402

TRAP_SEEDS = range(1, 121)


class FieldRules(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tpl = rf.load_template(rf.DEFAULT_TEMPLATE)

    def test_fair_and_dense_fields_keep_their_rules(self):
        for seed in range(1, 21):
            obstacles, _ = rf.generate(seed, self.tpl)
            self.assertEqual(rf.rule_violations(obstacles, self.tpl), [], seed)
        for seed in range(1, 4):  # dense fields take a second or so each to draw
            obstacles, _ = rf.generate_dense(seed, self.tpl)
            self.assertEqual(rf.dense_rule_violations(obstacles, self.tpl), [], seed)

    def test_trap_fields_keep_their_rules(self):
        kinds = collections.Counter()
        popups = 0
        for seed in TRAP_SEEDS:
            obstacles, _ = rf.generate_trap(seed, self.tpl)
            walls = [o for o in obstacles if "trap" in o]
            self.assertGreater(len(walls), 0, seed)
            # The trap's walls come first; the rest is clutter and the pop-up.
            self.assertEqual(obstacles[:len(walls)], walls, seed)
            self.assertEqual(rf.trap_rule_violations(obstacles, len(walls), self.tpl), [], seed)
            kind = walls[0]["trap"]
            kinds[kind] += 1
            self.assertEqual(len(walls), {"dead_end": 3, "pocket": 3}.get(kind, len(walls)), seed)
            if kind == "wide_wall":
                self.assertIn(len(walls), (1, 2), seed)
                reach = sum(w["size"][0] for w in walls)
                self.assertGreaterEqual(reach, rf.WIDE_WALL_LENGTH[0] - 2 * rf.WIDE_WALL_GAP[1], seed)
            clutter = len(obstacles) - len(walls)
            self.assertLessEqual(clutter, rf.TRAP_CLUTTER[1] + 1, seed)
            for ob in obstacles:
                if "appear_time" in ob:
                    popups += 1
                    self.assertNotIn("trap", ob)
                    self.assertGreaterEqual(ob["appear_time"], 1.0)
                    self.assertLessEqual(ob["appear_time"], rf._popup_fair(ob, self.tpl) + 1e-9, seed)
        self.assertEqual(set(kinds), set(rf.TRAP_KINDS))
        for kind in rf.TRAP_KINDS:
            self.assertGreater(kinds[kind], len(TRAP_SEEDS) // 6, kinds)
        self.assertGreater(popups, len(TRAP_SEEDS) // 6)
        self.assertLess(popups, len(TRAP_SEEDS) // 2)

    def test_a_dead_end_opens_towards_the_start(self):
        seen = 0
        for seed in TRAP_SEEDS:
            obstacles, _ = rf.generate_trap(seed, self.tpl)
            if obstacles[0]["trap"] not in ("dead_end", "pocket"):
                continue
            seen += 1
            back, left, right = obstacles[:3]
            # The side walls reach from the back wall towards the start: their
            # middles lie on the start's side of the back wall, the depth
            # (less half a wall) from it, and the mouth is open (it faces the
            # start within the turn allowed).
            yaw = math.radians(back["yaw_deg"])
            into = (math.sin(yaw), -math.cos(yaw))  # normal to the back wall ...
            if into[0] < 0:
                into = (-into[0], -into[1])  # ... pointing away from the start
            self.assertLessEqual(math.degrees(math.acos(into[0])), rf.TRAP_MAX_TURN_DEG + 0.2, seed)
            depth = rf.TRAP_POCKET_DEPTH if obstacles[0]["trap"] == "pocket" else rf.TRAP_DEPTH
            for side in (left, right):
                behind = ((back["center"][0] - side["center"][0]) * into[0]
                          + (back["center"][1] - side["center"][1]) * into[1])
                self.assertGreaterEqual(behind, 0.5 * depth[0] - 0.2, seed)
                self.assertLessEqual(behind, 0.5 * depth[1] + 0.2, seed)
            # Inside: the two side walls' centres are the width plus a wall apart.
            apart = math.hypot(left["center"][0] - right["center"][0],
                               left["center"][1] - right["center"][1])
            wide = rf.TRAP_DEAD_END_WIDTH if obstacles[0]["trap"] == "dead_end" else rf.TRAP_POCKET_WIDTH
            self.assertGreaterEqual(apart, wide[0] + rf.TRAP_WALL_THICKNESS[0] - 0.2, seed)
            self.assertLessEqual(apart, wide[1] + rf.TRAP_WALL_THICKNESS[1] + 0.2, seed)
            # The back wall closes the corners: it reaches the side walls' outer faces.
            self.assertGreaterEqual(back["size"][0], apart + min(left["size"][1], right["size"][1]) - 0.2,
                                    seed)
        self.assertGreater(seen, 0)

    def test_the_same_seed_writes_the_same_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            for kind in ("fair", "trap"):
                a, b = os.path.join(tmp, kind + "-a.yaml"), os.path.join(tmp, kind + "-b.yaml")
                rf.write_field(7, a, kind=kind)
                rf.write_field(7, b, kind=kind)
                with open(a) as fa, open(b) as fb:
                    self.assertEqual(fa.read(), fb.read(), kind)

    def test_out_and_back_adds_the_way_home_to_the_same_field(self):
        with tempfile.TemporaryDirectory() as tmp:
            for kind in ("fair", "dense", "trap"):
                one, both = os.path.join(tmp, kind + "-out.yaml"), os.path.join(tmp, kind + "-back.yaml")
                rf.write_field(11, one, kind=kind)
                rf.write_field(11, both, kind=kind, both_ways=True)
                with open(one) as f:
                    out = yaml.safe_load(f)
                with open(both) as f:
                    back = yaml.safe_load(f)
                self.assertEqual(back["obstacles"], out["obstacles"], kind)
                self.assertEqual(back["waypoints"][:-1], out["waypoints"], kind)
                self.assertEqual(len(back["waypoints"]), len(out["waypoints"]) + 1, kind)
                home = back["waypoints"][-1]
                self.assertEqual(home["position"], out["waypoints"][0]["position"], kind)
                self.assertEqual(home["capture_radius"], out["waypoints"][-1]["capture_radius"], kind)
                self.assertEqual(back["max_time"], 2 * out["max_time"], kind)
                self.assertEqual(back["name"], out["name"] + "-out-and-back", kind)
                for key in ("start", "limits", "gates"):
                    self.assertEqual(back[key], out[key], kind)

    def test_wind_and_turbulence_blow_over_the_same_field(self):
        directions = set()
        with tempfile.TemporaryDirectory() as tmp:
            for seed in (3, 5, 9):
                calm, windy = os.path.join(tmp, "calm.yaml"), os.path.join(tmp, "windy.yaml")
                rf.write_field(seed, calm, kind="fair")
                rf.write_field(seed, windy, kind="fair", wind_kt=15, turbulence="moderate")
                with open(calm) as f:
                    out = yaml.safe_load(f)
                with open(windy) as f:
                    blown = yaml.safe_load(f)
                # The weather draws from a stream of its own: the same obstacles.
                self.assertEqual(blown["obstacles"], out["obstacles"], seed)
                self.assertNotIn("environment", out)
                self.assertNotIn("disturbances", out)
                wx, wy, wh = blown["environment"]["wind"]
                self.assertAlmostEqual(math.hypot(wx, wy), 15 * 1.6878099, delta=0.02)  # ft/s
                self.assertEqual(wh, 0)
                directions.add(round(math.degrees(math.atan2(wy, wx))))
                self.assertEqual(blown["disturbances"], {"turbulence": "moderate", "seed": seed})
                self.assertEqual(blown["name"], out["name"] + "-wind")
        self.assertEqual(len(directions), 3)  # the direction comes from the seed

    def test_a_trap_file_is_a_scenario_with_its_pop_up_and_time_limit(self):
        with tempfile.TemporaryDirectory() as tmp:
            seed = next(s for s in TRAP_SEEDS
                        if any("appear_time" in o for o in rf.generate_trap(s, self.tpl)[0]))
            path = os.path.join(tmp, "trap.yaml")
            obstacles = rf.write_field(seed, path, kind="trap")
            with open(path) as f:
                scenario = yaml.safe_load(f)
            self.assertEqual(scenario["name"], "trap-%d" % seed)
            self.assertEqual(scenario["max_time"], rf.TRAP_MAX_TIME)
            self.assertEqual(len(scenario["obstacles"]), len(obstacles))
            timed = [o for o in scenario["obstacles"] if "appear_time" in o]
            self.assertEqual(len(timed), 1)
            self.assertEqual(timed[0]["appear_time"],
                             next(o["appear_time"] for o in obstacles if "appear_time" in o))
            for key in ("start", "waypoints", "limits", "gates"):
                self.assertEqual(scenario[key], self.tpl[key])


if __name__ == "__main__":
    unittest.main()
