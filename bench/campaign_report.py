#!/usr/bin/python3
"""Figures and Markdown tables of the benchmark campaign and the Monte Carlo fields.

Importable (campaign.py and monte_carlo.py use it); run on its own it draws
the course figure of one results folder:

    campaign_report.py RESULTS_DIR [--baseline DIR] [--out fig.png] [--tree]

All inputs are SI, local NED (summary.json, nav_state.csv, control_status.csv,
scan_points.csv, baseline_trajectory.csv); figures and tables use the course
frame (x = north, y = east, h = -down) in the display unit of summary.json.

The bench scripts reach the command-line helpers every Python entry point
shares (services/tools/ofn_cli.py: the project version, one-line usage
errors with exit code 2, --bin) through it; the third-party modules
(PyYAML, numpy, matplotlib) are imported only when first needed, so that
--help and the argument checks work without them.
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
sys.path.insert(0, os.path.join(REPO, "services", "tools"))

# Set by _plotting() on first use: services/tools/plot_flight.py (which picks
# the Agg backend), matplotlib and numpy.
pf = plt = np = None
Circle = Polygon = Rectangle = MaxNLocator = None

RECONSTRUCTION_NOTE = ("The course geometry is this project's reconstruction of the rotorcraft "
                       "obstacle-field-navigation benchmarks (/work/shared/BENCHMARKS.md), "
                       "not the original data.")
MAX_SCAN_POINTS = 20000  # LIDAR hits drawn per view; more only slows the figure down
FAIL_LINE = 0.8  # share of R_s below which a run fails (BENCHMARKS.md)
SMOOTHING_S = 0.5


# --------------------------------------------------------------------------- command lines

# The command-line helpers every Python entry point shares
# (services/tools/ofn_cli.py); the bench scripts reach them as cr.<name>.
from ofn_cli import (EXIT_USAGE, ArgumentParser, InputError, MissingModule,  # noqa: E402,F401
                     add_bin_option, bin_dir, need, project_version, run_main)


def _plotting():
    """Import plot_flight, matplotlib and numpy on first use."""
    global pf, plt, np, Circle, Polygon, Rectangle, MaxNLocator
    if pf is None:
        need("numpy")
        need("matplotlib")
        pf = need("plot_flight")  # sets the Agg backend before pyplot
        plt = need("matplotlib.pyplot")
        np = need("numpy")
        patches = need("matplotlib.patches")
        Circle, Polygon, Rectangle = patches.Circle, patches.Polygon, patches.Rectangle
        MaxNLocator = need("matplotlib.ticker").MaxNLocator


def need_plotting():
    """Fail early (MissingModule) when the figures could not be drawn."""
    _plotting()


def rel(path):
    """A path as shown in help texts: relative to the repository when inside it."""
    r = os.path.relpath(path, REPO)
    return path if r.startswith("..") else r


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
    _plotting()
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
    return pf.obstacle_extent(ob)[axis]


def _obstacle_elevation(ax, summary, k, axis, outline=False):
    """Obstacles as bars standing on the ground; outlines only (drawn over
    the LIDAR hits) when `outline`."""
    style = dict(fill=False, ec=pf.OBSTACLE_STYLE["edgecolor"], lw=1.0, zorder=3) if outline \
        else pf.OBSTACLE_STYLE
    for ob in summary.get("obstacles") or []:
        lo, hi = _obstacle_extent(ob, axis)
        tree = ob.get("kind") == "tree" and not outline
        ax.add_patch(Rectangle((lo * k, 0), (hi - lo) * k, float(ob.get("height", 0)) * k,
                               hatch="xx" if tree else None, **style))


def _flown_and_baseline(ax, nav, base, k, xcol, ycol, ysign):
    if base is not None:
        ax.plot(pf.col(base, xcol) * k, ysign * pf.col(base, ycol) * k, "--", color="k", lw=1.2,
                label="time-optimal baseline")
    ax.plot(pf.col(nav, xcol) * k, ysign * pf.col(nav, ycol) * k, "-", color="tab:blue", lw=1.6,
            label="flown", zorder=4)


def _subsample(data, limit):
    return pf.subsample(data, limit)


def course_figure_of(run_dir, title=None, baseline_dir=None, tree_views=False):
    """The paper-style figure of one flight as a Figure (see course_figure);
    None when the flight left no data. Axes are named by their label: top
    view, altitude, speed, acceleration, clearance and, with tree_views,
    front view and side view."""
    summary = read_json(os.path.join(run_dir, "summary.json"))
    if summary is None or not os.path.isfile(os.path.join(run_dir, "nav_state.csv")):
        return None
    _plotting()
    nav = load_csv(run_dir, "nav_state.csv")
    ctl = load_csv(run_dir, "control_status.csv")
    if nav is None:
        return None
    base = load_csv(baseline_dir, "baseline_trajectory.csv")
    unit, k = unit_scale(summary)
    lim = summary.get("limits") or {}
    gates = pf.course_gates(summary, k)
    gate_times = [(summary.get("gate_start_t"), "start"), (summary.get("gate_finish_t"), "finish")]
    shift = baseline_time_shift(summary, base)

    # Framed on the flown path, the baseline and the obstacles, at equal
    # scale; the top view's height follows the frame's shape.
    frame = pf.frame_of([(pf.col(nav, "north") * k, pf.col(nav, "east") * k),
                         (pf.col(base, "north") * k, pf.col(base, "east") * k),
                         pf.obstacle_points(summary, k)])
    top_h = 3.4
    if frame is not None:
        # The axes' height, plus the room of their title and tick labels.
        top_h = float(np.clip(10.8 * (frame[3] - frame[2]) / (frame[1] - frame[0]), 1.6, 7.0)) + 0.9
    heights = [top_h, 2.8, 3.2] + ([3.8] if tree_views else [])
    rows = len(heights)
    fig = plt.figure(figsize=(12, sum(heights) + 1.6))
    gs = fig.add_gridspec(rows, 1, height_ratios=heights)
    ax_top = fig.add_subplot(gs[0], label="top view")
    ax_alt = fig.add_subplot(gs[1], sharex=ax_top, label="altitude")
    row = gs[2].subgridspec(1, 3, wspace=0.3)
    ax_spd = fig.add_subplot(row[0], label="speed")
    ax_acc = fig.add_subplot(row[1], sharex=ax_spd, label="acceleration")
    ax_clr = fig.add_subplot(row[2], sharex=ax_spd, label="clearance")

    _obstacle_plan(ax_top, summary, k)
    _flown_and_baseline(ax_top, nav, base, k, "north", "east", 1.0)
    pf.draw_gates(ax_top, gates)
    ax_top.set(xlabel="x [%s]" % unit, ylabel="y [%s]" % unit, title="trajectory, top view")

    _obstacle_elevation(ax_alt, summary, k, 0)
    _flown_and_baseline(ax_alt, nav, base, k, "north", "down", -1.0)
    pf.draw_gates(ax_alt, gates, labels=False)
    heights_h = [float(ob.get("height", 0)) * k for ob in summary.get("obstacles") or []]
    heights_h += [pf.finite_max(-pf.col(d, "down") * k) for d in (nav, base) if d is not None]
    ax_alt.set_ylim(0.0, 1.15 * max(heights_h + [1.0]))
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
        # The reference acceleration (what the summary calls commanded), only
        # while the controller flies a plan: not a hold's command.
        pf.shade_idle(ax_acc, pf.idle_spans(ctl))
        ax_acc.plot(pf.col(ctl, "t"), pf.while_flying(ctl, magnitude(ctl, "ref_")) * k,
                    color="tab:red", lw=1.2, label="reference (commanded)", gid="reference")
    if lim.get("max_accel") is not None:
        ax_acc.axhline(lim["max_accel"] * k, color="red", ls="--", lw=1, label="limit")
        ax_acc.set_ylim(0.0, 2.5 * lim["max_accel"] * k)
    pf.draw_gates(ax_acc, gate_times, labels=False)
    ax_acc.set(xlabel="t [s]", ylabel="|a| [%s/s²]" % unit, title="acceleration")

    pf.panel_clearance(ax_clr, k, unit, pf.true_clearance(nav, summary), summary, gate_times)
    ax_clr.set(xlabel="t [s]", ylabel="clearance [%s]" % unit, title="least true clearance")

    axes = [ax_top, ax_alt, ax_spd, ax_acc, ax_clr]
    if tree_views:
        scan = _subsample(load_csv(run_dir, "scan_points.csv"), MAX_SCAN_POINTS)
        row = gs[3].subgridspec(1, 2, wspace=0.2)
        for col_idx, (xcol, axis, name) in enumerate((("east", 1, "front view (y-h)"),
                                                     ("north", 0, "side view (x-h)"))):
            ax = fig.add_subplot(row[col_idx], label=name.split(" (")[0])
            # The hits are what these views show: obstacle outlines over them,
            # so that neither buries the other.
            _obstacle_elevation(ax, summary, k, axis, outline=True)
            if scan is not None and pf.nrows(scan):
                ax.plot(scan[xcol] * k, -scan["down"] * k, ls="none", marker=".", ms=1,
                        color="0.45", alpha=0.6, zorder=1, rasterized=True, label="LIDAR hits")
            ax.plot(pf.col(nav, xcol) * k, -pf.col(nav, "down") * k, "-", color="tab:blue", lw=1.6,
                    label="flown", zorder=4)
            ax.set(xlabel="%s [%s]" % ("y" if axis else "x", unit), ylabel="h [%s]" % unit, title=name)
            ax.set_ylim(bottom=0.0)
            axes.append(ax)
    for ax in axes:
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
        if ax is not ax_clr:  # the clearance panel has its legend
            ax.legend(fontsize=7, loc="best", framealpha=0.7)

    head, reason = pf.verdict_title(summary, title)
    fig_h = fig.get_size_inches()[1]
    outcome, _ = pf.verdict_of(summary)
    fig.suptitle(head + ("\n" + reason if reason else ""), fontsize=13, y=1 - 0.1 / fig_h,
                 va="top", color="firebrick" if outcome == "failure" else "black")
    fig.text(0.99, 0.005, pf.FOOTER, ha="right", va="bottom", fontsize=7, color="0.4")
    # tight_layout makes room for the suptitle itself.
    fig.tight_layout(rect=(0, 0.15 / fig_h, 1, 1 - 0.1 / fig_h))
    pf.fit_equal(ax_top, frame)  # after the layout: it needs the axes' box
    if tree_views:
        # Framed like the top view, not on the ground hits.
        front, side = axes[-2:]
        front.set_xlim(*ax_top.get_ylim())
        side.set_xlim(*ax_top.get_xlim())
        top = 1.15 * max(heights_h + [1.0])
        for ax in (front, side):
            ax.set_ylim(0.0, top)
    return fig


def course_figure(run_dir, out_png, title=None, baseline_dir=None, tree_views=False):
    """The paper-style figure of one flight: top view, altitude, speed,
    acceleration (the reference, i.e. commanded, against the actual), the
    least true clearance and, for sensor-in-the-loop courses, front and side
    views with the LIDAR hits; the verdict in the title. Returns out_png, or
    None when the flight left no data."""
    fig = course_figure_of(run_dir, title=title, baseline_dir=baseline_dir, tree_views=tree_views)
    if fig is None:
        return None
    fig.savefig(out_png, dpi=100)
    plt.close(fig)
    return out_png


def histogram(out_png, values, xlabel, title, lines=(), bins=30):
    """A histogram with labelled vertical reference lines [(x, label, colour)]."""
    _plotting()
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


PROG = "bench/campaign_report.py"


def build_parser():
    ap = ArgumentParser(
        PROG, "Draw the course figure of one flight's results folder (as the campaign does).",
        epilog="Example:\n"
               "  bench/campaign_report.py results/campaign/bench1 --out /tmp/bench1.png\n"
               "      (after bench/campaign.py has flown bench1)\n"
               "\n"
               "Exit codes: 0 when the figure is written; 2 for bad arguments, a folder\n"
               "without summary.json / nav_state.csv, or matplotlib/numpy missing.")
    ap.add_argument("results_dir", metavar="RESULTS_DIR",
                    help="a flight's folder: summary.json, nav_state.csv, ... (required)")
    ap.add_argument("--baseline", metavar="DIR",
                    help="folder with baseline_trajectory.csv, drawn dashed (default: none)")
    ap.add_argument("--out", metavar="FILE", help="figure path (default: RESULTS_DIR/course.png)")
    ap.add_argument("--tree", action="store_true",
                    help="add front and side views with the LIDAR hits (default: off)")
    return ap


def main(argv=None):
    ap = build_parser()
    args = ap.parse_args(argv)
    if not os.path.isdir(args.results_dir):
        ap.error("RESULTS_DIR: no folder %s" % args.results_dir)
    if args.baseline is not None and not os.path.isdir(args.baseline):
        ap.error("--baseline: no folder %s" % args.baseline)
    out = args.out or os.path.join(args.results_dir, "course.png")
    if course_figure(args.results_dir, out, baseline_dir=args.baseline, tree_views=args.tree) is None:
        print("%s: error: no summary.json / nav_state.csv in %s" % (PROG, args.results_dir), file=sys.stderr)
        return EXIT_USAGE
    print(out)
    return 0


if __name__ == "__main__":
    run_main(PROG, main)
