#!/usr/bin/python3
"""Seeded random obstacle fields over the benchmark course, written as scenario YAML.

Usage: random_field.py --seed S --out FILE [--dense | --trap] [--out-and-back]
                       [--wind KT] [--turbulence LEVEL] [--template sim/scenarios/bench1.yaml]

The course (start, goal waypoint, limits, gates, max_time, units) is copied
from the template, bench1 by default; only the obstacles are drawn. The same
seed, class and template always give the same file, byte for byte.
With --out-and-back the course goes on from the goal back to the first
waypoint (one more waypoint, with the goal's capture radius, and twice the
time limit): the same obstacles, flown both ways over one line, so that
the legs of a route of several legs are exercised. The gates still time
the way out.
With --wind KT a steady horizontal wind of KT knots blows from a direction
drawn from the seed (its own random stream: the obstacles are those of the
calm field of the same seed), and --turbulence LEVEL (light, moderate,
severe: MIL-F-8785C, docs/SCENARIO_FORMAT.md) rides on it, seeded by the
field's seed. The airframe is the configured one.

Two classes of field (../shared/BENCHMARKS.md): "fair" fields (the default),
in which a route with R_s clearance always exists, and "dense" fields
(--dense), which may be sealed.

Fair fields. Fairness rules (every field that breaks one is redrawn from the same random
stream, so the result is still a function of the seed alone). Lengths in ft,
R_s = limits.clearance of the template (20 ft for bench1):

  1. 2 to 5 obstacles, each wholly inside 60 <= x <= 360: the run-up from the
     start (x = -100) past the start gate (x = 0) and the run-out past the
     finish gate (x = 400) to the goal (x = 500) stay clear, so the clock
     starts and stops in steady flight and every obstacle is in sensor range
     (200 ft) well before the vehicle must react.
  2. No obstacle within R_s + 30 of the start position or the goal waypoint.
  3. Low obstacles (top 40..150, i.e. below flight altitude + 60) can always
     be climbed over: their top plus R_s is at most 170, 50 above the
     120 ft flight altitude, a 10 s climb at the 5 ft/s vertical limit that
     fits in the >= 160 ft run-up of rule 1 (and anywhere else, since the
     forward speed may drop to zero).
  4. Tall obstacles (top 250..300) must be passed beside. Any two of them are
     at least 2 R_s + 40 apart in plan, so their footprints grown by R_s are
     disjoint with a corridor of at least 40 ft between any two. The plane
     outside a finite set of disjoint convex regions is connected, so a
     route at flight altitude with R_s clearance from every tall obstacle
     always exists; where it crosses a low obstacle it climbs (rule 3).
     Footprints are at most 120 ft across (a box diagonal <= 170 ft), so
     every detour stays well inside the mapper's window.
  5. Any two obstacles are at least R_s apart in plan, so no two of them
     merge into one shape whose top the sensor cannot judge.
  6. The first obstacle stands within 20 ft of the course line, so every
     field makes the vehicle do something.

Obstacles: boxes (footprint sides 20..120, yaw 0..180 deg) and cylinders
(radius 10..30), as documented in docs/SCENARIO_FORMAT.md.

Dense fields (--dense). No fairness rule: dead ends, sealed corridors and
gaps narrower than 2 R_s (impassable) are kept, and whether a route exists
is for the time-optimal baseline to find out. Only these rules hold (an
obstacle that breaks one is redrawn from the same stream, as above):

  D1. 10 to 25 obstacles, each wholly inside 40 <= x <= 380 and
      -160 <= y <= 160: the run-up from the start and the run-out to the
      goal stay clear, so the clock starts and stops in steady flight.
  D2. No obstacle within R_s + 30 of the start position or the goal
      waypoint (implied by D1 for bench1's course, checked for any template).
  D3. Any two obstacles at least 15 ft apart in plan, surface to surface, so
      that none overlap or touch; gaps of 15..2 R_s cannot be flown through
      with R_s clearance. The distance is computed conservatively: a
      cylinder is taken as its circumscribed polygon, never smaller than
      the cylinder itself.

Dense obstacles are smaller than fair ones so that up to 25 fit: boxes with
footprint sides 15..80 (yaw 0..180 deg) and cylinders of radius 8..30; 40 %
of them are tall (top 250..300, to be passed beside) and the rest have a top
anywhere in 40..250, low ones to climb over mixed with ones whose climb costs
about as much as a detour.

Trap fields (--trap). The shapes that catch a reactive planner, drawn at
random: each field has one trap and some clutter, and a third of them a
pop-up as well. Like dense fields they may be sealed (the baseline says).

  T1. The trap, one of three kinds, equally likely:
      - a dead end: a U of three thin walls (6..12 ft) open towards the
        start, its axis turned up to 35 deg off the course, 50..160 ft wide
        inside and 60..160 ft deep, its back wall at x = 200..330, up to
        60 ft aside;
      - a wall across the course wider than the map: 500..1000 ft long,
        8..15 ft thick, turned up to 10 deg, at x = 150..300, in 70 % of
        fields with one gap of 30..120 ft (narrower than 2 R_s in some)
        within 200 ft of the course line;
      - a pocket: a dead end 45..70 ft wide inside and 100..200 ft deep, a
        corridor with little more than 2 R_s of room to back out of.
      Walls are tall (top 250..300 ft) in 60 % of fields, else 100..240 ft.
  T2. 0..8 clutter obstacles as dense ones (D3's 15 ft between any two,
      trap walls included; a trap's own walls touch).
  T3. A pop-up in a third of the fields: a box or cylinder as a dense one,
      within 100 ft of the course line, that appears at a time at which no
      vehicle within the speed limit can be nearer to it than R_s plus its
      braking distance plus 30 ft (it is seen, not sprung).
  Every obstacle keeps D2 (R_s + 30 from the start and the goal) and lies
  within 40 <= x <= 380 (the run-up and run-out stay clear); the wall may
  reach far beyond |y| = 160. max_time is 300 s (a wall's end may be far).
"""
import argparse
import copy
import math
import os
import random
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import campaign_report as cr  # noqa: E402  (command-line helpers; imports nothing heavy)

REPO = os.path.dirname(HERE)
DEFAULT_TEMPLATE = os.path.join(REPO, "sim", "scenarios", "bench1.yaml")

FIELD_X_MIN, FIELD_X_MAX = 60.0, 360.0
LINE_Y_MAX = 100.0  # centres drawn within this distance of the course line
FIRST_ON_LINE_Y = 20.0
END_MARGIN_BEYOND_RS = 30.0
TALL_CORRIDOR_BEYOND_2RS = 40.0
LOW_TOP = (40.0, 150.0)
TALL_TOP = (250.0, 300.0)
BOX_SIDE = (20.0, 120.0)
CYLINDER_RADIUS = (10.0, 30.0)
TALL_SHARE = 0.5
BOX_SHARE = 0.6
COUNT = (2, 5)
# Dense fields (rules D1..D3 above).
DENSE_X_MIN, DENSE_X_MAX = 40.0, 380.0
DENSE_Y_MAX = 160.0
DENSE_COUNT = (10, 25)
DENSE_MIN_GAP = 15.0  # ft, least plan distance between two obstacle surfaces
DENSE_TALL_SHARE = 0.4
DENSE_TALL_TOP = (250.0, 300.0)
DENSE_OTHER_TOP = (40.0, 250.0)
DENSE_BOX_SIDE = (15.0, 80.0)
DENSE_CYLINDER_RADIUS = (8.0, 30.0)
DENSE_TRIES_PER_OBSTACLE = 200
# Trap fields (rules T1..T3 above).
TRAP_KINDS = ("dead_end", "wide_wall", "pocket")
TRAP_TALL_SHARE = 0.6
TRAP_TALL_TOP = (250.0, 300.0)
TRAP_LOW_TOP = (100.0, 240.0)
TRAP_MAX_TURN_DEG = 35.0
TRAP_WALL_THICKNESS = (6.0, 12.0)
TRAP_DEAD_END_WIDTH = (50.0, 160.0)
TRAP_POCKET_WIDTH = (45.0, 70.0)
TRAP_POCKET_DEPTH = (100.0, 200.0)
TRAP_DEPTH = (60.0, 160.0)
TRAP_BACK_X = (200.0, 330.0)
TRAP_ASIDE = 60.0
WIDE_WALL_LENGTH = (500.0, 1000.0)
WIDE_WALL_THICKNESS = (8.0, 15.0)
WIDE_WALL_TURN_DEG = 10.0
WIDE_WALL_X = (150.0, 300.0)
WIDE_WALL_GAP_SHARE = 0.7
WIDE_WALL_GAP = (30.0, 120.0)
WIDE_WALL_GAP_ASIDE = 200.0
TRAP_CLUTTER = (0, 8)
TRAP_POPUP_SHARE = 1.0 / 3.0
TRAP_POPUP_Y_MAX = 100.0
TRAP_POPUP_MARGIN = 30.0  # ft beyond R_s and the braking distance
TRAP_MAX_TIME = 300.0  # s
CIRCLE_SEGMENTS = 48  # cylinders as polygons for the plan distances; error < 0.3 % of the radius
MAX_DRAWS = 10000


def load_template(path):
    """The template scenario; ValueError (one line) when it is not a usable one."""
    yaml = cr.need("yaml")
    try:
        with open(path) as f:
            tpl = yaml.safe_load(f)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        where = " line %d, column %d:" % (mark.line + 1, mark.column + 1) if mark is not None else ""
        raise ValueError("%s: not valid YAML:%s %s" % (path, where, getattr(exc, "problem", None)
                                                      or " ".join(str(exc).split())))
    if not isinstance(tpl, dict):
        raise ValueError("%s: template is not a scenario (its top level is not a mapping)" % path)
    for key in ("units", "start", "waypoints", "limits", "gates"):
        if key not in tpl:
            raise ValueError("%s: template has no '%s'" % (path, key))
    return tpl


def footprint(ob, circumscribed=False):
    """Plan outline (x, y) of an obstacle as a convex polygon, counter-clockwise or not.

    A cylinder's polygon is inscribed in its circle (vertices on it), or with
    `circumscribed` drawn round it (edges touching it): the first may read a
    distance up to 0.3 % of the radius too long, the second never does.
    """
    cx, cy = ob["center"]
    if ob["kind"] == "cylinder":
        r = ob["radius"] / (math.cos(math.pi / CIRCLE_SEGMENTS) if circumscribed else 1.0)
        return [(cx + r * math.cos(a), cy + r * math.sin(a))
                for a in (2 * math.pi * i / CIRCLE_SEGMENTS for i in range(CIRCLE_SEGMENTS))]
    a, b = ob["size"]
    yaw = math.radians(ob.get("yaw_deg", 0.0))
    c, s = math.cos(yaw), math.sin(yaw)
    local = [(a / 2, b / 2), (-a / 2, b / 2), (-a / 2, -b / 2), (a / 2, -b / 2)]
    return [(cx + x * c - y * s, cy + x * s + y * c) for x, y in local]


def _point_segment(p, a, b):
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    L2 = dx * dx + dy * dy
    t = 0.0 if L2 == 0 else max(0.0, min(1.0, ((p[0] - ax) * dx + (p[1] - ay) * dy) / L2))
    return math.hypot(p[0] - ax - t * dx, p[1] - ay - t * dy)


def _inside(p, poly):
    """Point in convex polygon (either orientation)."""
    sign = 0
    for i in range(len(poly)):
        a, b = poly[i], poly[(i + 1) % len(poly)]
        cross = (b[0] - a[0]) * (p[1] - a[1]) - (b[1] - a[1]) * (p[0] - a[0])
        if cross != 0:
            if sign == 0:
                sign = 1 if cross > 0 else -1
            elif (cross > 0) != (sign > 0):
                return False
    return True


def _separating_axis(p, q):
    """True when an edge normal of p or q separates the two convex polygons."""
    for poly in (p, q):
        for i in range(len(poly)):
            a, b = poly[i], poly[(i + 1) % len(poly)]
            nx, ny = b[1] - a[1], a[0] - b[0]
            pp = [nx * x + ny * y for x, y in p]
            qq = [nx * x + ny * y for x, y in q]
            if max(pp) < min(qq) or max(qq) < min(pp):
                return True
    return False


def plan_distance(p, q):
    """Least distance between two convex polygons; 0 when they overlap."""
    if not _separating_axis(p, q):
        return 0.0
    best = math.inf
    for poly, other in ((p, q), (q, p)):
        for v in poly:
            for i in range(len(other)):
                best = min(best, _point_segment(v, other[i], other[(i + 1) % len(other)]))
    return best


def point_distance(pt, poly):
    if _inside(pt, poly):
        return 0.0
    return min(_point_segment(pt, poly[i], poly[(i + 1) % len(poly)]) for i in range(len(poly)))


def is_tall(ob):
    return ob["height"] >= TALL_TOP[0]


def rule_violations(obstacles, tpl):
    """Every broken fairness rule, as text; empty for a fair field."""
    rs = float(tpl["limits"].get("clearance", 0.0))
    start = tpl["start"]["position"][:2]
    goal = tpl["waypoints"][-1]["position"][:2]
    shapes = [footprint(ob) for ob in obstacles]
    out = []
    if not COUNT[0] <= len(obstacles) <= COUNT[1]:
        out.append("%d obstacles" % len(obstacles))
    for i, (ob, poly) in enumerate(zip(obstacles, shapes)):
        xs = [x for x, _ in poly]
        if min(xs) < FIELD_X_MIN or max(xs) > FIELD_X_MAX:
            out.append("obstacle %d outside %g <= x <= %g" % (i + 1, FIELD_X_MIN, FIELD_X_MAX))
        for name, pt in (("start", start), ("goal", goal)):
            if point_distance(pt, poly) < rs + END_MARGIN_BEYOND_RS:
                out.append("obstacle %d within R_s + %g of the %s" % (i + 1, END_MARGIN_BEYOND_RS, name))
        for j in range(i):
            d = plan_distance(poly, shapes[j])
            need = rs
            if is_tall(ob) and is_tall(obstacles[j]):
                need = 2 * rs + TALL_CORRIDOR_BEYOND_2RS
            if d < need:
                out.append("obstacles %d and %d %.1f apart (< %.1f)" % (j + 1, i + 1, d, need))
    if obstacles and abs(obstacles[0]["center"][1]) > FIRST_ON_LINE_Y:
        out.append("obstacle 1 off the course line")
    return out


def _draw_obstacle(rng, on_line):
    tall = rng.random() < TALL_SHARE
    height = rng.uniform(*(TALL_TOP if tall else LOW_TOP))
    y_max = FIRST_ON_LINE_Y if on_line else LINE_Y_MAX
    if rng.random() < BOX_SHARE:
        ob = {"kind": "box", "size": [rng.uniform(*BOX_SIDE), rng.uniform(*BOX_SIDE)],
              "yaw_deg": rng.uniform(0.0, 180.0)}
    else:
        ob = {"kind": "cylinder", "radius": rng.uniform(*CYLINDER_RADIUS)}
    ob["center"] = [rng.uniform(FIELD_X_MIN, FIELD_X_MAX), rng.uniform(-y_max, y_max)]
    ob["height"] = height
    return _rounded(ob)


def _rounded(ob):
    """Round to 0.1 ft (0.1 deg) before the rule checks, so the checked field is the written one."""
    r = {"kind": ob["kind"], "center": [round(v, 1) for v in ob["center"]]}
    if "size" in ob:
        r["size"] = [round(v, 1) for v in ob["size"]]
        r["yaw_deg"] = round(ob["yaw_deg"], 1)
    else:
        r["radius"] = round(ob["radius"], 1)
    r["height"] = round(ob["height"], 1)
    return r


def generate(seed, tpl):
    """(obstacles, redraws): a fair field, a function of the seed and the template only.

    Obstacles are placed one by one, each redrawn until it keeps the rules
    with those already placed; a field that cannot be completed that way
    within a bounded number of draws is started afresh from the same stream.
    """
    rng = random.Random(seed)
    draws = 0
    while draws < MAX_DRAWS:
        count = rng.randint(*COUNT)
        obstacles = []
        for k in range(count):
            for _ in range(200):
                draws += 1
                ob = _draw_obstacle(rng, on_line=(k == 0))
                trial = obstacles + [ob]
                if not [v for v in rule_violations(trial, tpl) if not v.endswith(" obstacles")]:
                    obstacles = trial
                    break
            else:
                break
        if len(obstacles) == count and not rule_violations(obstacles, tpl):
            return obstacles, draws
    raise RuntimeError("seed %d: no fair field in %d draws" % (seed, MAX_DRAWS))


def _bounding_radius(ob):
    if ob["kind"] == "cylinder":
        return ob["radius"]
    return 0.5 * math.hypot(*ob["size"])


def dense_rule_violations(obstacles, tpl):
    """Every broken dense-field rule (D1..D3), as text; empty for a dense field."""
    rs = float(tpl["limits"].get("clearance", 0.0))
    start = tpl["start"]["position"][:2]
    goal = tpl["waypoints"][-1]["position"][:2]
    # Circumscribed outlines: a distance read from them is never longer than the true one.
    shapes = [footprint(ob, circumscribed=True) for ob in obstacles]
    out = []
    if not DENSE_COUNT[0] <= len(obstacles) <= DENSE_COUNT[1]:
        out.append("%d obstacles" % len(obstacles))
    for i, (ob, poly) in enumerate(zip(obstacles, shapes)):
        xs = [x for x, _ in poly]
        ys = [y for _, y in poly]
        if min(xs) < DENSE_X_MIN or max(xs) > DENSE_X_MAX or min(ys) < -DENSE_Y_MAX or max(ys) > DENSE_Y_MAX:
            out.append("obstacle %d outside %g <= x <= %g, |y| <= %g"
                       % (i + 1, DENSE_X_MIN, DENSE_X_MAX, DENSE_Y_MAX))
        for name, pt in (("start", start), ("goal", goal)):
            if point_distance(pt, poly) < rs + END_MARGIN_BEYOND_RS:
                out.append("obstacle %d within R_s + %g of the %s" % (i + 1, END_MARGIN_BEYOND_RS, name))
        out += [v for v in (_dense_gap_violation(obstacles, shapes, i, j) for j in range(i)) if v]
    return out


def _dense_gap_violation(obstacles, shapes, i, j):
    """D3 between obstacles i and j (outlines `shapes`), as text; None when kept."""
    ob, other = obstacles[i], obstacles[j]
    centres = math.hypot(ob["center"][0] - other["center"][0], ob["center"][1] - other["center"][1])
    # Bounding circles far enough apart settle it without the polygons.
    if centres - _bounding_radius(ob) - _bounding_radius(other) >= DENSE_MIN_GAP:
        return None
    d = plan_distance(shapes[i], shapes[j])
    if d < DENSE_MIN_GAP:
        return "obstacles %d and %d %.1f apart (< %.1f)" % (j + 1, i + 1, d, DENSE_MIN_GAP)
    return None


def _draw_dense_obstacle(rng):
    tall = rng.random() < DENSE_TALL_SHARE
    height = rng.uniform(*(DENSE_TALL_TOP if tall else DENSE_OTHER_TOP))
    if rng.random() < BOX_SHARE:
        ob = {"kind": "box", "size": [rng.uniform(*DENSE_BOX_SIDE), rng.uniform(*DENSE_BOX_SIDE)],
              "yaw_deg": rng.uniform(0.0, 180.0)}
    else:
        ob = {"kind": "cylinder", "radius": rng.uniform(*DENSE_CYLINDER_RADIUS)}
    ob["center"] = [rng.uniform(DENSE_X_MIN, DENSE_X_MAX), rng.uniform(-DENSE_Y_MAX, DENSE_Y_MAX)]
    ob["height"] = height
    return _rounded(ob)


def generate_dense(seed, tpl):
    """(obstacles, draws): a dense field, a function of the seed and the template only.

    The count is drawn first; obstacles are then placed one by one, each
    redrawn until it keeps rules D1..D3 with those already placed. A field
    that cannot be completed that way is started afresh from the same stream.
    """
    rng = random.Random(seed)
    draws = 0
    while draws < MAX_DRAWS:
        count = rng.randint(*DENSE_COUNT)
        obstacles = []
        for _ in range(count):
            for _ in range(DENSE_TRIES_PER_OBSTACLE):
                draws += 1
                ob = _draw_dense_obstacle(rng)
                trial = obstacles + [ob]
                if not [v for v in dense_rule_violations(trial, tpl) if not v.endswith(" obstacles")]:
                    obstacles = trial
                    break
            else:
                break
        if len(obstacles) == count and not dense_rule_violations(obstacles, tpl):
            return obstacles, draws
    raise RuntimeError("seed %d: no dense field in %d draws" % (seed, MAX_DRAWS))


def _wall(a, b, thickness, height):
    """A thin box from plan point a to plan point b (ft)."""
    length = math.hypot(b[0] - a[0], b[1] - a[1])
    return _rounded({"kind": "box", "center": [0.5 * (a[0] + b[0]), 0.5 * (a[1] + b[1])],
                     "size": [length, thickness],
                     "yaw_deg": math.degrees(math.atan2(b[1] - a[1], b[0] - a[0])) % 180.0,
                     "height": height})


def _trap_walls(rng, kind):
    """The trap's walls (T1), before the placement rules are checked."""
    height = rng.uniform(*(TRAP_TALL_TOP if rng.random() < TRAP_TALL_SHARE else TRAP_LOW_TOP))
    if kind == "wide_wall":
        length = rng.uniform(*WIDE_WALL_LENGTH)
        thickness = rng.uniform(*WIDE_WALL_THICKNESS)
        turn = math.radians(rng.uniform(-WIDE_WALL_TURN_DEG, WIDE_WALL_TURN_DEG))
        cx, cy = rng.uniform(*WIDE_WALL_X), rng.uniform(-0.5 * length, 0.5 * length) * 0.5
        # Along the wall: (-sin, cos) turned from +y.
        ux, uy = -math.sin(turn), math.cos(turn)
        ends = (-0.5 * length, 0.5 * length)
        pieces = [ends]
        if rng.random() < WIDE_WALL_GAP_SHARE:
            gap = rng.uniform(*WIDE_WALL_GAP)
            # The gap's middle within WIDE_WALL_GAP_ASIDE of the course line (y = 0).
            mid = rng.uniform(-WIDE_WALL_GAP_ASIDE, WIDE_WALL_GAP_ASIDE) - cy / uy
            mid = min(max(mid, ends[0] + gap), ends[1] - gap)
            pieces = [(ends[0], mid - 0.5 * gap), (mid + 0.5 * gap, ends[1])]
        walls = [_wall((cx + ux * lo, cy + uy * lo), (cx + ux * hi, cy + uy * hi), thickness, height)
                 for lo, hi in pieces]
    else:
        pocket = kind == "pocket"
        width = rng.uniform(*(TRAP_POCKET_WIDTH if pocket else TRAP_DEAD_END_WIDTH))
        depth = rng.uniform(*(TRAP_POCKET_DEPTH if pocket else TRAP_DEPTH))
        thickness = rng.uniform(*TRAP_WALL_THICKNESS)
        turn = math.radians(rng.uniform(-TRAP_MAX_TURN_DEG, TRAP_MAX_TURN_DEG))
        bx, by = rng.uniform(*TRAP_BACK_X), rng.uniform(-TRAP_ASIDE, TRAP_ASIDE)
        fx, fy = math.cos(turn), math.sin(turn)  # into the trap, towards its back wall
        sx, sy = -fy, fx  # across it
        half = 0.5 * (width + thickness)
        back_l = (bx + sx * half, by + sy * half)
        back_r = (bx - sx * half, by - sy * half)
        mouth_l = (back_l[0] - fx * depth, back_l[1] - fy * depth)
        mouth_r = (back_r[0] - fx * depth, back_r[1] - fy * depth)
        # The back wall reaches the side walls' outer faces: the corners are closed.
        ext = 0.5 * thickness
        walls = [_wall((back_l[0] + sx * ext, back_l[1] + sy * ext),
                       (back_r[0] - sx * ext, back_r[1] - sy * ext), thickness, height),
                 _wall(mouth_l, back_l, thickness, height), _wall(mouth_r, back_r, thickness, height)]
    return walls


def _popup_fair(ob, tpl):
    """The latest appear time (s) at which no vehicle within the speed limit
    since the start can be nearer to `ob` than R_s, its braking distance and
    TRAP_POPUP_MARGIN (T3); negative when there is none."""
    lim = tpl["limits"]
    speed = float(lim["max_speed"])
    braking = speed * speed / (2.0 * float(lim["max_accel"]))
    start = tpl["start"]["position"][:2]
    reach = point_distance(start, footprint(ob, circumscribed=True))
    return (reach - float(lim.get("clearance", 0.0)) - braking - TRAP_POPUP_MARGIN) / speed


def trap_rule_violations(obstacles, n_walls, tpl):
    """Every broken trap-field rule, as text: D2 and the x band for all,
    D3 between any two obstacles that are not both walls of the trap."""
    rs = float(tpl["limits"].get("clearance", 0.0))
    start = tpl["start"]["position"][:2]
    goal = tpl["waypoints"][-1]["position"][:2]
    shapes = [footprint(ob, circumscribed=True) for ob in obstacles]
    out = []
    for i, (ob, poly) in enumerate(zip(obstacles, shapes)):
        xs = [x for x, _ in poly]
        if min(xs) < DENSE_X_MIN or max(xs) > DENSE_X_MAX:
            out.append("obstacle %d outside %g <= x <= %g" % (i + 1, DENSE_X_MIN, DENSE_X_MAX))
        for name, pt in (("start", start), ("goal", goal)):
            if point_distance(pt, poly) < rs + END_MARGIN_BEYOND_RS:
                out.append("obstacle %d within R_s + %g of the %s" % (i + 1, END_MARGIN_BEYOND_RS, name))
        # A trap's own walls touch at its corners.
        others = range(n_walls if i < n_walls else 0, i)
        out += [v for v in (_dense_gap_violation(obstacles, shapes, i, j) for j in others) if v]
    return out


def generate_trap(seed, tpl):
    """(obstacles, draws): a trap field (T1..T3), a function of the seed and the template only.

    The trap is drawn until its walls keep the rules; clutter obstacles and
    the pop-up are then placed one by one, each redrawn until the field
    keeps them (a clutter obstacle that finds no place within its tries is
    left out, so a field may hold fewer than drawn).
    """
    rng = random.Random(seed)
    draws = 0
    kind = TRAP_KINDS[rng.randrange(len(TRAP_KINDS))]
    while True:
        draws += 1
        if draws > MAX_DRAWS:
            raise RuntimeError("seed %d: no trap field in %d draws" % (seed, MAX_DRAWS))
        walls = _trap_walls(rng, kind)
        if not trap_rule_violations(walls, len(walls), tpl):
            break
    for w in walls:
        w["trap"] = kind
    obstacles = list(walls)
    for _ in range(rng.randint(*TRAP_CLUTTER)):
        for _ in range(DENSE_TRIES_PER_OBSTACLE):
            draws += 1
            ob = _draw_dense_obstacle(rng)
            if not trap_rule_violations(obstacles + [ob], len(walls), tpl):
                obstacles.append(ob)
                break
    if rng.random() < TRAP_POPUP_SHARE:
        for _ in range(DENSE_TRIES_PER_OBSTACLE):
            draws += 1
            ob = _draw_dense_obstacle(rng)
            ob["center"][1] = round(rng.uniform(-TRAP_POPUP_Y_MAX, TRAP_POPUP_Y_MAX), 1)
            latest = _popup_fair(ob, tpl)
            if latest < 1.0 or trap_rule_violations(obstacles + [ob], len(walls), tpl):
                continue
            ob["appear_time"] = round(rng.uniform(1.0, latest), 1)
            obstacles.append(ob)
            break
    return obstacles, draws


def _num(v):
    return ("%.1f" % v).rstrip("0").rstrip(".") if v != int(v) else "%d" % int(v)


def _vec(v):
    return "[" + ", ".join(_num(float(x)) for x in v) + "]"


def out_and_back(tpl):
    """The template's course flown out and back: a last waypoint at the first one, with the
    goal's capture radius, and twice the time limit."""
    course = copy.deepcopy(tpl)
    waypoints = course["waypoints"]
    back = {"position": list(waypoints[0]["position"])}
    if "capture_radius" in waypoints[-1]:
        back["capture_radius"] = waypoints[-1]["capture_radius"]
    waypoints.append(back)
    if "max_time" in course:
        course["max_time"] = 2.0 * float(course["max_time"])
    return course


# Feet or metres per second in one knot, by the template's units.
KNOT = {"ft": 1.6878099, "m": 0.5144444}
TURBULENCE_LEVELS = ("none", "light", "moderate", "severe")


def weather_flags(wind_kt=0.0, turbulence="none"):
    """This script's options that give a field that weather ("" in calm air)."""
    return (" --wind %g" % wind_kt if wind_kt > 0 else "") + \
        (" --turbulence %s" % turbulence if turbulence != "none" else "")


def weather_lines(seed, units, wind_kt=0.0, turbulence="none"):
    """The environment and disturbances sections of a field's weather: a wind of `wind_kt`
    knots from a direction drawn from the seed, and turbulence of that level."""
    lines = []
    if wind_kt > 0:
        # A stream of its own: the same seed gives the same obstacles in calm and in wind.
        towards = random.Random("wind-%d" % seed).uniform(0.0, 360.0)
        speed = wind_kt * KNOT[units]
        wx, wy = speed * math.cos(math.radians(towards)), speed * math.sin(math.radians(towards))
        lines += ["environment:",
                  "  wind: [%.2f, %.2f, 0]   # %g kt blowing towards %.0f deg from the course's x axis"
                  % (wx, wy, wind_kt, towards)]
    if turbulence != "none":
        lines += ["disturbances:", "  turbulence: %s" % turbulence, "  seed: %d" % seed]
    return lines


def field_yaml(seed, obstacles, tpl, template_name, kind="fair", both_ways=False, wind_kt=0.0,
               turbulence="none"):
    """Scenario text in the bench file layout; `kind` is fair, dense or trap; `both_ways`: the
    course out and back (out_and_back); `wind_kt` and `turbulence`: its weather
    (weather_lines)."""
    if both_ways:
        tpl = out_and_back(tpl)
    start, lim, gates = tpl["start"], tpl["limits"], tpl["gates"]
    tall = sum(1 for o in obstacles if is_tall(o))
    if kind == "trap":
        trap = next((o["trap"] for o in obstacles if "trap" in o), "none")
        popups = sum(1 for o in obstacles if "appear_time" in o)
        head = [
            "# Trap field, seed %d (bench/random_field.py --trap; course from %s)." % (seed, template_name),
            "# A %s, clutter%s; a route need not exist." % (trap.replace("_", " "),
                                                            " and a pop-up" if popups else ""),
            "# Regenerate: bench/random_field.py --trap --seed %d --out FILE" % seed,
            "name: trap-%d" % seed,
            "description: trap field %d, a %s and %d more obstacles, may be sealed"
            % (seed, trap.replace("_", " "), sum(1 for o in obstacles if "trap" not in o)),
        ]
    elif kind == "dense":
        head = [
            "# Dense random obstacle field, seed %d (bench/random_field.py --dense; course from %s)."
            % (seed, template_name),
            "# Dead ends and gaps too narrow for R_s are allowed: a route need not exist.",
            "# Regenerate: bench/random_field.py --dense --seed %d --out FILE" % seed,
            "name: dense-%d" % seed,
            "description: dense random field %d, %d obstacles (%d tall), may be sealed"
            % (seed, len(obstacles), tall),
        ]
    else:
        head = [
            "# Random obstacle field, seed %d (bench/random_field.py; course from %s)." % (seed, template_name),
            "# Regenerate: bench/random_field.py --seed %d --out FILE" % seed,
            "name: field-%d" % seed,
            "description: random field %d, %d obstacles (%d tall)" % (seed, len(obstacles), tall),
        ]
    weather = weather_lines(seed, tpl["units"], wind_kt, turbulence)
    if weather:
        flags = weather_flags(wind_kt, turbulence)
        for i, line in enumerate(head):
            if line.startswith("# Regenerate:"):
                head[i] = line.replace(" --out FILE", flags + " --out FILE")
            elif line.startswith("name: "):
                head[i] = line + "-wind" if wind_kt > 0 else line + "-turbulent"
            elif line.startswith("description: "):
                head[i] = line + ", %s" % ", ".join(
                    ([("%g kt wind" % wind_kt)] if wind_kt > 0 else [])
                    + ([turbulence + " turbulence"] if turbulence != "none" else []))
    if both_ways:
        for i, line in enumerate(head):
            if line.startswith("# Regenerate:"):
                head[i] = line.replace(" --out FILE", " --out-and-back --out FILE")
            elif line.startswith("name: "):
                head[i] = line + "-out-and-back"
            elif line.startswith("description: "):
                head[i] = line + ", flown out and back"
    lines = head + [
        "units: %s" % tpl["units"],
        "start:",
        "  position: %s" % _vec(start["position"]),
    ]
    for key in ("speed", "heading_deg"):
        if key in start:
            lines.append("  %s: %s" % (key, _num(float(start[key]))))
    lines.append("waypoints:")
    for wp in tpl["waypoints"]:
        lines.append("  - position: %s" % _vec(wp["position"]))
        if "capture_radius" in wp:
            lines.append("    capture_radius: %s" % _num(float(wp["capture_radius"])))
    for key in ("capture_radius", "cruise_speed"):
        if key in tpl:
            lines.append("%s: %s" % (key, _num(float(tpl[key]))))
    lines.append("limits:")
    for key, value in lim.items():
        lines.append("  %s: %s" % (key, _num(float(value))))
    lines.append("gates:")
    for key, value in gates.items():
        lines.append("  %s: %s" % (key, _num(float(value))))
    lines.append("obstacles:")
    for i, ob in enumerate(obstacles):
        lines.append("  - kind: %s" % ob["kind"])
        lines.append("    id: %d" % (i + 1))
        lines.append("    center: %s" % _vec(ob["center"]))
        if ob["kind"] == "box":
            lines.append("    size: %s" % _vec(ob["size"]))
            lines.append("    yaw_deg: %s" % _num(ob["yaw_deg"]))
        else:
            lines.append("    radius: %s" % _num(ob["radius"]))
        lines.append("    height: %s%s" % (_num(ob["height"]), "   # tall: pass beside" if is_tall(ob)
                                          else "   # low: may climb over"))
        if "appear_time" in ob:
            lines.append("    appear_time: %s   # s; seen before it can be reached" % _num(ob["appear_time"]))
    lines += weather
    if kind == "trap":
        lines.append("max_time: %s" % _num(TRAP_MAX_TIME * (2 if both_ways else 1)))
    elif "max_time" in tpl:
        lines.append("max_time: %s" % _num(float(tpl["max_time"])))
    return "\n".join(lines) + "\n"


GENERATORS = {"fair": generate, "dense": generate_dense, "trap": generate_trap}


def write_field(seed, path, template=DEFAULT_TEMPLATE, kind="fair", both_ways=False, wind_kt=0.0,
                turbulence="none"):
    """Write the field of `seed` of `kind` (fair, dense or trap) to `path`, in the weather of
    weather_lines; returns its obstacle list."""
    tpl = load_template(template)
    if tpl["units"] not in KNOT:
        raise ValueError("%s: units %r are neither ft nor m" % (template, tpl["units"]))
    obstacles, _ = GENERATORS[kind](seed, tpl)
    text = field_yaml(seed, obstacles, tpl, os.path.relpath(template, REPO), kind, both_ways,
                      wind_kt, turbulence)
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as f:
        f.write(text)
    return obstacles


PROG = "bench/random_field.py"


def build_parser():
    ap = cr.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="The rules of the three classes of field are in this file's docstring.\n"
               "\n"
               "Examples:\n"
               "  bench/random_field.py --seed 7 --out /tmp/field-7.yaml\n"
               "  bench/random_field.py --dense --seed 7 --template sim/scenarios/bench1.yaml \\\n"
               "      --out /tmp/dense-7.yaml\n"
               "  bench/random_field.py --trap --seed 7 --out /tmp/trap-7.yaml\n"
               "  bench/random_field.py --dense --out-and-back --seed 7 --out /tmp/dense-7-back.yaml\n"
               "  bench/random_field.py --dense --wind 15 --turbulence moderate --seed 7 \\\n"
               "      --out /tmp/dense-7-wind.yaml\n"
               "\n"
               "Exit codes: 0 when the field is written; 2 for bad arguments, an unusable\n"
               "template, a file that cannot be written or PyYAML missing.")
    ap.add_argument("--seed", type=int, required=True, metavar="S",
                    help="random seed; the same seed always gives the same field (required)")
    ap.add_argument("--out", required=True, metavar="FILE", help="scenario file to write (required)")
    ap.add_argument("--template", default=DEFAULT_TEMPLATE, metavar="FILE",
                    help="scenario whose course (start, waypoints, limits, gates) is used "
                         "(default: %s)" % cr.rel(DEFAULT_TEMPLATE))
    kind = ap.add_mutually_exclusive_group()
    kind.add_argument("--dense", action="store_true",
                      help="a dense field (10-25 obstacles, 15 ft gaps, may be sealed) instead of "
                           "a fair one (default: fair)")
    kind.add_argument("--trap", action="store_true",
                      help="a trap field (a dead end, a wall wider than the map or a narrow "
                           "pocket, clutter, sometimes a pop-up; may be sealed) (default: fair)")
    ap.add_argument("--out-and-back", action="store_true",
                    help="the course goes on from the goal back to the first waypoint, with the "
                         "same obstacles and twice the time limit (default: out only)")
    add_weather_arguments(ap)
    return ap


def wind_knots(text):
    """--wind's value: knots, 0 to 60."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError("expected knots, a number, got %r" % text)
    if not 0.0 <= value <= 60.0:
        raise argparse.ArgumentTypeError("expected 0 to 60 kt, got %g" % value)
    return value


def add_weather_arguments(ap):
    """--wind and --turbulence (shared with bench/monte_carlo.py)."""
    ap.add_argument("--wind", type=wind_knots, default=0.0, metavar="KT",
                    help="a steady wind of KT knots from a direction drawn from the seed "
                         "(default: 0, calm)")
    ap.add_argument("--turbulence", choices=TURBULENCE_LEVELS, default="none",
                    help="MIL-F-8785C turbulence on the wind, seeded by the field's seed "
                         "(default: none)")


def field_kind(args):
    """fair, dense or trap, from --dense / --trap."""
    return "trap" if getattr(args, "trap", False) else "dense" if args.dense else "fair"


def main(argv=None):
    args = build_parser().parse_args(argv)
    try:
        obstacles = write_field(args.seed, args.out, args.template, field_kind(args),
                                args.out_and_back, args.wind, args.turbulence)
    except OSError as exc:
        print("%s: error: %s: %s" % (PROG, exc.filename or args.out, exc.strerror), file=sys.stderr)
        return cr.EXIT_USAGE
    except (ValueError, RuntimeError) as exc:
        print("%s: error: %s" % (PROG, exc), file=sys.stderr)
        return cr.EXIT_USAGE
    print("%s: %d obstacles (%d tall)" % (args.out, len(obstacles),
                                          sum(1 for o in obstacles if is_tall(o))))
    return 0


if __name__ == "__main__":
    cr.run_main(PROG, main)
