#!/usr/bin/python3
"""Plot the tracking sweep: RMS tracking error, adaptive against non-adaptive, per airframe error and wind.

Usage: plot_tracking_sweep.py CSV [OUT.png]

Reads tracking_sweep.csv as ofn_tracking_sweep writes it (make bench:
results/bench/tracking_sweep.csv), one row per airframe, mass scale and
wind, with the unit in each header (`wind [kt]`, `adaptive_rms [m]`; a
header without the unit reads the same), and draws one bar chart per
airframe. matplotlib is imported once the command line and the file have
been read, so --help and a bad input need none.
"""
import csv
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import campaign_report as cr  # noqa: E402  (command-line helpers; imports nothing heavy)

PROG = "bench/plot_tracking_sweep.py"
# Bare column names (the unit is in the header) and how each is read.
COLUMNS = {"mass_scale": float, "airframe": str, "wind": float, "turbulence": str,
           "adaptive_rms": float, "adaptive_max": float, "baseline_rms": float,
           "baseline_max": float}
# The headers before they named their units.
OLD_NAMES = {"wind_kt": "wind"}


def bare_name(header):
    """'wind [kt]' -> 'wind'; the old 'wind_kt' -> 'wind'."""
    name = header.strip()
    if name.endswith("]") and "[" in name:
        name = name[:name.rindex("[")].strip()
    return OLD_NAMES.get(name, name)


def read_sweep(path):
    """The rows of tracking_sweep.csv as dicts of bare column names; InputError
    (one line, exit code 2) for a missing file, a missing column or a cell
    that is not a number."""
    try:
        with open(path, newline="") as f:
            rows = list(csv.reader(f))
    except OSError as exc:
        raise cr.InputError("cannot read %s: %s" % (path, exc.strerror or exc))
    except (csv.Error, UnicodeDecodeError) as exc:
        raise cr.InputError("%s is not a CSV file: %s" % (path, exc))
    if not rows:
        raise cr.InputError("%s is empty" % path)
    header = [bare_name(h) for h in rows[0]]
    missing = [c for c in COLUMNS if c not in header]
    if missing:
        raise cr.InputError("%s has no column %s (is it ofn_tracking_sweep's tracking_sweep.csv?)"
                            % (path, ", ".join(missing)))
    out = []
    for line, row in enumerate(rows[1:], 2):
        if not row:
            continue
        cells = dict(zip(header, row))
        record = {}
        for name, kind in COLUMNS.items():
            text = cells.get(name, "")
            try:
                value = kind(text)
            except ValueError:
                raise cr.InputError("%s line %d: %s is %r, not a number" % (path, line, name, text))
            record[name] = value
        out.append(record)
    if not out:
        raise cr.InputError("%s has a header but no rows" % path)
    return out


def figure(rows):
    plt = cr.need("matplotlib.pyplot")
    airframes = list(dict.fromkeys(r["airframe"] for r in rows))
    winds = sorted({r["wind"] for r in rows})
    fig, axes = plt.subplots(1, len(airframes), figsize=(6 * len(airframes), 4.5), sharey=True,
                             squeeze=False)
    for ax, airframe in zip(axes[0], airframes):
        sub = [r for r in rows if r["airframe"] == airframe]
        labels = [f"m x{r['mass_scale']:.1f}\n{r['wind']:.0f} kt" for r in sub]
        x = range(len(sub))
        ax.bar([i - 0.2 for i in x], [r["baseline_rms"] for r in sub], 0.4,
               label="non-adaptive", color="tab:gray")
        ax.bar([i + 0.2 for i in x], [r["adaptive_rms"] for r in sub], 0.4,
               label="adaptive", color="tab:blue")
        ax.set_xticks(list(x))
        ax.set_xticklabels(labels, fontsize=7)
        ax.set_yscale("log")
        ax.set_title(f"airframe: {airframe}")
        ax.grid(True, axis="y", which="both", alpha=0.3)
    axes[0][0].set_ylabel("RMS tracking error (m, log scale)")
    axes[0][0].legend()
    fig.suptitle(f"Tracking sweep ({rows[0]['turbulence']} turbulence; winds "
                 + ", ".join(f"{w:.0f}" for w in winds) + " kt crosswind)")
    fig.tight_layout()
    return fig, plt


def build_parser():
    ap = cr.ArgumentParser(
        PROG, __doc__.splitlines()[0],
        epilog="Example:\n"
               "  bench/plot_tracking_sweep.py results/bench/tracking_sweep.csv\n"
               "\n"
               "Exit codes: 0 when the figure is written; 2 for a bad command line, a\n"
               "missing or unreadable CSV, a figure that cannot be written or a missing\n"
               "Python module (matplotlib).")
    ap.add_argument("csv", metavar="CSV",
                    help="tracking_sweep.csv written by ofn_tracking_sweep (required)")
    ap.add_argument("out", metavar="OUT.png", nargs="?",
                    help="figure to write (default: CSV with .png for .csv)")
    return ap


def main(argv=None):
    args = build_parser().parse_args(argv)
    out = args.out or os.path.splitext(args.csv)[0] + ".png"
    rows = read_sweep(args.csv)
    cr.need("matplotlib").use("Agg")  # headless
    fig, plt = figure(rows)
    try:
        fig.savefig(out, dpi=120)
    except OSError as exc:
        raise cr.InputError("cannot write %s: %s" % (out, exc.strerror or exc))
    finally:
        plt.close(fig)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    cr.run_main(PROG, main)
