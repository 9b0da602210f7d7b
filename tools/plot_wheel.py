#!/usr/bin/python3
"""Plots a coupled single-wheel run (grainlink run scenarios/wheel_demo.yaml): the soil's force
in travel direction against travel (the seed's Figure 11 view), slip and sinkage against time,
and the motor torque. Reads RUN_DIR/rig.csv (multibody node) and RUN_DIR/soil.csv (DEM node).

Usage: tools/plot_wheel.py RUN_DIR   -> RUN_DIR/wheel.png
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    rig = read(f"{run_dir}/rig.csv")
    soil = read(f"{run_dir}/soil.csv")
    if not rig or not soil:
        sys.exit(f"{run_dir}: rig.csv or soil.csv is empty")
    col = lambda rows, name: [float(r[name]) for r in rows]
    t = col(rig, "time_s")
    drive = [r for r in rig if r["phase"] != "drop"]
    t_drive = drive[0]["time_s"] if drive else None

    fig, axes = plt.subplots(4, 1, figsize=(8, 11))
    if drive:
        axes[0].plot(col(drive, "travel_m"), col(drive, "soil_Fx_N"), lw=0.6, label="F_x (traction)")
        axes[0].plot(col(drive, "travel_m"), col(drive, "soil_Fz_N"), lw=0.6, label="F_z (support)")
    axes[0].set_xlabel("travel while driving [m]")
    axes[0].set_ylabel("soil force on wheel [N]")
    axes[0].legend(fontsize="small")
    axes[1].plot(t, col(rig, "slip"), lw=0.8)
    axes[1].set_ylabel("slip [-]")
    axes[2].plot(col(soil, "time_s"), [1000 * v for v in col(soil, "sinkage_m")], lw=0.8)
    axes[2].set_ylabel("sinkage [mm]")
    axes[3].plot(t, col(rig, "motor_torque_N_m"), lw=0.6)
    axes[3].set_ylabel("motor torque [N m]")
    for axis in axes[1:]:
        axis.set_xlabel("time [s]")
        if t_drive:
            axis.axvline(float(t_drive), color="gray", ls="--", lw=0.8)
    for axis in axes:
        axis.grid(alpha=0.3)
    fig.suptitle(f"{run_dir}: single-wheel coupled run (dashed: drive starts)")
    fig.tight_layout()
    fig.savefig(f"{run_dir}/wheel.png", dpi=110)
    print(f"plot: {run_dir}/wheel.png")


if __name__ == "__main__":
    main()
