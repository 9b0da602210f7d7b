#!/usr/bin/python3
"""Plots a coupled run's coupling.csv: each body's position and soil force against time, the
coupling's energy mismatch, and the passes per window (implicit coupling).

Usage: tools/plot_coupling.py RUN_DIR   -> RUN_DIR/coupling.png
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    with open(f"{run_dir}/coupling.csv") as f:
        rows = list(csv.DictReader(f))
    if not rows:
        sys.exit(f"{run_dir}/coupling.csv has no windows")
    bodies = sorted({key.split(".")[0] for key in rows[0] if key.endswith(".x_m")})
    t = [float(r["end_s"]) for r in rows]
    column = lambda name: [float(r[name]) for r in rows]

    fig, axes = plt.subplots(4, 1, figsize=(8, 10), sharex=True)
    for body in bodies:
        for axis in "xyz":
            values = column(f"{body}.{axis}_m")
            if max(values) != min(values):
                axes[0].plot(t, values, label=f"{body} {axis}")
            forces = column(f"{body}.f{axis}_N")
            if any(forces):
                axes[1].plot(t, forces, label=f"{body} F{axis}")
    axes[0].set_ylabel("position [m]")
    axes[1].set_ylabel("soil force [N]\n(window average)")
    axes[2].plot(t, column("cumulative_mismatch_J"))
    axes[2].set_ylabel("coupling energy\nmismatch [J]")
    axes[3].step(t, column("iterations"), where="post")
    axes[3].set_ylabel("passes per window")
    axes[3].set_ylim(bottom=0)
    axes[3].set_xlabel("time [s]")
    for axis in axes[:2]:
        axis.legend(loc="best", fontsize="small")
    for axis in axes:
        axis.grid(alpha=0.3)
    fig.suptitle(f"{run_dir}: {len(rows)} windows")
    fig.tight_layout()
    fig.savefig(f"{run_dir}/coupling.png", dpi=110)
    print(f"plot: {run_dir}/coupling.png")


if __name__ == "__main__":
    main()
