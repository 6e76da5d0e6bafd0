#!/usr/bin/env python3
"""Plot the tracking sweep (tracking_sweep.csv from ofn_tracking_sweep):
RMS tracking error, adaptive vs non-adaptive, per airframe error and wind.

usage: plot_tracking_sweep.py results/bench/tracking_sweep.csv [out.png]
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")  # headless
import matplotlib.pyplot as plt  # noqa: E402


def main():
    if len(sys.argv) < 2:
        print(__doc__)
        return 2
    path = sys.argv[1]
    out = sys.argv[2] if len(sys.argv) > 2 else path.rsplit(".", 1)[0] + ".png"
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    airframes = list(dict.fromkeys(r["airframe"] for r in rows))
    winds = sorted({float(r["wind_kt"]) for r in rows})
    fig, axes = plt.subplots(1, len(airframes), figsize=(6 * len(airframes), 4.5), sharey=True,
                             squeeze=False)
    for ax, airframe in zip(axes[0], airframes):
        sub = [r for r in rows if r["airframe"] == airframe]
        labels = [f"m x{float(r['mass_scale']):.1f}\n{float(r['wind_kt']):.0f} kt" for r in sub]
        x = range(len(sub))
        ax.bar([i - 0.2 for i in x], [float(r["baseline_rms"]) for r in sub], 0.4,
               label="non-adaptive", color="tab:gray")
        ax.bar([i + 0.2 for i in x], [float(r["adaptive_rms"]) for r in sub], 0.4,
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
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
