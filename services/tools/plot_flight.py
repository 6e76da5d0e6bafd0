#!/usr/bin/env python3
"""Draw the flight-test figure of an obstacle-avoidance flight from a results folder.

Usage: plot_flight.py RESULTS_DIR [--out RESULTS_DIR/flight.png]

Writes flight.png (top view, altitude, speed, acceleration) and tracking.png
(position error) and prints the paths written. All inputs are SI, local NED;
the plots use the course frame (x = north, y = east, h = -down) in the
display unit named by summary.json.
"""
import argparse
import csv
import json
import math
import os
import sys

import matplotlib
matplotlib.use("Agg")  # headless: runs on test machines and in CI
import matplotlib.pyplot as plt  # noqa: E402
import matplotlib.transforms as mtransforms  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.patches import Circle, Polygon, Rectangle  # noqa: E402

REQUIRED = ("nav_state.csv", "control_status.csv", "waypoints.csv")
FOOTER = "course geometry: this project's reconstruction of the benchmark"
OBSTACLE_STYLE = dict(facecolor="#f4b6b6", edgecolor="#c0392b", alpha=0.8, lw=1.0)


def fail(msg):
    print("plot_flight: error: " + msg, file=sys.stderr)
    sys.exit(2)


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
    header = [h.strip() for h in rows[0]]
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


def no_data(ax):
    ax.text(0.5, 0.5, "no data", transform=ax.transAxes, ha="center",
            va="center", color="grey", fontsize=12)


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
            ax.add_patch(Rectangle((n0, e0), n1 - n0, e1 - e0, fill=False,
                                   ls="--", ec="purple", lw=0.8))
    if scan is not None and nrows(scan):
        ax.plot(col(scan, "north") * k, col(scan, "east") * k, ".", ms=1,
                color="0.6", label="LIDAR hits")
    draw_plans(ax, k, gpath, ref, "east", 1.0)
    ax.plot(col(ctl, "ref_n") * k, col(ctl, "ref_e") * k, "--", color="tab:red",
            lw=1, label="reference")
    ax.plot(col(nav, "north") * k, col(nav, "east") * k, "-", color="tab:blue",
            lw=1.5, label="flown")
    ax.plot(col(wps, "north") * k, col(wps, "east") * k, "k^", ms=6, label="waypoints")
    draw_gates(ax, course_gates(summary, k))
    if not nrows(nav):
        no_data(ax)
    ax.set_aspect("equal", adjustable="datalim")
    ax.autoscale_view()


def panel_altitude(ax, k, nav, ctl, wps, summary, cuboids, scan, gpath, ref):
    for ob in summary.get("obstacles") or []:
        if ob.get("kind") in ("cylinder", "tree"):
            r = 0.5 * float(ob["size"][0])
            x0, x1 = ob["center"][0] - r, ob["center"][0] + r
        else:
            ns = [n for n, _ in obstacle_footprint(ob)]
            x0, x1 = min(ns), max(ns)
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
            ax.add_patch(Rectangle((n0, h0), n1 - n0, h1 - h0, fill=False,
                                   ls="--" if seen else ":", ec="purple", lw=0.8))
    if scan is not None and nrows(scan):
        ax.plot(col(scan, "north") * k, -col(scan, "down") * k, ".", ms=1, color="0.6",
                label="LIDAR hits")
    draw_plans(ax, k, gpath, ref, "down", -1.0)
    ax.plot(col(ctl, "ref_n") * k, -col(ctl, "ref_d") * k, "--", color="tab:red",
            lw=1, label="reference")
    ax.plot(col(nav, "north") * k, -col(nav, "down") * k, "-", color="tab:blue",
            lw=1.5, label="flown")
    ax.plot(col(wps, "north") * k, -col(wps, "down") * k, "k^", ms=6, label="waypoints")
    draw_gates(ax, course_gates(summary, k))
    if not nrows(nav):
        no_data(ax)
    ax.autoscale_view()
    # Unseen-top cuboids reach the mapper's ceiling; keep the view on the
    # flight and the real obstacles instead.
    tops = [float(ob.get("height", 0)) * k for ob in summary.get("obstacles") or []]
    if nrows(nav):
        tops.append(float(np.nanmax(-col(nav, "down"))) * k)
    top = 1.3 * max(tops) if tops else ax.get_ylim()[1]
    ax.set_ylim(bottom=min(0.0, ax.get_ylim()[0]), top=min(ax.get_ylim()[1], top))


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
    """Three component panels (x, y, z-up) and the commanded magnitude.

    Signs flip down to up for z so that a climb reads positive, like the altitude plot.
    """
    limit = (summary.get("limits") or {}).get("max_accel")
    comps = [("x", "an", "cmd_an", 1), ("y", "ae", "cmd_ae", 1), ("z", "ad", "cmd_ad", -1)]
    for ax, (name, act, cmd, sign) in zip(axes[:3], comps):
        ax.plot(col(nav, "t"), sign * col(nav, act) * k, "-", color="tab:blue",
                lw=1, label="actual")
        ax.plot(col(ctl, "t"), sign * col(ctl, cmd) * k, "--", color="tab:red",
                lw=1, label="commanded")
        ax.set_ylabel("a_%s [%s/s²]" % (name, unit), fontsize=8)
        draw_gates(ax, gate_times, labels=False)
        if not nrows(nav) and not nrows(ctl):
            no_data(ax)
    mag = np.sqrt(col(ctl, "cmd_an") ** 2 + col(ctl, "cmd_ae") ** 2 + col(ctl, "cmd_ad") ** 2)
    axes[3].plot(col(ctl, "t"), mag * k, color="tab:red", lw=1, label="|commanded|")
    if limit is not None:
        for ax in axes:
            ax.axhline(limit * k, color="red", ls="--", lw=0.8)
            if ax is not axes[3]:
                ax.axhline(-limit * k, color="red", ls="--", lw=0.8)
    axes[3].set_ylabel("|a_cmd| [%s/s²]" % unit, fontsize=8)
    axes[3].set_xlabel("t [s]")
    draw_gates(axes[3], gate_times, labels=False)
    axes[3].set_ylim(bottom=0.0)  # a magnitude: keep zero in view
    if not nrows(ctl):
        no_data(axes[3])
    axes[0].legend(fontsize=7, loc="upper right")


def tracking_figure(path, k, unit, nav, ctl, title):
    """Position error ref - actual, interpolating the flown path at the reference times."""
    t = col(ctl, "t")
    tn = col(nav, "t")
    ok = np.isfinite(tn)  # np.interp needs finite, increasing sample times
    order = np.argsort(tn[ok])
    if len(order) >= 2 and len(t):
        errs = [col(ctl, "ref_" + c) - np.interp(t, tn[ok][order], col(nav, name)[ok][order])
                for c, name in (("n", "north"), ("e", "east"), ("d", "down"))]
    else:  # fall back to the controller's own error report
        errs = [col(ctl, "err_" + c) for c in ("n", "e", "d")]
    errs[2] = -errs[2]  # down -> up, matching the course frame
    fig, ax = plt.subplots(2, 1, figsize=(10, 6), sharex=True)
    for e, name in zip(errs, ("x", "y", "h")):
        ax[0].plot(t, e * k, lw=1, label="e_" + name)
    ax[1].plot(t, np.sqrt(sum(e ** 2 for e in errs)) * k, color="k", lw=1, label="|e|")
    ax[0].set_ylabel("ref - actual [%s]" % unit)
    ax[1].set_ylabel("error norm [%s]" % unit)
    ax[1].set_xlabel("t [s]")
    for a in ax:
        a.grid(alpha=0.3)
        a.legend(fontsize=8, loc="upper right")
        if not len(t):
            no_data(a)
    fig.suptitle(title + " - tracking error")
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("results_dir")
    ap.add_argument("--out", help="flight figure path (default RESULTS_DIR/flight.png)")
    args = ap.parse_args()
    res = args.results_dir
    if not os.path.isdir(res):
        fail("results folder not found: " + res)
    out = args.out or os.path.join(res, "flight.png")

    summary_path = os.path.join(res, "summary.json")
    if not os.path.isfile(summary_path):
        fail("required file missing: " + summary_path)
    try:
        with open(summary_path) as f:
            summary = json.load(f)
    except (OSError, ValueError) as exc:
        fail("cannot read %s: %s" % (summary_path, exc))
    nav, ctl, wps = (load_csv(res, n, True) for n in REQUIRED)
    gpath = load_csv(res, "global_path.csv", False)
    ref = load_csv(res, "ref_traj.csv", False)
    scan = load_csv(res, "scan_points.csv", False)
    cuboids = load_csv(res, "cuboids.csv", False)

    unit = summary.get("display_unit", "m")
    k = 1.0 / float(summary.get("metres_per_unit") or 1.0)  # metres -> display unit
    t0, t1 = summary.get("gate_start_t"), summary.get("gate_finish_t")
    gate_times = [(t0, "start"), (t1, "finish")]
    title = str(summary.get("scenario", os.path.basename(os.path.abspath(res))))
    if t0 is not None and t1 is not None:
        title += "   gate-to-gate %.1f s" % (t1 - t0)
    outcome, reason = verdict_of(summary)
    if outcome:
        title += "   " + outcome
    # The first failure line names what went wrong; it gets a line of its own.
    flight_title = title + ("\n" + reason if reason else "")

    fig = plt.figure(figsize=(12, 10))
    gs = fig.add_gridspec(3, 2, height_ratios=[1.2, 1.0, 1.6])
    ax_top = fig.add_subplot(gs[0, :])
    ax_alt = fig.add_subplot(gs[1, :], sharex=ax_top)
    ax_spd = fig.add_subplot(gs[2, 0])
    sub = gs[2, 1].subgridspec(4, 1, hspace=0.08)
    ax_acc = [fig.add_subplot(sub[0])]
    ax_acc += [fig.add_subplot(sub[i], sharex=ax_acc[0]) for i in range(1, 4)]

    panel_top_view(ax_top, k, nav, ctl, wps, summary, gpath, ref, scan, cuboids)
    ax_top.set(xlabel="x (north) [%s]" % unit, ylabel="y (east) [%s]" % unit, title="top view")
    panel_altitude(ax_alt, k, nav, ctl, wps, summary, cuboids, scan, gpath, ref)
    ax_alt.set(xlabel="x (north) [%s]" % unit, ylabel="h [%s]" % unit, title="altitude")
    panel_speed(ax_spd, k, nav, summary, gate_times)
    ax_spd.set(xlabel="t [s]", ylabel="speed [%s/s]" % unit, title="speed")
    panel_accel(ax_acc, k, nav, ctl, summary, gate_times, unit)
    ax_acc[0].set_title("acceleration: commanded (dashed) vs actual (solid)")
    for ax in ax_acc[:3]:
        ax.tick_params(labelbottom=False)
    for ax in [ax_top, ax_alt, ax_spd] + ax_acc:
        ax.grid(alpha=0.3)
        ax.tick_params(labelsize=8)
    for ax in (ax_top, ax_alt, ax_spd):
        ax.legend(fontsize=7, loc="best", framealpha=0.7)

    fig.suptitle(flight_title, fontsize=14, color="firebrick" if outcome == "failure" else "black")
    fig.text(0.99, 0.005, FOOTER, ha="right", va="bottom", fontsize=7, color="0.4")
    fig.tight_layout(rect=(0, 0.02, 1, 0.97))
    os.makedirs(os.path.dirname(os.path.abspath(out)), exist_ok=True)
    fig.savefig(out, dpi=120)
    plt.close(fig)
    print(out)

    track = os.path.join(os.path.dirname(os.path.abspath(out)), "tracking.png")
    tracking_figure(track, k, unit, nav, ctl, title)
    print(track)
    return 0


if __name__ == "__main__":
    sys.exit(main())
