"""Tests of the flight figures: services/tools/plot_flight.py and the course
figure of bench/campaign_report.py, on small synthetic results folders
written here with the column names of services/tools/src/flight_report.cpp.

What they check: the command traces leave out the samples before the
controller engages (CONTROL_STATUS mode HOLD); the top view is framed on
the obstacles and the flown path, at equal scale, and not on a far LIDAR
ground hit; LIDAR hits lie under the cuboid outlines; the clearance panel
shows the true clearance with lines at R_s and 0.8 R_s; the verdict is in
the title; every axis label names its unit.

Needs numpy and matplotlib (Debian's /usr/bin/python3). Run from the
repository root:
    /usr/bin/python3 -m unittest -v tests/integration/test_plot_flight.py
"""

import json
import math
import os
import re
import subprocess
import sys
import tempfile
import unittest

REPO_ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
PLOT_FLIGHT = os.path.join(REPO_ROOT, "services", "tools", "plot_flight.py")
sys.path.insert(0, os.path.join(REPO_ROOT, "services", "tools"))
sys.path.insert(0, os.path.join(REPO_ROOT, "bench"))

import numpy as np  # noqa: E402
import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import Rectangle  # noqa: E402

import plot_flight as pf  # noqa: E402
import campaign_report as cr  # noqa: E402

FT = 0.3048  # metres per foot: the synthetic course is in feet, like the benchmarks
ENGAGE_T = 1.0  # s: HOLD before, WAYPOINT from here
DONE_T = 19.0  # s: DONE from here
SPIKE = 5.0  # m/s^2: the pseudo-control of the hold (16.4 ft/s^2), the spike of the issue
RS = 6.096  # m: R_s = 20 ft
WALL = dict(id=1, kind="box", center=[50.0, 0.0], size=[2.0, 120.0], height=30.0, yaw=0.0,
            appear_time=-1, disappear_time=-1)  # 394 ft wide: beyond a +-80 ft frame
POLE = dict(id=2, kind="cylinder", center=[30.0, 20.0], size=[6.0, 6.0], height=40.0, yaw=0.0,
            appear_time=-1, disappear_time=-1)
# A low box under the approach: 8 m below the flight, the least clearance.
LOW = dict(id=3, kind="box", center=[5.0, 0.0], size=[4.0, 4.0], height=12.0, yaw=0.5,
           appear_time=-1, disappear_time=-1)
# A pop-up on the path at north 85 m (t = 15 s), gone at 5 s: it must not count.
GONE = dict(id=4, kind="cylinder", center=[85.0, 0.0], size=[4.0, 4.0], height=40.0, yaw=0.0,
            appear_time=2.0, disappear_time=5.0)
OBSTACLES = [WALL, POLE, LOW, GONE]
FAR_HIT_NORTH = 600.0  # m: a ground hit far past the goal (100 m)
ALTITUDE = 20.0  # m above the ground


def flown(t):
    """North, east, down (m) of the synthetic flight: along x at 7 m/s, round
    the wall's end (east -60 m) with 10 m to spare at the tip (t = 10 s)."""
    north = -20.0 + 7.0 * t
    east = np.where((north >= 20.0) & (north <= 80.0),
                    -70.0 * np.sin(np.pi * np.clip(north - 20.0, 0.0, 60.0) / 60.0), 0.0)
    return north, east, np.full_like(t, -ALTITUDE)


def clearance_by_hand(t, n, e, d):
    """Least distance (m) of one point at time t to the obstacles present
    then and to the ground."""
    h = -d
    wall = math.sqrt(max(abs(n - 50.0) - 1.0, 0.0) ** 2 + max(abs(e) - 60.0, 0.0) ** 2 +
                     max(abs(h - 15.0) - 15.0, 0.0) ** 2)
    radial = max(math.hypot(n - 30.0, e - 20.0) - 3.0, 0.0)
    pole = math.hypot(radial, max(h - 40.0, 0.0))
    c, s = math.cos(0.5), math.sin(0.5)  # the low box's yaw
    u, v = c * (n - 5.0) + s * e, -s * (n - 5.0) + c * e
    low = math.sqrt(max(abs(u) - 2.0, 0.0) ** 2 + max(abs(v) - 2.0, 0.0) ** 2 +
                    max(abs(h - 6.0) - 6.0, 0.0) ** 2)
    gone = math.hypot(max(math.hypot(n - 85.0, e) - 2.0, 0.0), max(h - 40.0, 0.0))
    present = 2.0 <= t < 5.0
    return min(wall, pole, low, gone if present else math.inf, max(h, 0.0))


def write_csv(path, header, rows):
    with open(path, "w") as f:
        f.write(",".join(header) + "\n")
        for row in rows:
            f.write(",".join(repr(float(v)) for v in row) + "\n")


def write_results(folder, min_clearance=None, outcome="failure"):
    """A results folder as the flight report writes it (SI, NED)."""
    t = np.round(np.arange(0.0, 20.0 + 1e-9, 0.05), 6)
    n, e, d = flown(t)
    vn = np.full_like(t, 7.0)
    ve = np.gradient(e, t)
    zero = np.zeros_like(t)
    an = 0.05 * np.sin(t)
    write_csv(os.path.join(folder, "nav_state.csv"),
              "t,north,east,down,vn,ve,vd,an,ae,ad,roll,pitch,yaw,p,q,r".split(","),
              zip(t, n, e, d, vn, ve, zero, an, np.gradient(ve, t), zero, zero, zero, zero,
                  zero, zero, zero))

    tc = t[1:] - 0.01
    mode = np.where(tc < ENGAGE_T, 0, np.where(tc < DONE_T, 1, 4))
    hold = mode == 0
    nc, ec, dc = flown(tc)
    ref_an = np.where(hold, -0.4, 0.3 * np.sin(tc))
    cmd_an = np.where(hold, SPIKE, 0.3 * np.sin(tc) + 0.25)
    cmd_ad = np.where(hold, -SPIKE, 0.1)
    zc = np.zeros_like(tc)
    write_csv(os.path.join(folder, "control_status.csv"),
              ("t,mode,mission_id,active_waypoint,ref_n,ref_e,ref_d,ref_vn,ref_ve,ref_vd,ref_an,"
               "ref_ae,ref_ad,cmd_an,cmd_ae,cmd_ad,err_n,err_e,err_d,yaw_ref").split(","),
              zip(tc, mode, zc + 1, zc + 1, nc, ec, dc, zc + 7.0, zc, zc, ref_an, zc, zc, cmd_an,
                  zc, cmd_ad, zc, zc, zc, zc))
    write_csv(os.path.join(folder, "waypoints.csv"),
              "index,north,east,down,capture_radius".split(","),
              [(0, -20.0, 0.0, -ALTITUDE, 3.0), (1, 120.0, 0.0, -ALTITUDE, 3.0)])
    # Hits on the wall's face and one on the ground far past the goal.
    hits = [(5.0, 49.0, east, -h) for east in (-20.0, 0.0, 20.0) for h in (5.0, 15.0, 25.0)]
    hits.append((9.0, FAR_HIT_NORTH, 0.0, 0.0))
    write_csv(os.path.join(folder, "scan_points.csv"), "t,north,east,down".split(","), hits)
    write_csv(os.path.join(folder, "cuboids.csv"),
              "t,id,min_n,min_e,min_d,max_n,max_e,max_d,top_observed,confidence".split(","),
              [(20.0, 1, 48.0, -40.0, -31.0, 52.0, 40.0, 0.0, 1, 1.0)])

    least = [clearance_by_hand(*p) for p in zip(t, n, e, d)]
    i = int(np.argmin(least))
    summary = {
        "scenario": "synthetic-wall", "display_unit": "ft", "metres_per_unit": FT,
        "limits": {"max_speed": 3.048 * 2.5, "max_accel": 0.5, "max_vertical_speed": 1.524},
        "gates": {"start_x": 0.0, "finish_x": 100.0},
        "gate_start_t": 20.0 / 7.0, "gate_finish_t": 120.0 / 7.0,
        "max_commanded_accel": 0.3, "pseudo_control_bound": {"horizontal": 5, "vertical": 3},
        "min_clearance": least[i] if min_clearance is None else min_clearance,
        "min_clearance_t": float(t[i]), "min_clearance_surface": "obstacle",
        "clearance_required": RS,
        "outcome": outcome, "success": outcome == "success",
        "failures": (["clearance (ft) below 0.8 R_s: 9.9 against 16",
                      "speed (ft/s) over the limit + 2 %: 23 against 20"]
                     if outcome == "failure" else []),
        "obstacles": [dict(ob) for ob in OBSTACLES],
    }
    with open(os.path.join(folder, "summary.json"), "w") as f:
        json.dump(summary, f, indent=1)
    return summary


def axes_named(fig, label):
    found = [ax for ax in fig.axes if ax.get_label() == label]
    if len(found) != 1:
        raise AssertionError("no single axes '%s' in %s"
                             % (label, [a.get_label() for a in fig.axes]))
    return found[0]


def lines_with_gid(ax, gid):
    return [line for line in ax.get_lines() if line.get_gid() == gid]


def obstacle_extents_ft():
    """(north low, north high, east low, east high) of every obstacle, ft."""
    out = []
    for ob in OBSTACLES:
        (n0, n1), (e0, e1) = pf.obstacle_extent(ob)
        out.append((n0 / FT, n1 / FT, e0 / FT, e1 / FT))
    return out


class FlightFigureTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-plot-test-")
        self.dir = self.tmp.name
        self.summary = write_results(self.dir)
        self.fig = pf.flight_figure(pf.load_results(self.dir))
        self.fig.canvas.draw()  # applies the equal aspect, as saving does

    def tearDown(self):
        plt.close(self.fig)
        self.tmp.cleanup()

    def test_command_traces_leave_out_the_hold_before_engagement(self):
        checked = 0
        for label, gids in (("a_x", ["reference"]), ("reference", ["reference"]),
                            ("pseudo-control", ["pseudo-control"])):
            ax = axes_named(self.fig, label)
            lines = [line for gid in gids for line in lines_with_gid(ax, gid)]
            self.assertTrue(lines, "no command trace in '%s'" % label)
            for line in lines:
                x, y = (np.asarray(v, dtype=float) for v in line.get_data())
                shown = np.isfinite(y)
                self.assertTrue(shown.any(), "'%s' shows nothing" % label)
                self.assertGreaterEqual(x[shown].min(), ENGAGE_T - 1e-9,
                                        "'%s' shows a sample of the hold" % label)
                self.assertLess(np.nanmax(np.abs(y)), 0.5 * SPIKE / FT)
                checked += 1
        self.assertGreaterEqual(checked, 4)
        # Each trace is the quantity it is named for.
        ctl = pf.load_csv(self.dir, "control_status.csv", True)
        engaged = (ctl["t"] >= ENGAGE_T) & (ctl["t"] < DONE_T)
        x, y = lines_with_gid(axes_named(self.fig, "a_x"), "reference")[0].get_data()
        self.assertTrue(np.allclose(np.asarray(y)[engaged], ctl["ref_an"][engaged] / FT))
        pseudo = lines_with_gid(axes_named(self.fig, "pseudo-control"), "pseudo-control")
        self.assertTrue(np.allclose(np.asarray(pseudo[0].get_ydata())[engaged],
                                    np.hypot(ctl["cmd_an"], ctl["cmd_ae"])[engaged] / FT))
        # The spike must not stretch the axes either.
        self.assertLess(axes_named(self.fig, "a_x").get_ylim()[1], 0.5 * SPIKE / FT)
        self.assertLess(axes_named(self.fig, "reference").get_ylim()[1], 0.5 * SPIKE / FT)

    def test_reference_and_pseudo_control_are_separate_against_their_bounds(self):
        ref = axes_named(self.fig, "reference")
        pseudo = axes_named(self.fig, "pseudo-control")
        self.assertIn("|reference (commanded)|", [line.get_label() for line in ref.get_lines()])
        levels = {round(line.get_ydata()[0], 3) for line in ref.get_lines()
                  if len(set(line.get_ydata())) == 1 and line.get_linestyle() == "--"}
        self.assertIn(round(0.5 / FT, 3), levels)  # the acceleration limit, ft/s^2
        bounds = {round(line.get_ydata()[0], 3) for line in pseudo.get_lines()
                  if len(set(line.get_ydata())) == 1 and line.get_linestyle() == "--"}
        self.assertEqual(bounds, {round(5 / FT, 3), round(3 / FT, 3)})
        self.assertFalse(any("pseudo" in line.get_label() for line in ref.get_lines()))

    def test_top_view_frames_obstacles_and_path_not_far_hits(self):
        ax = axes_named(self.fig, "top view")
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        for n0, n1, e0, e1 in obstacle_extents_ft():
            self.assertLessEqual(x0, n0)
            self.assertGreaterEqual(x1, n1)
            self.assertLessEqual(y0, e0)
            self.assertGreaterEqual(y1, e1)
        n, e, _ = flown(np.arange(0.0, 20.0, 0.05))
        self.assertLessEqual(x0, n.min() / FT)
        self.assertGreaterEqual(x1, n.max() / FT)
        self.assertLessEqual(y0, e.min() / FT)
        self.assertGreaterEqual(y1, e.max() / FT)
        self.assertLess(x1, FAR_HIT_NORTH / FT, "framed on a far ground hit")
        self.assertLess(x1 - x0, 2.5 * (n.max() - n.min()) / FT, "frame far too wide")
        # Equal scale: one foot is as long along x as along y.
        self.assertEqual(ax.get_aspect(), 1.0)
        bb = ax.get_window_extent()
        self.assertAlmostEqual((x1 - x0) / bb.width, (y1 - y0) / bb.height,
                               delta=0.01 * (x1 - x0) / bb.width)
        # The altitude view shares the frame along x.
        self.assertEqual(axes_named(self.fig, "altitude").get_xlim(), (x0, x1))

    def test_lidar_hits_lie_under_the_cuboid_outlines(self):
        for label in ("top view", "altitude"):
            ax = axes_named(self.fig, label)
            hits = lines_with_gid(ax, "lidar")
            self.assertEqual(len(hits), 1, label)
            cuboids = [p for p in ax.patches if isinstance(p, Rectangle) and not p.get_fill()]
            self.assertTrue(cuboids, "no cuboid outline in " + label)
            for c in cuboids:
                self.assertLess(hits[0].get_zorder(), c.get_zorder(), label)
            self.assertLessEqual(hits[0].get_markersize(), 1.0)
        alt = axes_named(self.fig, "altitude")
        self.assertLess(alt.get_xlim()[1], FAR_HIT_NORTH / FT)

    def test_clearance_panel_with_r_s_lines(self):
        ax = axes_named(self.fig, "clearance")
        self.assertIn("[ft]", ax.get_ylabel())
        for gid, level in (("R_s", RS / FT), ("0.8 R_s", 0.8 * RS / FT)):
            line = lines_with_gid(ax, gid)
            self.assertEqual(len(line), 1, gid)
            self.assertTrue(np.allclose(line[0].get_ydata(), level), gid)
            self.assertLess(level, ax.get_ylim()[1])
        curve = lines_with_gid(ax, "clearance")
        self.assertEqual(len(curve), 1)
        t, y = (np.asarray(v, dtype=float) for v in curve[0].get_data())
        # At the tip (t = 10 s: north 50, east -70, h 20 m) the wall's end is
        # 10 m away, nearer than the ground (20 m) and the pole; over the low
        # box (t = 25/7 s, north 5 m) its top is 8 m below.
        for when, metres in ((10.0, 10.0), (25.0 / 7.0, 8.0)):
            i = int(np.argmin(np.abs(t - when)))
            self.assertLess(abs(t[i] - when), 0.03)
            self.assertAlmostEqual(y[i], metres / FT, places=6)
        # The pop-up on the path at t = 15 s was gone by then.
        self.assertGreater(y[int(np.argmin(np.abs(t - 15.0)))], RS / FT)
        n, e, d = flown(t)
        by_hand = np.array([clearance_by_hand(*p) for p in zip(t, n, e, d)]) / FT
        self.assertTrue(np.allclose(y, by_hand, atol=1e-9))
        self.assertAlmostEqual(np.nanmin(y), self.summary["min_clearance"] / FT, places=6)

    def test_verdict_in_title(self):
        title = self.fig._suptitle.get_text()
        self.assertIn("synthetic-wall", title)
        self.assertIn("outcome: failure", title)
        self.assertIn("clearance (ft) below 0.8 R_s: 9.9 against 16", title)
        self.assertIn("1 more failure", title)
        self.assertNotIn("speed (ft/s)", title)

    def test_every_axis_label_names_its_unit(self):
        labels = [lab for ax in self.fig.axes for lab in (ax.get_xlabel(), ax.get_ylabel()) if lab]
        self.assertGreaterEqual(len(labels), 12)
        for lab in labels:
            self.assertRegex(lab, r"\[(s|ft|ft/s|ft/s²)\]$")


class FlightFigureCasesTest(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-plot-test-")
        self.dir = self.tmp.name

    def tearDown(self):
        plt.close("all")
        self.tmp.cleanup()

    def test_success_title_has_no_failure_line(self):
        write_results(self.dir, outcome="success")
        fig = pf.flight_figure(pf.load_results(self.dir))
        title = fig._suptitle.get_text()
        self.assertIn("outcome: success", title)
        self.assertNotIn("\n", title)

    def test_clearance_that_disagrees_with_the_report_is_not_drawn_as_true(self):
        write_results(self.dir, min_clearance=2.0)
        fig = pf.flight_figure(pf.load_results(self.dir))
        ax = axes_named(fig, "clearance")
        self.assertEqual(lines_with_gid(ax, "clearance"), [])
        self.assertEqual(len(lines_with_gid(ax, "clearance-bound")), 1)
        self.assertIn("differs from the report", ax.get_legend().get_title().get_text())

    def test_tree_gives_a_lower_bound_only(self):
        summary = write_results(self.dir)
        summary["obstacles"].append(dict(id=3, kind="tree", center=[90.0, -10.0],
                                         size=[10.0, 10.0], height=25.0, yaw=0.0,
                                         appear_time=-1, disappear_time=-1))
        with open(os.path.join(self.dir, "summary.json"), "w") as f:
            json.dump(summary, f)
        fig = pf.flight_figure(pf.load_results(self.dir))
        ax = axes_named(fig, "clearance")
        self.assertEqual(lines_with_gid(ax, "clearance"), [])
        self.assertEqual(len(lines_with_gid(ax, "clearance-bound")), 1)
        self.assertIn("lower bound", ax.get_legend().get_title().get_text())

    def test_report_without_world_draws_no_clearance(self):
        summary = write_results(self.dir)
        summary.update(min_clearance=None, min_clearance_t=None, obstacles=[])
        with open(os.path.join(self.dir, "summary.json"), "w") as f:
            json.dump(summary, f)
        fig = pf.flight_figure(pf.load_results(self.dir))
        ax = axes_named(fig, "clearance")
        self.assertEqual(lines_with_gid(ax, "clearance"), [])
        self.assertIn("no true clearance", ax.get_legend().get_title().get_text())

    def test_headers_with_units_read_as_bare_names(self):
        write_csv(os.path.join(self.dir, "x.csv"), ["t [s]", "north (m)", "east"],
                  [(0.0, 1.0, 2.0)])
        data = pf.load_csv(self.dir, "x.csv", True)
        self.assertEqual(sorted(data), ["east", "north", "t"])
        self.assertEqual(data["north"][0], 1.0)

    def test_command_line_writes_both_figures(self):
        write_results(self.dir)
        out = os.path.join(self.dir, "figs", "flight.png")
        run = subprocess.run([sys.executable, PLOT_FLIGHT, self.dir, "--out", out],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             timeout=120)
        self.assertEqual(run.returncode, 0, run.stderr)
        track = os.path.join(self.dir, "figs", "tracking.png")
        self.assertEqual(run.stdout.split(), [out, track])
        for path in (out, track):
            self.assertGreater(os.path.getsize(path), 10000, path)


class CourseFigureTest(unittest.TestCase):
    """The campaign's and the Monte Carlo runs' figure (bench/campaign_report.py)."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-course-test-")
        self.dir = self.tmp.name
        write_results(self.dir)
        self.fig = cr.course_figure_of(self.dir, title="bench-synthetic", tree_views=True)
        self.fig.canvas.draw()

    def tearDown(self):
        plt.close(self.fig)
        self.tmp.cleanup()

    def test_frame_title_commands_and_clearance(self):
        ax = axes_named(self.fig, "top view")
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        for n0, n1, e0, e1 in obstacle_extents_ft():
            self.assertTrue(x0 <= n0 and n1 <= x1 and y0 <= e0 and e1 <= y1)
        self.assertEqual(ax.get_aspect(), 1.0)
        self.assertLess(axes_named(self.fig, "side view").get_xlim()[1], FAR_HIT_NORTH / FT)

        title = self.fig._suptitle.get_text()
        self.assertIn("bench-synthetic", title)
        self.assertIn("outcome: failure", title)
        self.assertIn("clearance (ft) below 0.8 R_s", title)

        acc = axes_named(self.fig, "acceleration")
        ref = lines_with_gid(acc, "reference")
        self.assertEqual(len(ref), 1)
        self.assertEqual(ref[0].get_label(), "reference (commanded)")
        x, y = (np.asarray(v, dtype=float) for v in ref[0].get_data())
        self.assertGreaterEqual(x[np.isfinite(y)].min(), ENGAGE_T - 1e-9)

        clr = axes_named(self.fig, "clearance")
        self.assertEqual(len(lines_with_gid(clr, "R_s")), 1)
        self.assertEqual(len(lines_with_gid(clr, "0.8 R_s")), 1)
        self.assertEqual(len(lines_with_gid(clr, "clearance")), 1)


def written_header(source):
    """The CSV header line a C++ program writes (the string literal(s) after
    `csv << `), so that the readers here are tested on what is written."""
    with open(os.path.join(REPO_ROOT, source)) as f:
        text = f.read()
    literal = re.search(r'csv << ((?:"[^"]*"\s*)+)', text).group(1)
    return "".join(re.findall(r'"([^"]*)"', literal)).replace("\\n", "")


class WrittenHeadersTest(unittest.TestCase):
    """baseline_trajectory.csv (ofn_baseline) and tracking_sweep.csv
    (ofn_tracking_sweep) name their units, and their readers read them."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="ofn-headers-test-")
        self.dir = self.tmp.name

    def tearDown(self):
        self.tmp.cleanup()

    def test_baseline_trajectory_has_units_and_is_drawn(self):
        header = written_header("sim/src/baseline_main.cpp").split(",")
        self.assertEqual(header[:4], ["t [s]", "north [m]", "east [m]", "down [m]"])
        self.assertTrue(all(re.search(r" \[[^]]+\]$", h) for h in header), header)
        run_dir, base_dir = os.path.join(self.dir, "run"), os.path.join(self.dir, "base")
        os.makedirs(run_dir)
        os.makedirs(base_dir)
        write_results(run_dir)
        t = np.arange(0.0, 18.0, 0.1)
        n, e, d = -20.0 + 8.0 * t, 0.0 * t, 0.0 * t - ALTITUDE
        write_csv(os.path.join(base_dir, "baseline_trajectory.csv"), header,
                  zip(t, n, e, d, t * 0 + 8.0, t * 0, t * 0, t * 0, t * 0, t * 0))
        fig = cr.course_figure_of(run_dir, title="with baseline", baseline_dir=base_dir)
        try:
            top = axes_named(fig, "top view")
            dashed = [line for line in top.get_lines() if line.get_linestyle() == "--"]
            self.assertEqual(len(dashed), 1, [line.get_label() for line in top.get_lines()])
            x, _ = dashed[0].get_data()
            self.assertAlmostEqual(float(np.max(x)), float(np.max(n)) / FT, places=3)
        finally:
            plt.close(fig)

    def test_tracking_sweep_has_units_and_is_drawn(self):
        header = written_header("bench/tracking_sweep.cpp")
        self.assertIn("wind [kt]", header.split(","))
        self.assertIn("adaptive_rms [m]", header.split(","))
        script = os.path.join(REPO_ROOT, "bench", "plot_tracking_sweep.py")
        rows = '1,"nominal",0,light,0.2,0.5,0.3,0.9\n1.2,"nominal",10,light,0.4,1.0,2.5,6.0\n'
        for name, head in (("units", header), ("old", header.replace(" [kt]", "_kt")
                                                               .replace(" [m]", ""))):
            csv_path = os.path.join(self.dir, name + ".csv")
            with open(csv_path, "w") as f:
                f.write(head + "\n" + rows)
            run = subprocess.run([sys.executable, script, csv_path], stdout=subprocess.PIPE,
                                 stderr=subprocess.PIPE, text=True, timeout=120)
            self.assertEqual(run.returncode, 0, run.stderr)
            png = os.path.join(self.dir, name + ".png")
            self.assertEqual(run.stdout.strip(), "wrote " + png)
            self.assertGreater(os.path.getsize(png), 10000)


if __name__ == "__main__":
    unittest.main()
