#!/usr/bin/python3
"""The mole run's report from RUN_DIR/mbs.csv and RUN_DIR/mbs_summary.json (grainlink mbs-node
with a `mole:` model):
per stroke the penetration at its end, the advance it made, the peak and mean vertical soil
force on the hull and the soil's impulse on the hull, written to RUN_DIR/strokes.csv, and
RUN_DIR/mole.png: penetration against stroke number, hull force per stroke, and penetration and
hull force against time.

Usage: tools/plot_mole.py RUN_DIR [HULL_NAME]
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import json
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    if len(sys.argv) not in (2, 3):
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    hull = sys.argv[2] if len(sys.argv) == 3 else "mole"
    with open(f"{run_dir}/mbs.csv") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{run_dir}/mbs.csv has no windows")
    t = [float(r["time_s"]) for r in rows]
    depth = [1000 * float(r["penetration_m"]) for r in rows]
    fz = [float(r[f"{hull}.Fz_N"]) for r in rows]

    # The strokes as the run's summary gives them (grainlink's mbs::moleStrokes, which a study
    # reads too): stroke k spans the windows from its release to the next one.
    with open(f"{run_dir}/mbs_summary.json") as f:
        summary = json.load(f)
    strokes = [{"stroke": s["stroke"], "end_time_s": s["end_time_s"],
                "penetration_mm": 1000 * s["penetration_m"], "advance_mm": 1000 * s["advance_m"],
                "peak_hull_Fz_N": s["peak_hull_force_N"], "mean_hull_Fz_N": s["mean_hull_force_N"],
                "hull_impulse_z_N_s": s["hull_impulse_N_s"]} for s in summary["strokes"]]
    with open(f"{run_dir}/strokes.csv", "w", newline="") as f:
        out = csv.DictWriter(f, fieldnames=list(strokes[0]) if strokes else ["stroke"])
        out.writeheader()
        out.writerows(strokes)

    fig, axes = plt.subplots(2, 2, figsize=(11, 7))
    n = [s["stroke"] for s in strokes]
    axes[0][0].plot([0] + n, [0] + [s["penetration_mm"] for s in strokes], "o-")
    axes[0][0].set_xlabel("stroke")
    axes[0][0].set_ylabel("penetration [mm]")
    axes[0][1].bar(n, [s["peak_hull_Fz_N"] for s in strokes], label="peak")
    axes[0][1].plot(n, [s["mean_hull_Fz_N"] for s in strokes], "ko-", label="mean over the stroke")
    axes[0][1].set_xlabel("stroke")
    axes[0][1].set_ylabel("vertical soil force on hull [N]")
    axes[0][1].legend(fontsize="small")
    axes[1][0].plot(t, depth, lw=0.8)
    axes[1][0].set_xlabel("time [s]")
    axes[1][0].set_ylabel("penetration [mm]")
    axes[1][1].plot(t, fz, lw=0.5)
    axes[1][1].set_xlabel("time [s]")
    axes[1][1].set_ylabel("vertical soil force on hull [N]")
    for row in axes:
        for axis in row:
            axis.grid(alpha=0.3)
    fig.suptitle(f"{run_dir}: HP3 mole hammering into the grains")
    fig.tight_layout()
    fig.savefig(f"{run_dir}/mole.png", dpi=110)
    for s in strokes:
        print(f"stroke {s['stroke']:3d}: penetration {s['penetration_mm']:7.2f} mm "
              f"(+{s['advance_mm']:.2f}), hull force peak {s['peak_hull_Fz_N']:.1f} N, "
              f"mean {s['mean_hull_Fz_N']:.2f} N")
    print(f"report: {run_dir}/strokes.csv, plot: {run_dir}/mole.png")


if __name__ == "__main__":
    main()
