#!/usr/bin/python3
"""Plots a virtual lab run (grainlink lab TEST SCENARIO --out RUN_DIR).

bevameter: the measured p(z) of every plate and Bekker's fitted p = (k_c/b + k_phi) z^n over it,
with the fit's values and 95 % intervals (RUN_DIR/pressure_sinkage.csv, bekker_fit.csv)
-> RUN_DIR/bevameter.png.
repose: the heap profile (highest grain top per radial bin, RUN_DIR/heap_profile.csv) with the
angle from RUN_DIR/report.txt -> RUN_DIR/repose.png.

Usage: tools/plot_lab.py RUN_DIR
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt


def read(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def repose(run_dir):
    rows = read(f"{run_dir}/heap_profile.csv")
    with open(f"{run_dir}/report.txt") as f:
        angle = next((l.strip() for l in f if "angle of repose" in l), "")
    r = [1e3 * float(x["radius_m"]) for x in rows]
    h = [1e3 * float(x["height_m"]) for x in rows]
    fig, ax = plt.subplots(figsize=(7, 4))
    ax.step(r, h, where="mid", label="highest grain top per radial bin")
    ax.set_xlabel("distance from the tube axis [mm]")
    ax.set_ylabel("heap height [mm]")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_title(angle, fontsize=9)
    ax.legend(fontsize=8)
    fig.tight_layout()
    out = f"{run_dir}/repose.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    if os.path.exists(f"{run_dir}/heap_profile.csv"):
        return repose(run_dir)
    rows = read(f"{run_dir}/pressure_sinkage.csv")
    if not rows:
        sys.exit(f"{run_dir}/pressure_sinkage.csv is empty")
    fit = {r["parameter"]: r for r in read(f"{run_dir}/bekker_fit.csv")}

    plates = sorted({float(r["plate_radius_m"]) for r in rows})
    fig, ax = plt.subplots(figsize=(7, 5))
    for i, b in enumerate(plates):
        z = [1e3 * float(r["sinkage_m"]) for r in rows if float(r["plate_radius_m"]) == b]
        p = [1e-3 * float(r["pressure_Pa"]) for r in rows if float(r["plate_radius_m"]) == b]
        colour = f"C{i}"
        ax.plot(z, p, ".", color=colour, ms=3, label=f"DEM, plate R = {1e3 * b:g} mm")
        if fit:
            kc, kphi, n = (float(fit[k]["value"]) for k in ("k_c", "k_phi", "n"))
            zs = [x * max(z) / 100 for x in range(101)]
            ps = [1e-3 * (kc / b + kphi) * (1e-3 * zz) ** n for zz in zs]
            ax.plot(zs, ps, "-", color=colour, lw=1.2)
    if fit:
        text = "Bekker fit (lines), 95 % CI:\n" + "\n".join(
            f"{k} = {float(fit[k]['value']):.4g} ± {float(fit[k]['half_width_95']):.2g} {fit[k]['unit']}"
            for k in ("k_c", "k_phi", "n"))
        ax.text(0.02, 0.98, text, transform=ax.transAxes, va="top", fontsize=8,
                bbox=dict(fc="white", ec="0.7"))
    ax.set_xlabel("sinkage z [mm]")
    ax.set_ylabel("pressure p [kPa]")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Virtual bevameter: pressure-sinkage")
    fig.tight_layout()
    out = f"{run_dir}/bevameter.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
