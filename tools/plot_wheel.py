#!/usr/bin/python3
"""Plots a coupled single-wheel run (grainlink run scenarios/wheel_demo.yaml): the soil's force
in travel direction against travel (the seed's Figure 11 view), slip and sinkage against time,
and the motor torque. Reads RUN_DIR/rig.csv (multibody node), RUN_DIR/soil.csv (DEM node) and,
when the run reached it, the steady state of RUN_DIR/rig_summary.json: the judged span is
shaded, its mean ± sd drawn and written on each panel, and the normal load is a line beside the
support force.

With --grousers N RADIUS_M HEIGHT_M (count, rim radius, grouser height) a fifth panel counts
the grousers whose tips are below the settled bed surface (the seed's "6 or 7 grousers in the
soil" at 28), and the count over the steady span is printed. A tip is in the soil when it is
deeper than (r + h)(1 - cos theta) below the wheel's lowest point, whose depth is soil.csv's
sinkage; theta is each grouser's angle from straight down, from omega integrated over rig.csv
(the initial phase is arbitrary: over whole revolutions it does not change the shares).

Usage: tools/plot_wheel.py RUN_DIR [--grousers N RADIUS_M HEIGHT_M]   -> RUN_DIR/wheel.png
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import json
import math
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def grousers_in_soil(rig, soil, wheel, count, radius, height):
    """Per rig row: how many grouser tips are below the settled surface."""
    soil_t = [float(r["time_s"]) for r in soil if r["body"] == wheel]
    soil_s = [float(r["sinkage_m"]) for r in soil if r["body"] == wheel]
    tip = radius + height
    angle, previous, j, counts = 0.0, None, 0, []
    for row in rig:
        t, omega = float(row["time_s"]), float(row["omega_rad_s"])
        if previous is not None:
            angle += 0.5 * (omega + previous[1]) * (t - previous[0])
        previous = (t, omega)
        while j + 1 < len(soil_t) and soil_t[j + 1] <= t:
            j += 1
        depth = soil_s[j] if soil_t and soil_t[j] <= t else 0.0
        counts.append(sum(1 for k in range(count)
                          if tip * (1.0 - math.cos(angle + 2.0 * math.pi * k / count)) < depth))
    return counts


def main():
    args = sys.argv[1:]
    grousers = None
    if "--grousers" in args:
        at = args.index("--grousers")
        try:
            grousers = (int(args[at + 1]), float(args[at + 2]), float(args[at + 3]))
        except (IndexError, ValueError):
            sys.exit("--grousers takes N RADIUS_M HEIGHT_M\n" + __doc__)
        del args[at:at + 4]
    if len(args) != 1:
        sys.exit(__doc__)
    run_dir = args[0]
    rig = read(f"{run_dir}/rig.csv")
    soil = read(f"{run_dir}/soil.csv")
    if not rig or not soil:
        sys.exit(f"{run_dir}: rig.csv or soil.csv is empty")
    col = lambda rows, name: [float(r[name]) for r in rows]
    # The soil's load on the wheel is <wheel>.Fx_N, ... whatever the rig names its wheel.
    wheel = next(key for key in rig[0] if key.endswith(".Fx_N"))[: -len(".Fx_N")]
    t = col(rig, "time_s")
    drive = [r for r in rig if r["phase"] != "drop"]
    t_drive = drive[0]["time_s"] if drive else None

    summary_path = f"{run_dir}/rig_summary.json"
    summary = json.load(open(summary_path)) if os.path.exists(summary_path) else {}
    steady = summary.get("steady", False)

    fig, axes = plt.subplots(5 if grousers else 4, 1, figsize=(8, 13.5 if grousers else 11))
    if drive:
        axes[0].plot(col(drive, "travel_m"), col(drive, wheel + ".Fx_N"), lw=0.6, label="F_x (traction)")
        axes[0].plot(col(drive, "travel_m"), col(drive, wheel + ".Fz_N"), lw=0.6, label="F_z (support)")
    if "normal_load_N" in summary:
        load = summary["normal_load_N"]
        axes[0].axhline(load, color="k", ls=":", lw=0.8, label=f"normal load (weight) {load:.1f} N")
    axes[0].set_xlabel("travel while driving [m]")
    axes[0].set_ylabel("soil force on wheel [N]")
    axes[0].legend(fontsize="small")
    axes[1].plot(t, col(rig, "slip"), lw=0.8)
    axes[1].set_ylabel("slip [-]")
    axes[2].plot(col(soil, "time_s"), [1000 * v for v in col(soil, "sinkage_m")], lw=0.8)
    axes[2].set_ylabel("sinkage [mm]")
    axes[3].plot(t, col(rig, "motor_torque_N_m"), lw=0.6)
    axes[3].set_ylabel("motor torque [N m]")
    if grousers:
        counts = grousers_in_soil(rig, soil, wheel, *grousers)
        axes[4].step(t, counts, where="post", lw=0.8)
        axes[4].set_ylabel(f"grousers in the soil (of {grousers[0]})")
        if steady:
            start, end = summary["span_s"]
            span = [c for c, ti in zip(counts, t) if start <= ti <= end]
            shares = {c: span.count(c) / len(span) for c in sorted(set(span))}
            text = ", ".join(f"{c}: {100 * share:.0f} %" for c, share in shares.items())
            mean = sum(span) / len(span)
            axes[4].axvspan(start, end, color="tab:green", alpha=0.15)
            axes[4].set_title(f"steady: {mean:.2f} on average ({text} of the time)", fontsize="small")
            print(f"grousers in the soil over the steady span: mean {mean:.2f}; {text} of the time")
    for axis in axes[1:]:
        axis.set_xlabel("time [s]")
        if t_drive:
            axis.axvline(float(t_drive), color="gray", ls="--", lw=0.8)
    if steady:
        # The judged span, and each quantity's mean ± sd over it (sinkage from the soil).
        start, end = summary["span_s"]
        for axis, key, scale, unit in ((axes[1], "slip", 1.0, ""),
                                       (axes[2], "sinkage_m", 1000.0, " mm"),
                                       (axes[3], "motor_torque_N_m", 1.0, " N m")):
            axis.axvspan(start, end, color="tab:green", alpha=0.15)
            if key in summary:
                v = summary[key]
                mean, sd = scale * v["mean"], scale * v["sd"]
                axis.hlines([mean - sd, mean, mean + sd], start, end, colors="tab:green",
                            linestyles=[":", "-", ":"], lw=1.0)
                axis.set_title(f"steady: {mean:.3g} ± {sd:.2g}{unit} (se "
                               f"{scale * v['standard_error']:.2g})", fontsize="small")
    for axis in axes:
        axis.grid(alpha=0.3)
    fig.suptitle(f"{run_dir}: single-wheel coupled run (dashed: drive starts"
                 + ("; shaded: the steady span)" if steady else "; no steady state)"))
    fig.tight_layout()
    fig.savefig(f"{run_dir}/wheel.png", dpi=110)
    print(f"plot: {run_dir}/wheel.png")


if __name__ == "__main__":
    main()
