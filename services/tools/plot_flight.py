#!/usr/bin/python3
"""Draw the flight-test figure of an obstacle-avoidance flight from a results folder.

Usage: plot_flight.py RESULTS_DIR [--out RESULTS_DIR/flight.png] [--scenario FILE] [--no-lidar]

Writes flight.png (top view, altitude, speed, true clearance, acceleration:
actual against the reference, the reference against its limit, the
controller's pseudo-control against its bound) and tracking.png (position
error), and prints the paths written. All inputs are SI, local NED; the
plots use the course frame (x = north, y = east, h = -down) in the display
unit named by summary.json. Each CSV header names its column's unit, as
ofn_flight_report writes them (``north [m]``); a column is read by its bare
name (``north``), so a header without the unit reads the same.

Command traces (reference acceleration, pseudo-control, tracking error)
show only the samples in which the controller flies a plan, as the
summary's figures count them: nothing of the hold before the mission
(CONTROL_STATUS mode HOLD), a stale navigation solution or the hold after
arrival (NAV_STALE, DONE).

numpy and matplotlib are imported once the command line has been read
(when run) or on import (as a module, bench/campaign_report.py), so that
--help, --version and a bad command line need neither. A missing module,
a missing or unreadable input and a figure that cannot be written are
one-line errors with exit code 2.
"""
import csv
import json
import math
import os
import re
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from ofn_cli import ArgumentParser, InputError, need, run_main  # noqa: E402

PROG = "services/tools/plot_flight.py"

# Set by import_plotting(): matplotlib (the Agg backend) and numpy.
np = plt = mtransforms = Circle = Polygon = Rectangle = None


def import_plotting():
    """numpy and matplotlib, headless (Agg: runs on test machines and in CI);
    MissingModule (one line, exit code 2) when either cannot be imported."""
    global np, plt, mtransforms, Circle, Polygon, Rectangle
    if plt is None:
        np = need("numpy")
        need("matplotlib").use("Agg")
        plt = need("matplotlib.pyplot")
        mtransforms = need("matplotlib.transforms")
        patches = need("matplotlib.patches")
        Circle, Polygon, Rectangle = patches.Circle, patches.Polygon, patches.Rectangle


if __name__ != "__main__":
    import_plotting()  # a module: its functions are used at once

REQUIRED = ("nav_state.csv", "control_status.csv", "waypoints.csv")
FOOTER = "course geometry: this project's reconstruction of the benchmark"
OBSTACLE_STYLE = dict(facecolor="#f4b6b6", edgecolor="#c0392b", alpha=0.8, lw=1.0)
# LIDAR hits are context, not the subject: small, light and under every outline.
SCAN_STYLE = dict(ls="none", marker=".", ms=0.8, color="0.6", alpha=0.5, zorder=0.5,
                  rasterized=True)
MAX_SCAN_POINTS = 30000  # hits drawn per view; more only slow the figure down
# lcmtypes/control_status_t.lcm
CONTROL_MODES = {0: "HOLD", 1: "WAYPOINT", 2: "TRAJECTORY", 3: "NAV_STALE", 4: "DONE",
                 5: "SAFE_STOP"}
# The modes in which the controller does not fly a plan; the flight report
# (flies_a_plan in services/tools/src/flight_analysis.cpp) leaves the same out.
NOT_FLYING_A_PLAN = (0, 3, 4)
CLEARANCE_FAIL_SHARE = 0.8  # of R_s (flight_analysis.hpp, kClearanceFailShare)
FRAME_MARGIN = 0.06  # share of the larger extent added round the top view's frame


def fail(msg):
    """A missing or unusable input: one line, exit code 2 (run_main)."""
    raise InputError(msg)


def column_name(header):
    """The bare column name: 'north [m]' and 'north (m)' read as 'north'."""
    return re.sub(r"\s*[\[(][^\])]*[\])]\s*$", "", header.strip())


def load_csv(results, name, required):
    """Read a CSV into {column: float array}; None if an optional file is absent.

    The csv module is used instead of genfromtxt because it copes with
    header-only files and non-numeric cells (e.g. a mode name) without warnings.
    """
    path = os.path.join(results, name)
    if not os.path.isfile(path):
        if required:
            fail("required file missing: " + path)
        return None
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        return {}
    header = [column_name(h) for h in rows[0]]
    cols = {h: [] for h in header}
    for row in rows[1:]:
        if not row:
            continue
        for h, cell in zip(header, row + [""] * (len(header) - len(row))):
            try:
                cols[h].append(float(cell))
            except ValueError:
                cols[h].append(math.nan)
    return {h: np.asarray(v, dtype=float) for h, v in cols.items()}


def col(data, name):
    """Column or an empty array, so absent data never raises."""
    if not data or name not in data:
        return np.empty(0)
    return data[name]


def nrows(data):
    return max((len(v) for v in data.values()), default=0) if data else 0


def no_data(ax, text="no data"):
    ax.text(0.5, 0.5, text, transform=ax.transAxes, ha="center", va="center", color="grey",
            fontsize=10, wrap=True)


def draw_gates(ax, positions, labels=True):
    """Dotted vertical lines; labels sit at the top of the axes, whatever the data range."""
    trans = mtransforms.blended_transform_factory(ax.transData, ax.transAxes)
    for x, label in positions:
        if x is None or not np.isfinite(x):
            continue
        ax.axvline(x, color="k", ls=":", lw=1.0)
        if labels:
            ax.text(x, 0.98, " " + label, transform=trans, va="top", ha="left", fontsize=8)


def verdict_of(summary):
    """(outcome, first failure line or None) from the summary; a summary
    written before the outcome field gives success or failure from its
    success flag, and (None, None) when it has neither."""
    outcome = summary.get("outcome")
    if outcome is None and "success" in summary:
        outcome = "success" if summary["success"] else "failure"
    failures = summary.get("failures") or []
    reason = str(failures[0]) if outcome == "failure" and failures else None
    return outcome, reason


def verdict_title(summary, name=None):
    """(first line, second line or None) of a flight's title: the scenario
    (or `name`), the gate-to-gate time and the outcome; on failure the first
    failure line, with how many more the summary lists."""
    head = name or str(summary.get("scenario", "flight"))
    t0, t1 = summary.get("gate_start_t"), summary.get("gate_finish_t")
    if t0 is not None and t1 is not None:
        head += "   gate-to-gate %.1f s" % (t1 - t0)
    outcome, reason = verdict_of(summary)
    head += "   outcome: " + (outcome or "not judged")
    if reason:
        more = len(summary.get("failures") or []) - 1
        if more > 0:
            reason += "   (and %d more failure%s)" % (more, "s" if more > 1 else "")
    return head, reason


def course_gates(summary, k):
    """Gate lines (north coordinate, display unit); either may be null in the summary."""
    gates = summary.get("gates") or {}
    return [(None if gates.get(key) is None else float(gates[key]) * k, label)
            for key, label in (("start_x", "start"), ("finish_x", "finish"))]


def obstacle_footprint(ob):
    """Footprint corners (north, east) in metres; None for round obstacles."""
    cn, ce = ob["center"]
    a, b = (list(ob.get("size", [0, 0])) + [0, 0])[:2]
    yaw = float(ob.get("yaw", 0.0) or 0.0)
    c, s = math.cos(yaw), math.sin(yaw)
    local = [(a / 2, b / 2), (-a / 2, b / 2), (-a / 2, -b / 2), (a / 2, -b / 2)]
    return [(cn + x * c - y * s, ce + x * s + y * c) for x, y in local]


def obstacle_extent(ob):
    """((north low, north high), (east low, east high)) of a footprint, metres."""
    if ob.get("kind") in ("cylinder", "tree"):
        cn, ce = ob["center"]
        a, b = (list(ob.get("size", [0, 0])) + [0, 0])[:2]
        return (cn - 0.5 * a, cn + 0.5 * a), (ce - 0.5 * b, ce + 0.5 * b)
    pts = obstacle_footprint(ob)
    ns, es = [p[0] for p in pts], [p[1] for p in pts]
    return (min(ns), max(ns)), (min(es), max(es))


# --------------------------------------------------------------------------- control modes

def flying_a_plan(ctl):
    """Per CONTROL_STATUS sample: does the controller fly a plan? All true
    when the file has no mode column."""
    mode = col(ctl, "mode")
    if not len(mode):
        return np.ones(nrows(ctl), dtype=bool)
    return ~np.isin(mode, NOT_FLYING_A_PLAN)


def while_flying(ctl, values):
    """The values with NaN in the samples in which no plan is flown (a line
    breaks there instead of showing a hold's command)."""
    out = np.array(values, dtype=float, copy=True)
    mask = flying_a_plan(ctl)
    if len(out) == len(mask):
        out[~mask] = np.nan
    return out


def idle_spans(ctl):
    """[(t begin, t end, mode names)] of the stretches without a plan flown."""
    t, mask = col(ctl, "t"), flying_a_plan(ctl)
    mode = col(ctl, "mode")
    spans, i = [], 0
    while i < len(t):
        if mask[i]:
            i += 1
            continue
        j = i
        while j + 1 < len(t) and not mask[j + 1]:
            j += 1
        names = [CONTROL_MODES.get(m, str(m))
                 for m in sorted({int(m) for m in mode[i:j + 1] if np.isfinite(m)})]
        end = t[j + 1] if j + 1 < len(t) else t[j]
        spans.append((t[i], end, names))
        i = j + 1
    return spans


def shade_idle(ax, spans, label=True):
    names = []
    for _, _, ns in spans:
        names += [n for n in ns if n not in names]
    for i, (t0, t1, _) in enumerate(spans):
        ax.axvspan(t0, t1, color="0.88", zorder=0,
                   label="no plan flown (%s)" % ", ".join(names) if label and i == 0 else None)


# --------------------------------------------------------------------------- framing

def frame_of(points, margin_share=FRAME_MARGIN):
    """(x0, x1, y0, y1) round the finite points [(xs, ys)], with a margin;
    None when there are none."""
    xs = np.concatenate([np.ravel(np.asarray(x, dtype=float)) for x, _ in points] or [[]])
    ys = np.concatenate([np.ravel(np.asarray(y, dtype=float)) for _, y in points] or [[]])
    ok = np.isfinite(xs) & np.isfinite(ys)
    if not ok.any():
        return None
    x0, x1, y0, y1 = xs[ok].min(), xs[ok].max(), ys[ok].min(), ys[ok].max()
    m = margin_share * max(x1 - x0, y1 - y0, 1.0)
    return x0 - m, x1 + m, y0 - m, y1 + m


def obstacle_points(summary, k):
    """Footprint extremes of every obstacle, display unit, as (xs, ys)."""
    xs, ys = [], []
    for ob in summary.get("obstacles") or []:
        (n0, n1), (e0, e1) = obstacle_extent(ob)
        xs += [n0 * k, n1 * k]
        ys += [e0 * k, e1 * k]
    return xs, ys


def fit_equal(ax, frame):
    """Limits that show the whole frame at equal scale in x and y, in the
    axes' box as laid out now: the shorter side is widened about its
    centre. The axes keep adjustable 'datalim', which then leaves them as
    they are."""
    if frame is None:
        return
    x0, x1, y0, y1 = frame
    bb = ax.get_window_extent()
    ratio = bb.height / max(bb.width, 1e-9)
    xr, yr = x1 - x0, y1 - y0
    xr_shown = max(xr, yr / ratio)
    xc, yc = 0.5 * (x0 + x1), 0.5 * (y0 + y1)
    ax.set_xlim(xc - 0.5 * xr_shown, xc + 0.5 * xr_shown)
    ax.set_ylim(yc - 0.5 * xr_shown * ratio, yc + 0.5 * xr_shown * ratio)
    ax.set_aspect("equal", adjustable="datalim")


def finite_max(values, default=0.0):
    values = np.asarray(values, dtype=float)
    values = values[np.isfinite(values)]
    return float(values.max()) if len(values) else default


def subsample(data, limit):
    n = nrows(data)
    if n <= limit:
        return data
    idx = np.linspace(0, n - 1, limit).astype(int)
    return {c: v[idx] for c, v in data.items()}


# --------------------------------------------------------------------------- clearance

def read_ground_altitude(scenario_path):
    """environment.ground_altitude of a scenario file, metres (0 when absent)."""
    yaml = need("yaml")  # python3-yaml; only needed with --scenario
    with open(scenario_path) as f:
        try:
            doc = yaml.safe_load(f) or {}
        except yaml.YAMLError as exc:
            raise ValueError("not valid YAML: " + " ".join(str(exc).split()))
    if not isinstance(doc, dict):
        raise ValueError("not a scenario (a YAML mapping)")
    per_unit = 0.3048 if doc.get("units") == "ft" else 1.0
    return float((doc.get("environment") or {}).get("ground_altitude", 0.0) or 0.0) * per_unit


def true_clearance(nav, summary, ground_altitude=0.0):
    """Distance from every navigation sample to the real obstacles present
    then and to the ground, metres, computed from the obstacles in
    summary.json as the flight report's world does (services/world): boxes
    with a yaw and vertical cylinders exactly. A tree's seeded canopy is not
    in the summary; its bounding box stands in, which gives a lower bound.

    Returns {"t", "least", "obstacles", "ground", "lower_bound", "note"}, or
    {"note": why} without the arrays when it cannot be computed."""
    if summary.get("min_clearance") is None:
        return {"note": "the report knew no world (made without a scenario):\n"
                        "no true clearance to draw"}
    t = col(nav, "t")
    n, e, d = col(nav, "north"), col(nav, "east"), col(nav, "down")
    if not len(t) or not (len(t) == len(n) == len(e) == len(d)):
        return {"note": "no navigation data"}
    ground_z = -ground_altitude
    to_obstacles = np.full(len(t), np.inf)
    lower_bound = False
    for ob in summary.get("obstacles") or []:
        kind = ob.get("kind", "box")
        cn, ce = (float(v) for v in ob["center"])
        length, width = (float(v) for v in (list(ob.get("size", [0, 0])) + [0, 0])[:2])
        height = float(ob.get("height", 0.0))
        top_z = ground_z - height
        if kind == "box":
            yaw = float(ob.get("yaw", 0.0) or 0.0)
            c, s = math.cos(yaw), math.sin(yaw)
            rn, re_ = n - cn, e - ce
            local = np.stack([c * rn + s * re_, -s * rn + c * re_, d - 0.5 * (top_z + ground_z)])
            half = np.array([0.5 * length, 0.5 * width, 0.5 * height])[:, None]
            dist = np.linalg.norm(np.maximum(np.abs(local) - half, 0.0), axis=0)
        elif kind in ("cylinder", "tree"):
            vertical = np.maximum(np.maximum(top_z - d, d - ground_z), 0.0)
            if kind == "cylinder":
                radial = np.maximum(np.hypot(n - cn, e - ce) - 0.5 * length, 0.0)
            else:  # the tree's box: trunk and canopy lie inside it
                lower_bound = True
                radial = np.hypot(np.maximum(np.abs(n - cn) - 0.5 * length, 0.0),
                                  np.maximum(np.abs(e - ce) - 0.5 * width, 0.0))
            dist = np.hypot(radial, vertical)
        else:
            return {"note": "obstacle kind '%s' unknown to this plot:\n"
                            "no true clearance to draw" % kind}
        appear = float(ob.get("appear_time", -1))
        disappear = float(ob.get("disappear_time", -1))
        present = ((appear < 0) | (t >= appear)) & ((disappear < 0) | (t < disappear))
        to_obstacles = np.minimum(to_obstacles, np.where(present, dist, np.inf))
    to_ground = np.maximum(-d - ground_altitude, 0.0)
    least = np.minimum(to_obstacles, to_ground)
    note = None
    reported = float(summary["min_clearance"])
    computed = float(np.nanmin(least))
    if lower_bound:
        note = ("no per-sample true clearance in the data, and a tree's\n"
                "canopy is not in summary.json: the curve is a lower bound")
    elif abs(computed - reported) > max(0.01, 1e-3 * reported):
        note = ("computed least %.2f m differs from the report's %.2f m\n"
                "(ground altitude? pass --scenario)" % (computed, reported))
    return {"t": t, "least": least, "obstacles": to_obstacles, "ground": to_ground,
            "lower_bound": lower_bound, "note": note}


def panel_clearance(ax, k, unit, clearance, summary, gate_times):
    """Least true clearance against time, with R_s and 0.8 R_s, the report's
    least clearance as a circle, and the legend (titled with what is
    missing, if anything). A curve that is only a bound, or that disagrees
    with the report, is drawn faint and named so."""
    rs = summary.get("clearance_required")
    top = None
    if "least" in clearance:
        t = clearance["t"]
        if clearance["lower_bound"] or clearance.get("note"):
            ax.plot(t, clearance["least"] * k, ":", color="0.35", lw=1.2, gid="clearance-bound",
                    label=("lower bound (trees as their boxes)" if clearance["lower_bound"]
                           else "computed here, disagrees with the report"))
        else:
            ax.plot(t, clearance["least"] * k, "-", color="tab:blue", lw=1.5, gid="clearance",
                    label="least true clearance (obstacles, ground)")
        ax.plot(t, clearance["ground"] * k, ":", color="tab:green", lw=0.9, label="to the ground")
        top = 1.05 * finite_max(clearance["least"]) * k or None
    if summary.get("min_clearance") is not None and summary.get("min_clearance_t") is not None:
        ax.plot([summary["min_clearance_t"]], [summary["min_clearance"] * k], "o", mfc="none",
                mec="k", ms=7, zorder=5, gid="report-least",
                label="report: least %.1f %s at %.1f s" % (summary["min_clearance"] * k, unit,
                                                          summary["min_clearance_t"]))
    if rs is not None:
        ax.axhline(rs * k, color="orange", ls="--", lw=1.0, gid="R_s",
                   label="R_s = %.3g %s" % (rs * k, unit))
        ax.axhline(CLEARANCE_FAIL_SHARE * rs * k, color="red", ls="--", lw=1.0, gid="0.8 R_s",
                   label="0.8 R_s = %.3g %s (failure below)" % (CLEARANCE_FAIL_SHARE * rs * k,
                                                                unit))
        # Far from every obstacle the clearance is the height: keep the
        # interesting band, near R_s, legible.
        top = max(1.6 * rs * k, min(top, 6.0 * rs * k)) if top else 2.0 * rs * k
    if top:
        ax.set_ylim(0.0, top)
    draw_gates(ax, gate_times, labels=False)
    note = clearance.get("note")
    leg = ax.legend(fontsize=7, loc="best", framealpha=0.8, title=note, title_fontsize=7)
    if note:
        leg.get_title().set_color("firebrick")


# --------------------------------------------------------------------------- panels

def draw_plans(ax, k, gpath, ref, axis, sign):
    """Planned routes against north: every global path faintly, the one that
    strays furthest from the straight line (the route round or over the
    obstacles) boldly, and the RH optimiser's trajectories as thin lines."""
    if gpath is not None and nrows(gpath) and "seq" in gpath:
        seq = col(gpath, "seq")
        best, best_dev = None, 0.0
        for s_id in np.unique(seq):
            sel = seq == s_id
            n, v = gpath["north"][sel], gpath[axis][sel]
            ax.plot(n * k, sign * v * k, "-", color="tab:green", lw=0.4, alpha=0.25)
            dev = np.nanmax(np.abs(v - v[0])) if len(v) else 0.0
            if best is None or dev > best_dev:
                best, best_dev = sel, dev
        ax.plot(gpath["north"][best] * k, sign * gpath[axis][best] * k, "--",
                color="tab:green", lw=1.2, label="global path")
    if ref is not None and nrows(ref) and "seq" in ref:
        seq = col(ref, "seq")
        for i, s_id in enumerate(np.unique(seq)):
            sel = seq == s_id
            ax.plot(ref["north"][sel] * k, sign * ref[axis][sel] * k, "-", color="tab:orange",
                    lw=0.5, alpha=0.6, label="RH trajectories" if i == 0 else None)


def draw_scan(ax, x, y):
    """LIDAR hits, light and small under every outline; the legend gets a
    visible marker of its own."""
    ax.plot(x, y, gid="lidar", **SCAN_STYLE)
    ax.plot([], [], ls="none", marker=".", ms=5, color=SCAN_STYLE["color"], label="LIDAR hits")


def top_view_frame(k, nav, ctl, wps, summary):
    """The top view's frame: the flown path, the reference while a plan is
    flown, the waypoints, the gates and every obstacle, not the LIDAR hits
    (ground hits reach far past the goal) nor the mapped cuboids."""
    pts = [(col(nav, "north") * k, col(nav, "east") * k),
           (while_flying(ctl, col(ctl, "ref_n")) * k, while_flying(ctl, col(ctl, "ref_e")) * k),
           (col(wps, "north") * k, col(wps, "east") * k),
           obstacle_points(summary, k)]
    frame = frame_of(pts)
    gx = [x for x, _ in course_gates(summary, k) if x is not None]
    if frame is not None and gx:
        x0, x1, y0, y1 = frame
        frame = (min([x0] + gx), max([x1] + gx), y0, y1)
    return frame


def panel_top_view(ax, k, nav, ctl, wps, summary, gpath, ref, scan, cuboids):
    for ob in summary.get("obstacles") or []:
        cn, ce = ob["center"]
        if ob.get("kind") in ("cylinder", "tree"):
            r = 0.5 * float(ob["size"][0]) * k
            hatch = "xx" if ob.get("kind") == "tree" else None
            ax.add_patch(Circle((cn * k, ce * k), r, hatch=hatch, **OBSTACLE_STYLE))
        else:
            pts = [(n * k, e * k) for n, e in obstacle_footprint(ob)]
            ax.add_patch(Polygon(pts, closed=True, **OBSTACLE_STYLE))
    if cuboids is not None and nrows(cuboids):
        for i in range(nrows(cuboids)):
            n0, n1 = cuboids["min_n"][i] * k, cuboids["max_n"][i] * k
            e0, e1 = cuboids["min_e"][i] * k, cuboids["max_e"][i] * k
            ax.add_patch(Rectangle((n0, e0), n1 - n0, e1 - e0, fill=False, zorder=3,
                                   ls="--", ec="purple", lw=0.9,
                                   label="mapped cuboids" if i == 0 else None))
    if scan is not None and nrows(scan):
        draw_scan(ax, col(scan, "north") * k, col(scan, "east") * k)
    draw_plans(ax, k, gpath, ref, "east", 1.0)
    ax.plot(while_flying(ctl, col(ctl, "ref_n")) * k, while_flying(ctl, col(ctl, "ref_e")) * k,
            "--", color="tab:red", lw=1, label="reference")
    ax.plot(col(nav, "north") * k, col(nav, "east") * k, "-", color="tab:blue",
            lw=1.5, label="flown", gid="flown", zorder=4)
    ax.plot(col(wps, "north") * k, col(wps, "east") * k, "k^", ms=6, label="waypoints", zorder=4)
    draw_gates(ax, course_gates(summary, k))
    if not nrows(nav):
        no_data(ax)


def panel_altitude(ax, k, nav, ctl, wps, summary, cuboids, scan, gpath, ref):
    for ob in summary.get("obstacles") or []:
        (x0, x1), _ = obstacle_extent(ob)
        # Obstacles stand on the ground (h = 0): the bar shows what must be cleared.
        ax.add_patch(Rectangle((x0 * k, 0), (x1 - x0) * k, float(ob.get("height", 0)) * k,
                               hatch="xx" if ob.get("kind") == "tree" else None,
                               **OBSTACLE_STYLE))
    if cuboids is not None and nrows(cuboids):
        for i in range(nrows(cuboids)):
            n0, n1 = cuboids["min_n"][i] * k, cuboids["max_n"][i] * k
            h0, h1 = -cuboids["max_d"][i] * k, -cuboids["min_d"][i] * k
            # A cuboid whose top the sensor never saw reaches the mapper's ceiling.
            seen = "top_observed" not in cuboids or cuboids["top_observed"][i] > 0
            ax.add_patch(Rectangle((n0, h0), n1 - n0, h1 - h0, fill=False, zorder=3,
                                   ls="--" if seen else ":", ec="purple", lw=0.9,
                                   label="mapped cuboids" if i == 0 else None))
    if scan is not None and nrows(scan):
        draw_scan(ax, col(scan, "north") * k, -col(scan, "down") * k)
    draw_plans(ax, k, gpath, ref, "down", -1.0)
    ref_h = -while_flying(ctl, col(ctl, "ref_d")) * k
    ax.plot(while_flying(ctl, col(ctl, "ref_n")) * k, ref_h, "--", color="tab:red", lw=1,
            label="reference")
    ax.plot(col(nav, "north") * k, -col(nav, "down") * k, "-", color="tab:blue",
            lw=1.5, label="flown", zorder=4)
    ax.plot(col(wps, "north") * k, -col(wps, "down") * k, "k^", ms=6, label="waypoints", zorder=4)
    draw_gates(ax, course_gates(summary, k))
    if not nrows(nav):
        no_data(ax)
    # Framed on the flight and the real obstacles: not on the LIDAR hits, nor
    # on cuboids whose unseen tops reach the mapper's ceiling.
    heights = [float(ob.get("height", 0)) * k for ob in summary.get("obstacles") or []]
    for h in (-col(nav, "down") * k, -col(wps, "down") * k, ref_h):
        h = h[np.isfinite(h)]
        if len(h):
            heights += [float(h.max()), float(h.min())]
    if heights:
        top = max(max(heights), 1.0)
        ax.set_ylim(min(0.0, min(heights)) - 0.03 * top, 1.15 * top)


def panel_speed(ax, k, nav, summary, gate_times):
    t = col(nav, "t")
    v = np.sqrt(col(nav, "vn") ** 2 + col(nav, "ve") ** 2 + col(nav, "vd") ** 2)
    ax.plot(t, v * k, color="tab:blue", lw=1.5, label="speed")
    ax.plot(t, -col(nav, "vd") * k, color="0.5", lw=0.8, label="climb rate")
    lim = summary.get("limits") or {}
    if lim.get("max_speed") is not None:
        ax.axhline(lim["max_speed"] * k, color="red", ls="--", lw=1, label="speed limit")
    if lim.get("max_vertical_speed") is not None:
        for sign in (1, -1):
            ax.axhline(sign * lim["max_vertical_speed"] * k, color="orange", ls="--",
                       lw=0.8, label="climb limit" if sign > 0 else None)
    draw_gates(ax, gate_times)
    if not nrows(nav):
        no_data(ax)


def panel_accel(axes, k, nav, ctl, summary, gate_times, unit):
    """Five panels against time, every trace named for what it is:
    x, y, h components of the actual acceleration against the reference
    acceleration (what the trajectory source commands, the quantity the
    summary calls commanded); |reference| against the acceleration limit;
    the controller's pseudo-control (command plus feedback corrections),
    horizontal norm and vertical part, against the bounds it is clamped to.
    The command traces leave out the samples in which no plan is flown.
    Signs flip down to up for h so that a climb reads positive."""
    t_ctl = col(ctl, "t")
    spans = idle_spans(ctl)
    ref = [while_flying(ctl, col(ctl, "ref_" + c)) for c in ("an", "ae", "ad")]
    pseudo = [while_flying(ctl, col(ctl, "cmd_" + c)) for c in ("an", "ae", "ad")]
    comps = [("x", "an", 1), ("y", "ae", 1), ("h", "ad", -1)]
    for i, (ax, (name, act, sign)) in enumerate(zip(axes[:3], comps)):
        shade_idle(ax, spans, label=False)
        ax.plot(col(nav, "t"), sign * col(nav, act) * k, "-", color="tab:blue", lw=0.9,
                label="actual")
        ax.plot(t_ctl, sign * ref[i] * k, "--", color="tab:red", lw=1,
                label="reference (commanded)", gid="reference")
        ax.set_ylabel("a_%s [%s/s²]" % (name, unit), fontsize=8)
        draw_gates(ax, gate_times, labels=False)
        if not nrows(nav) and not nrows(ctl):
            no_data(ax)
    axes[0].legend(fontsize=7, loc="upper right", ncol=2)

    ax = axes[3]
    shade_idle(ax, spans)
    mag = np.sqrt(sum(r ** 2 for r in ref))
    ax.plot(t_ctl, mag * k, color="tab:red", lw=1, label="|reference (commanded)|",
            gid="reference")
    limit = (summary.get("limits") or {}).get("max_accel")
    if limit is not None:
        ax.axhline(limit * k, color="red", ls="--", lw=0.9,
                   label="limit %.3g %s/s²" % (limit * k, unit))
    ax.set_ylabel("|a_ref| [%s/s²]" % unit, fontsize=8)
    # A magnitude: zero and the limit in view.
    ax.set_ylim(0.0, 1.5 * max(finite_max(mag * k), (limit or 0.0) * k, 1e-3))
    draw_gates(ax, gate_times, labels=False)
    ax.legend(fontsize=7, loc="upper left", ncol=3)
    if not nrows(ctl):
        no_data(ax)

    ax = axes[4]
    shade_idle(ax, spans, label=False)
    horizontal = np.hypot(pseudo[0], pseudo[1])
    ax.plot(t_ctl, horizontal * k, color="tab:purple", lw=1,
            label="pseudo-control, horizontal |u_xy|", gid="pseudo-control")
    ax.plot(t_ctl, np.abs(pseudo[2]) * k, color="tab:brown", lw=1,
            label="pseudo-control, vertical |u_h|", gid="pseudo-control")
    bound = summary.get("pseudo_control_bound") or {}
    if bound.get("horizontal") is not None:
        ax.axhline(bound["horizontal"] * k, color="tab:purple", ls="--", lw=0.9,
                   label="horizontal bound %.3g" % (bound["horizontal"] * k))
    if bound.get("vertical") is not None:
        ax.axhline(bound["vertical"] * k, color="tab:brown", ls="--", lw=0.9,
                   label="vertical bound %.3g" % (bound["vertical"] * k))
    if not bound:
        ax.text(0.01, 0.9, "bound not in summary.json", transform=ax.transAxes, fontsize=7,
                color="grey", va="top")
    ax.set_ylabel("|u| [%s/s²]" % unit, fontsize=8)
    # Room above the largest line for the legend.
    ax.set_ylim(0.0, 1.4 * max(finite_max(horizontal * k), finite_max(np.abs(pseudo[2]) * k),
                               *[(v or 0.0) * k for v in bound.values()], 1e-3))
    ax.set_xlabel("t [s]")
    draw_gates(ax, gate_times, labels=False)
    ax.legend(fontsize=7, loc="upper left", ncol=2)
    if not nrows(ctl):
        no_data(ax)


def tracking_figure(k, unit, nav, ctl, title):
    """Position error ref - actual while a plan is flown, interpolating the
    flown path at the reference times. Returns the Figure."""
    t = col(ctl, "t")
    tn = col(nav, "t")
    ok = np.isfinite(tn)  # np.interp needs finite, increasing sample times
    order = np.argsort(tn[ok])
    if len(order) >= 2 and len(t):
        errs = [col(ctl, "ref_" + c) - np.interp(t, tn[ok][order], col(nav, name)[ok][order])
                for c, name in (("n", "north"), ("e", "east"), ("d", "down"))]
    else:  # fall back to the controller's own error report
        errs = [col(ctl, "err_" + c) for c in ("n", "e", "d")]
    errs = [while_flying(ctl, e) for e in errs]
    errs[2] = -errs[2]  # down -> up, matching the course frame
    fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    spans = idle_spans(ctl)
    for e, name in zip(errs, ("x", "y", "h")):
        ax[0].plot(t, e * k, lw=1, label="e_" + name)
    ax[1].plot(t, np.sqrt(sum(e ** 2 for e in errs)) * k, color="k", lw=1, label="|e|")
    ax[0].set_ylabel("reference - actual [%s]" % unit)
    ax[1].set_ylabel("error norm [%s]" % unit)
    ax[1].set_xlabel("t [s]")
    for i, a in enumerate(ax):
        shade_idle(a, spans, label=i == 1)
        a.grid(alpha=0.3)
        a.legend(fontsize=8, loc="upper right")
        if not len(t):
            no_data(a)
    fig.suptitle(title + " - tracking error")
    fig.tight_layout()
    return fig


# --------------------------------------------------------------------------- the figure

def load_results(res, scenario=None):
    """Everything the figures read from a results folder, as a dict."""
    summary_path = os.path.join(res, "summary.json")
    if not os.path.isfile(summary_path):
        fail("required file missing: " + summary_path)
    try:
        with open(summary_path) as f:
            summary = json.load(f)
    except (OSError, ValueError) as exc:
        fail("cannot read %s: %s" % (summary_path, exc))
    nav, ctl, wps = (load_csv(res, n, True) for n in REQUIRED)
    ground = 0.0
    if scenario:
        try:
            ground = read_ground_altitude(scenario)
        except OSError as exc:
            fail("--scenario: cannot read %s: %s" % (scenario, exc.strerror))
        except (ValueError, TypeError, AttributeError) as exc:
            fail("--scenario: cannot read the ground altitude of %s: %s" % (scenario, exc))
    return dict(summary=summary, nav=nav, ctl=ctl, wps=wps, ground_altitude=ground,
                gpath=load_csv(res, "global_path.csv", False),
                ref=load_csv(res, "ref_traj.csv", False),
                scan=load_csv(res, "scan_points.csv", False),
                cuboids=load_csv(res, "cuboids.csv", False),
                name=str(summary.get("scenario", os.path.basename(os.path.abspath(res)))))


def flight_figure(data, lidar=True):
    """The flight figure of load_results()' data; returns the Figure, laid
    out and framed (axes named by their label: top view, altitude, speed,
    clearance, a_x, a_y, a_h, reference, pseudo-control)."""
    summary, nav, ctl, wps = data["summary"], data["nav"], data["ctl"], data["wps"]
    scan = subsample(data.get("scan"), MAX_SCAN_POINTS) if lidar else None
    unit = summary.get("display_unit", "m")
    k = 1.0 / float(summary.get("metres_per_unit") or 1.0)  # metres -> display unit
    gate_times = [(summary.get("gate_start_t"), "start"), (summary.get("gate_finish_t"), "finish")]
    head, reason = verdict_title(summary, data.get("name"))
    outcome, _ = verdict_of(summary)

    # The top view's height follows the frame's shape, so that equal scale
    # in x and y leaves little empty space.
    frame = top_view_frame(k, nav, ctl, wps, summary)
    width, plot_width = 12.0, 9.7  # inches: the figure, the top view (its legend beside it)
    top_h = 3.0
    if frame is not None:
        # The axes' height, plus the room of their title and tick labels.
        top_h = float(np.clip(plot_width * (frame[3] - frame[2]) / (frame[1] - frame[0]),
                              1.6, 7.0)) + 0.9
    heights = [top_h, 2.6, 6.6]
    fig = plt.figure(figsize=(width, sum(heights) + 2.6))
    gs = fig.add_gridspec(3, 2, height_ratios=heights)
    ax_top = fig.add_subplot(gs[0, :], label="top view")
    ax_alt = fig.add_subplot(gs[1, :], sharex=ax_top, label="altitude")
    left = gs[2, 0].subgridspec(2, 1, hspace=0.45)
    ax_spd = fig.add_subplot(left[0], label="speed")
    ax_clr = fig.add_subplot(left[1], sharex=ax_spd, label="clearance")
    right = gs[2, 1].subgridspec(5, 1, hspace=0.12, height_ratios=[1, 1, 1, 1.3, 1.3])
    ax_acc = [fig.add_subplot(right[0], sharex=ax_spd, label="a_x")]
    ax_acc += [fig.add_subplot(right[i], sharex=ax_spd, label=name)
               for i, name in ((1, "a_y"), (2, "a_h"), (3, "reference"), (4, "pseudo-control"))]

    panel_top_view(ax_top, k, nav, ctl, wps, summary, data.get("gpath"), data.get("ref"),
                   scan, data.get("cuboids"))
    ax_top.set(xlabel="x (north) [%s]" % unit, ylabel="y (east) [%s]" % unit, title="top view")
    panel_altitude(ax_alt, k, nav, ctl, wps, summary, data.get("cuboids"), scan,
                   data.get("gpath"), data.get("ref"))
    ax_alt.set(xlabel="x (north) [%s]" % unit, ylabel="h [%s]" % unit, title="altitude")
    panel_speed(ax_spd, k, nav, summary, gate_times)
    ax_spd.set(ylabel="speed [%s/s]" % unit, title="speed")
    clearance = true_clearance(nav, summary, data.get("ground_altitude", 0.0))
    panel_clearance(ax_clr, k, unit, clearance, summary, gate_times)
    ax_clr.set(xlabel="t [s]", ylabel="clearance [%s]" % unit,
               title="least true clearance to the obstacles and the ground")
    panel_accel(ax_acc, k, nav, ctl, summary, gate_times, unit)
    ax_acc[0].set_title("acceleration: actual (solid) and reference (dashed); pseudo-control",
                        fontsize=11)
    for ax in ax_acc[:4]:
        ax.tick_params(labelbottom=False)
    for ax in [ax_top, ax_alt, ax_spd, ax_clr] + ax_acc:
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
    for ax in (ax_top, ax_alt):
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.002, 1.0), framealpha=0.7)
    ax_spd.legend(fontsize=7, loc="best", framealpha=0.7)

    fig_h = fig.get_size_inches()[1]
    fig.suptitle(head + ("\n" + reason if reason else ""), fontsize=13, y=1 - 0.12 / fig_h,
                 va="top", color="firebrick" if outcome == "failure" else "black")
    fig.text(0.99, 0.003, FOOTER, ha="right", va="bottom", fontsize=7, color="0.4")
    # tight_layout makes room for the suptitle itself.
    fig.tight_layout(rect=(0, 0.15 / fig_h, 1, 1 - 0.1 / fig_h))
    fit_equal(ax_top, frame)  # after the layout: it needs the axes' box
    return fig


def build_parser():
    ap = ArgumentParser(PROG, __doc__.splitlines()[0],
                        epilog="Example:\n"
                               "  /usr/bin/python3 services/tools/plot_flight.py results/lockstep\n"
                               "\n"
                               "Exit codes: 0 when the figures are written; 2 for a bad command line,\n"
                               "a missing or unreadable input, a figure that cannot be written or a\n"
                               "missing Python module (numpy, matplotlib; PyYAML with --scenario).")
    ap.add_argument("results_dir", metavar="RESULTS_DIR",
                    help="folder written by ofn_flight_report or ofn_sim_runner --out (required)")
    ap.add_argument("--out", metavar="FILE",
                    help="flight figure path; tracking.png goes beside it "
                         "(default: RESULTS_DIR/flight.png)")
    ap.add_argument("--scenario", metavar="FILE",
                    help="the flight's scenario file, for the ground altitude of the clearance "
                         "(default: the ground at altitude 0)")
    ap.add_argument("--no-lidar", action="store_true",
                    help="leave the LIDAR hits out (default: drawn)")
    return ap


def save(fig, path, dpi):
    try:
        fig.savefig(path, dpi=dpi)
    except OSError as exc:
        fail("cannot write %s: %s" % (path, exc.strerror or exc))
    finally:
        plt.close(fig)
    print(path)


def main(argv=None):
    args = build_parser().parse_args(argv)
    res = args.results_dir
    if not os.path.isdir(res):
        fail("results folder not found: " + res)
    if args.scenario is not None and not os.path.isfile(args.scenario):
        fail("--scenario: no file " + args.scenario)
    import_plotting()
    out = args.out or os.path.join(res, "flight.png")
    data = load_results(res, args.scenario)

    fig = flight_figure(data, lidar=not args.no_lidar)
    out_dir = os.path.dirname(os.path.abspath(out))
    try:
        os.makedirs(out_dir, exist_ok=True)
    except OSError as exc:
        fail("--out: cannot create %s: %s" % (out_dir, exc.strerror or exc))
    save(fig, out, 110)

    summary = data["summary"]
    k = 1.0 / float(summary.get("metres_per_unit") or 1.0)
    head, _ = verdict_title(summary, data["name"])
    track = os.path.join(out_dir, "tracking.png")
    save(tracking_figure(k, summary.get("display_unit", "m"), data["nav"], data["ctl"], head),
         track, 120)
    return 0


if __name__ == "__main__":
    run_main(PROG, main)
