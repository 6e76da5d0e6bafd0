#!/usr/bin/python3
"""Figures and Markdown tables of the benchmark campaign and the Monte Carlo fields.

Importable (campaign.py and monte_carlo.py use it); run on its own it draws
the course figure of one results folder:

    campaign_report.py RESULTS_DIR [--baseline DIR] [--out fig.png] [--tree]

All inputs are SI, local NED (summary.json, nav_state.csv, control_status.csv,
scan_points.csv, baseline_trajectory.csv); figures and tables use the course
frame (x = north, y = east, h = -down) in the display unit of summary.json.
"""
import argparse
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "services", "tools"))

import plot_flight as pf  # noqa: E402  (sets the Agg backend)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle, Polygon, Rectangle  # noqa: E402
from matplotlib.ticker import MaxNLocator  # noqa: E402

RECONSTRUCTION_NOTE = ("The course geometry is this project's reconstruction of the rotorcraft "
                       "obstacle-field-navigation benchmarks (/work/shared/BENCHMARKS.md), "
                       "not the original data.")
MAX_SCAN_POINTS = 20000  # LIDAR hits drawn per view; more only slows the figure down
FAIL_LINE = 0.8  # share of R_s below which a run fails (BENCHMARKS.md)
SMOOTHING_S = 0.5


# --------------------------------------------------------------------------- reading

def read_json(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def load_csv(folder, name):
    """{column: array} or None when the file is missing."""
    if folder is None or not os.path.isfile(os.path.join(folder, name)):
        return None
    return pf.load_csv(folder, name, False)


def unit_scale(summary):
    """(display unit, factor metres -> display unit)."""
    unit = (summary or {}).get("display_unit", "m")
    return unit, 1.0 / float((summary or {}).get("metres_per_unit") or 1.0)


def gate_crossing_time(t, north, x):
    """First time the path crosses north = x going forward; None if never."""
    for i in range(1, len(t)):
        if north[i - 1] < x <= north[i]:
            f = (x - north[i - 1]) / (north[i] - north[i - 1])
            return t[i - 1] + f * (t[i] - t[i - 1])
    return None


def baseline_time_shift(summary, base):
    """Offset that puts the baseline's start-gate crossing on the flight's, so
    that the time plots compare the two over the same stretch of course."""
    gates = summary.get("gates") or {}
    t0 = summary.get("gate_start_t")
    if base is None or t0 is None or gates.get("start_x") is None or "t" not in base:
        return 0.0
    tb = gate_crossing_time(base["t"], base["north"], float(gates["start_x"]))
    return 0.0 if tb is None else float(t0) - tb


# --------------------------------------------------------------------------- figures

def _obstacle_plan(ax, summary, k):
    for ob in summary.get("obstacles") or []:
        cn, ce = ob["center"]
        if ob.get("kind") in ("cylinder", "tree"):
            ax.add_patch(Circle((cn * k, ce * k), 0.5 * float(ob["size"][0]) * k,
                                hatch="xx" if ob.get("kind") == "tree" else None, **pf.OBSTACLE_STYLE))
        else:
            ax.add_patch(Polygon([(n * k, e * k) for n, e in pf.obstacle_footprint(ob)],
                                 closed=True, **pf.OBSTACLE_STYLE))


def _obstacle_extent(ob, axis):
    """(low, high) of the footprint along axis 0 (north) or 1 (east), metres."""
    if ob.get("kind") in ("cylinder", "tree"):
        r = 0.5 * float(ob["size"][axis])
        return ob["center"][axis] - r, ob["center"][axis] + r
    vals = [p[axis] for p in pf.obstacle_footprint(ob)]
    return min(vals), max(vals)


def _obstacle_elevation(ax, summary, k, axis):
    for ob in summary.get("obstacles") or []:
        lo, hi = _obstacle_extent(ob, axis)
        ax.add_patch(Rectangle((lo * k, 0), (hi - lo) * k, float(ob.get("height", 0)) * k,
                               hatch="xx" if ob.get("kind") == "tree" else None, **pf.OBSTACLE_STYLE))


def _flown_and_baseline(ax, nav, base, k, xcol, ycol, ysign):
    if base is not None:
        ax.plot(pf.col(base, xcol) * k, ysign * pf.col(base, ycol) * k, "--", color="k", lw=1.2,
                label="time-optimal baseline")
    ax.plot(pf.col(nav, xcol) * k, ysign * pf.col(nav, ycol) * k, "-", color="tab:blue", lw=1.6,
            label="flown")


def _subsample(data, limit):
    n = pf.nrows(data)
    if n <= limit:
        return data
    idx = np.linspace(0, n - 1, limit).astype(int)
    return {c: v[idx] for c, v in data.items()}


def course_figure(run_dir, out_png, title=None, baseline_dir=None, tree_views=False):
    """The paper-style figure of one flight: top view, altitude, speed, acceleration
    (commanded vs actual) and, for sensor-in-the-loop courses, front and side
    views with the LIDAR hits. Returns out_png, or None when the flight left no data."""
    summary = read_json(os.path.join(run_dir, "summary.json"))
    nav = load_csv(run_dir, "nav_state.csv")
    ctl = load_csv(run_dir, "control_status.csv")
    if summary is None or nav is None:
        return None
    base = load_csv(baseline_dir, "baseline_trajectory.csv")
    unit, k = unit_scale(summary)
    lim = summary.get("limits") or {}
    gates = pf.course_gates(summary, k)
    gate_times = [(summary.get("gate_start_t"), "start"), (summary.get("gate_finish_t"), "finish")]
    shift = baseline_time_shift(summary, base)

    rows = 4 if tree_views else 3
    fig = plt.figure(figsize=(12, 3.4 * rows + 1))
    gs = fig.add_gridspec(rows, 2, height_ratios=[1.2, 1.0, 1.1] + ([1.3] if tree_views else []))
    ax_top = fig.add_subplot(gs[0, :])
    ax_alt = fig.add_subplot(gs[1, :], sharex=ax_top)
    ax_spd = fig.add_subplot(gs[2, 0])
    ax_acc = fig.add_subplot(gs[2, 1], sharex=ax_spd)

    _obstacle_plan(ax_top, summary, k)
    _flown_and_baseline(ax_top, nav, base, k, "north", "east", 1.0)
    pf.draw_gates(ax_top, gates)
    ax_top.set_aspect("equal", adjustable="datalim")
    ax_top.autoscale_view()
    ax_top.set(xlabel="x [%s]" % unit, ylabel="y [%s]" % unit, title="trajectory, top view")

    _obstacle_elevation(ax_alt, summary, k, 0)
    _flown_and_baseline(ax_alt, nav, base, k, "north", "down", -1.0)
    pf.draw_gates(ax_alt, gates, labels=False)
    ax_alt.autoscale_view()
    ax_alt.set_ylim(bottom=0.0)
    ax_alt.set(xlabel="x [%s]" % unit, ylabel="h [%s]" % unit, title="altitude")

    speed = np.sqrt(pf.col(nav, "vn") ** 2 + pf.col(nav, "ve") ** 2 + pf.col(nav, "vd") ** 2)
    ax_spd.plot(pf.col(nav, "t"), speed * k, color="tab:blue", lw=1.4, label="flown")
    if base is not None:
        bspeed = np.sqrt(pf.col(base, "vn") ** 2 + pf.col(base, "ve") ** 2 + pf.col(base, "vd") ** 2)
        ax_spd.plot(pf.col(base, "t") + shift, bspeed * k, "--", color="k", lw=1.0, label="baseline")
    if lim.get("max_speed") is not None:
        ax_spd.axhline(lim["max_speed"] * k, color="red", ls="--", lw=1, label="limit")
    pf.draw_gates(ax_spd, gate_times)
    ax_spd.set_ylim(bottom=0.0)
    ax_spd.set(xlabel="t [s]", ylabel="speed [%s/s]" % unit, title="speed")

    def magnitude(data, prefix):
        return np.sqrt(sum(pf.col(data, prefix + c) ** 2 for c in ("an", "ae", "ad")))

    t_nav, a_nav = pf.col(nav, "t"), magnitude(nav, "") * k
    ax_acc.plot(t_nav, a_nav, color="tab:blue", lw=0.5, alpha=0.35, label="actual")
    # Rotor vibration makes the raw trace a band; its running mean shows what the
    # airframe followed.
    if len(t_nav) > 2 and np.all(np.isfinite(a_nav)):
        width = max(1, int(round(SMOOTHING_S / max(np.median(np.diff(t_nav)), 1e-6))))
        smooth = np.convolve(a_nav, np.ones(width) / width, mode="same")
        ax_acc.plot(t_nav, smooth, color="tab:blue", lw=1.2, label="actual, %.1f s mean" % SMOOTHING_S)
    if ctl is not None:
        ax_acc.plot(pf.col(ctl, "t"), magnitude(ctl, "ref_") * k, color="tab:red", lw=1.2,
                    label="commanded")
    if lim.get("max_accel") is not None:
        ax_acc.axhline(lim["max_accel"] * k, color="red", ls="--", lw=1, label="limit")
        ax_acc.set_ylim(0.0, 2.5 * lim["max_accel"] * k)
    pf.draw_gates(ax_acc, gate_times, labels=False)
    ax_acc.set(xlabel="t [s]", ylabel="|a| [%s/s²]" % unit, title="acceleration")

    axes = [ax_top, ax_alt, ax_spd, ax_acc]
    if tree_views:
        scan = _subsample(load_csv(run_dir, "scan_points.csv"), MAX_SCAN_POINTS)
        for col_idx, (xcol, axis, name) in enumerate((("east", 1, "front view (y-h)"),
                                                     ("north", 0, "side view (x-h)"))):
            ax = fig.add_subplot(gs[3, col_idx])
            _obstacle_elevation(ax, summary, k, axis)
            if scan is not None and pf.nrows(scan):
                ax.plot(scan[xcol] * k, -scan["down"] * k, ".", ms=1, color="0.45", label="LIDAR hits")
            ax.plot(pf.col(nav, xcol) * k, -pf.col(nav, "down") * k, "-", color="tab:blue", lw=1.6,
                    label="flown")
            ax.set(xlabel="%s [%s]" % ("y" if axis else "x", unit), ylabel="h [%s]" % unit, title=name)
            ax.set_ylim(bottom=0.0)
            if axis == 0:
                ax.set_xlim(*ax_top.get_xlim())
            axes.append(ax)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
        ax.legend(fontsize=7, loc="best", framealpha=0.7)

    head = title or str(summary.get("scenario", os.path.basename(run_dir)))
    if summary.get("gate_to_gate") is not None:
        head += "   gate-to-gate %.1f s" % summary["gate_to_gate"]
    fig.suptitle(head, fontsize=13)
    fig.text(0.99, 0.005, pf.FOOTER, ha="right", va="bottom", fontsize=7, color="0.4")
    fig.tight_layout(rect=(0, 0.015, 1, 0.97))
    fig.savefig(out_png, dpi=100)
    plt.close(fig)
    return out_png


def histogram(out_png, values, xlabel, title, lines=(), bins=30):
    """A histogram with labelled vertical reference lines [(x, label, colour)]."""
    fig, ax = plt.subplots(figsize=(7, 4))
    vals = [v for v in values if v is not None and math.isfinite(v)]
    if vals:
        ax.hist(vals, bins=bins, color="tab:blue", alpha=0.8)
    else:
        pf.no_data(ax)
    for x, label, colour in lines:
        ax.axvline(x, color=colour, ls="--", lw=1.2, label=label)
    if lines:
        ax.legend(fontsize=8)
    ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    ax.set(xlabel=xlabel, ylabel="runs", title=title)
    ax.grid(alpha=0.3)
    fig.tight_layout()
    fig.savefig(out_png, dpi=100)
    plt.close(fig)
    return out_png


# --------------------------------------------------------------------------- tables

def fmt(value, digits=1, scale=1.0):
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "n/a"
    return "%.*f" % (digits, value * scale)


def course_metrics(summary):
    """The reported figures of one flight, in display units, from its summary."""
    unit, k = unit_scale(summary)
    lim = summary.get("limits") or {}
    ms = 1000.0
    return {
        "display_unit": unit,
        "success": bool(summary.get("success")),
        "failures": list(summary.get("failures") or []),
        "crossed_finish": bool(summary.get("crossed_finish")),
        "gate_to_gate_s": summary.get("gate_to_gate"),
        "min_clearance": None if summary.get("min_clearance") is None else summary["min_clearance"] * k,
        "clearance_required": None if summary.get("clearance_required") is None
        else summary["clearance_required"] * k,
        "max_commanded_accel_pct": None if summary.get("max_commanded_accel_fraction") is None
        else 100.0 * summary["max_commanded_accel_fraction"],
        "max_speed": None if summary.get("max_speed") is None else summary["max_speed"] * k,
        "max_speed_limit": None if lim.get("max_speed") is None else lim["max_speed"] * k,
        "tracking_rms": None if summary.get("tracking_rms") is None else summary["tracking_rms"] * k,
        "tracking_max": None if summary.get("tracking_max") is None else summary["tracking_max"] * k,
        "rh_solve_median_ms": None if summary.get("rh_solve_time_median") is None
        else summary["rh_solve_time_median"] * ms,
        "rh_solve_p99_ms": None if summary.get("rh_solve_time_p99") is None
        else summary["rh_solve_time_p99"] * ms,
        "rh_solve_max_ms": None if summary.get("rh_solve_time_max") is None
        else summary["rh_solve_time_max"] * ms,
    }


def ratio_of(gate_to_gate, baseline_time):
    if gate_to_gate is None or not baseline_time:
        return None
    return gate_to_gate / baseline_time


def course_table(rows, unit):
    """Markdown table, one row per flight. Each row: dict with 'label', 'metrics'
    (from course_metrics, or None when the flight left no summary), 'error',
    'baseline_time', 'paper_ratio'."""
    head = ("| course | success | gate-to-gate (s) | baseline (s) | ratio | paper FT2 ratio "
            "| least clearance (%s) / R_s | max cmd accel (%% of limit) | max speed (%s/s) / limit "
            "| tracking RMS / max (%s) | RH solve median / p99 / max (ms) |" % (unit, unit, unit))
    lines = [head, "|" + "---|" * 11]
    for r in rows:
        m = r.get("metrics")
        paper = "-" if r.get("paper_ratio") is None else "%.3f" % r["paper_ratio"]
        if m is None:
            lines.append("| %s | **no** (%s) | n/a | %s | n/a | %s | n/a | n/a | n/a | n/a | n/a |"
                         % (r["label"], r.get("error") or "no summary", fmt(r.get("baseline_time")), paper))
            continue
        success = "yes" if m["success"] else "**no**: " + "; ".join(m["failures"] or ["see log"])
        ratio = fmt(ratio_of(m["gate_to_gate_s"], r.get("baseline_time")), 3)
        if r.get("baseline_knows_popups") and ratio != "n/a":
            ratio += " (pop-ups known to the baseline)"
        lines.append("| %s | %s | %s | %s | %s | %s | %s / %s | %s | %s / %s | %s / %s | %s / %s / %s |" % (
            r["label"], success, fmt(m["gate_to_gate_s"]), fmt(r.get("baseline_time")),
            ratio, paper, fmt(m["min_clearance"]), fmt(m["clearance_required"], 0),
            fmt(m["max_commanded_accel_pct"], 0), fmt(m["max_speed"], 2), fmt(m["max_speed_limit"], 0),
            fmt(m["tracking_rms"], 2), fmt(m["tracking_max"], 2), fmt(m["rh_solve_median_ms"]),
            fmt(m["rh_solve_p99_ms"]), fmt(m["rh_solve_max_ms"])))
    return "\n".join(lines)


def wilson_interval(successes, n, z=1.959964):
    """95 % Wilson score interval of a success rate; (0, 1) for n = 0."""
    if n == 0:
        return 0.0, 1.0
    p = successes / n
    den = 1 + z * z / n
    centre = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    return max(0.0, centre - half), min(1.0, centre + half)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results_dir")
    ap.add_argument("--baseline", help="folder with baseline_trajectory.csv")
    ap.add_argument("--out", help="figure path (default RESULTS_DIR/course.png)")
    ap.add_argument("--tree", action="store_true", help="add front and side views with the LIDAR hits")
    args = ap.parse_args()
    out = args.out or os.path.join(args.results_dir, "course.png")
    if course_figure(args.results_dir, out, baseline_dir=args.baseline, tree_views=args.tree) is None:
        print("campaign_report: no summary.json / nav_state.csv in %s" % args.results_dir, file=sys.stderr)
        return 2
    print(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
