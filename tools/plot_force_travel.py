#!/usr/bin/python3
"""Plots a body's force against travel from a grainlink series.csv (the seed's Figure 11 view).

Usage: tools/plot_force_travel.py RUN_DIR [BODY]   -> RUN_DIR/force_travel.png
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    body = sys.argv[2] if len(sys.argv) > 2 else "wheel"
    with open(f"{run_dir}/series.csv") as f:
        rows = list(csv.DictReader(f))
    if not rows or f"{body}.x_m" not in rows[0]:
        sys.exit(f"{run_dir}/series.csv has no body '{body}'")
    x0 = float(rows[0][f"{body}.x_m"])
    travel = [float(r[f"{body}.x_m"]) - x0 for r in rows]
    time = [float(r["run_time_s"]) for r in rows]
    fx = [float(r[f"{body}.Fx_N"]) for r in rows]
    fz = [float(r[f"{body}.Fz_N"]) for r in rows]
    ty = [float(r[f"{body}.Ty_N_m"]) for r in rows]
    sinkage = [float(rows[0][f"{body}.z_m"]) - float(r[f"{body}.z_m"]) for r in rows]

    fig, (ax1, ax2) = plt.subplots(2, 1, figsize=(8, 7), sharex=False)
    moving = [i for i, t in enumerate(travel) if t > 1e-6]
    ax1.plot([travel[i] for i in moving], [fx[i] for i in moving], label="F_x (travel direction)")
    ax1.plot([travel[i] for i in moving], [fz[i] for i in moving], label="F_z (vertical)")
    ax1.set_xlabel("travel [m]")
    ax1.set_ylabel("soil force on the body [N]")
    ax1.set_title(f"{body}: force vs travel")
    ax1.grid(True, alpha=0.3)
    ax1.legend()
    ax2.plot(time, [1000 * s for s in sinkage], color="tab:green", label="depth below start [mm]")
    ax2.set_xlabel("run time [s]")
    ax2.set_ylabel("depth [mm]")
    ax3 = ax2.twinx()
    ax3.plot(time, ty, color="tab:red", alpha=0.6, label="T_y [N m]")
    ax3.set_ylabel("torque about the axle T_y [N m]")
    ax2.grid(True, alpha=0.3)
    ax2.legend(loc="upper left")
    ax3.legend(loc="lower right")
    fig.tight_layout()
    out = f"{run_dir}/force_travel.png"
    fig.savefig(out, dpi=110)
    print(f"plot: {out}")


if __name__ == "__main__":
    main()
