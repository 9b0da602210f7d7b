#!/usr/bin/python3
"""Plots the Soil03 bevameter run against the frame of the seed's Figure 7 and prints p(z).

The seed (Lichtenheldt & Schaefer 2013, Figure 7, "Verification Bevameter - Soil03") plots
measured and simulated pressure-sinkage points of RMC-Soil03 on axes of 0-20 mm and 0-20 kPa.
Its points are not recoverable from the paper's text, so the figure is drawn as that frame only:
the region a curve "in the range of Figure 7" must stay inside.

Reads RUN_DIR/pressure_sinkage.csv and bekker_fit.csv (grainlink lab bevameter), prints the
pressure of every plate at 5, 10, 15 and 20 mm (linear interpolation between samples, clamped at
the ends, as lab/NumericalChecks.cpp does) with its excess over the frame's 20 kPa, and writes
the plot (default docs/lab_soil03.png). --reference DIR adds another bevameter run (e.g. the
default scenario's, out/bevameter) in grey for comparison.

Usage: tools/plot_soil03.py RUN_DIR [--reference DIR] [--out OUT.png]
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import argparse
import os
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
from matplotlib.patches import Rectangle

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from plot_lab import read  # noqa: E402

FIGURE7_MM = 20.0  # the seed's Figure 7: sinkage axis 0..20 mm
FIGURE7_KPA = 20.0  # pressure axis 0..20 kPa
SINKAGES_MM = (5.0, 10.0, 15.0, 20.0)


def interpolate(x, y, at):
    """y(at) by linear interpolation in samples sorted by x, clamped to the ends."""
    if at <= x[0]:
        return y[0]
    for (x0, y0), (x1, y1) in zip(zip(x, y), zip(x[1:], y[1:])):
        if x0 <= at <= x1:
            return y0 + (y1 - y0) * (at - x0) / (x1 - x0) if x1 > x0 else y1
    return y[-1]


def curves(run_dir):
    """{plate radius [m]: (sinkage [mm], pressure [kPa]) sorted by sinkage} of a bevameter run."""
    rows = read(f"{run_dir}/pressure_sinkage.csv")
    if not rows:
        sys.exit(f"{run_dir}/pressure_sinkage.csv is empty")
    result = {}
    for b in sorted({float(r["plate_radius_m"]) for r in rows}):
        sel = sorted((float(r["sinkage_m"]), float(r["pressure_Pa"])) for r in rows
                     if float(r["plate_radius_m"]) == b)
        result[b] = ([1e3 * s for s, _ in sel], [1e-3 * q for _, q in sel])
    return result


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir")
    parser.add_argument("--reference", help="another bevameter run, drawn in grey")
    parser.add_argument("--out", default="docs/lab_soil03.png")
    args = parser.parse_args()
    run_dir, out = args.run_dir, args.out
    fit = {r["parameter"]: r for r in read(f"{run_dir}/bekker_fit.csv")}

    fig, ax = plt.subplots(figsize=(7, 5))
    ax.add_patch(Rectangle((0, 0), FIGURE7_MM, FIGURE7_KPA, fc="0.92", ec="0.4", ls="--",
                           label="seed Figure 7: axes 0-20 mm, 0-20 kPa (points not readable)"))
    if args.reference:
        for j, (b, (z, p)) in enumerate(curves(args.reference).items()):
            ax.plot(z, p, color="0.55", lw=0.8, ls=("--", ":")[j % 2],
                    label=f"reference: {os.path.basename(os.path.normpath(args.reference))}, "
                          f"R = {1e3 * b:g} mm")
    print("plate R [mm]  z [mm]  p [kPa]  vs Figure 7's 20 kPa")
    for i, (b, (z, p)) in enumerate(curves(run_dir).items()):
        colour = f"C{i}"
        ax.plot(z, p, ".", color=colour, ms=3,
                label=f"DEM, proposed (phi, gamma), R = {1e3 * b:g} mm")
        if fit:
            kc, kphi, n = (float(fit[k]["value"]) for k in ("k_c", "k_phi", "n"))
            zs = [x * max(z) / 100 for x in range(101)]
            ax.plot(zs, [1e-3 * (kc / b + kphi) * (1e-3 * zz) ** n for zz in zs], "-",
                    color=colour, lw=1.2)
        for at in SINKAGES_MM:
            pa = interpolate(z, p, at)
            ax.plot(at, pa, "o", mfc="none", color=colour, ms=7)
            verdict = ("inside" if pa <= FIGURE7_KPA else
                       f"outside by {pa - FIGURE7_KPA:.1f} kPa (x {pa / FIGURE7_KPA:.2f})")
            print(f"{1e3 * b:12g}  {at:6g}  {pa:7.2f}  {verdict}")
    if fit:
        text = "Bekker fit (lines), 95 % CI:\n" + "\n".join(
            f"{k} = {float(fit[k]['value']):.4g} ± {float(fit[k]['half_width_95']):.2g} "
            f"{fit[k]['unit']}" for k in ("k_c", "k_phi", "n"))
        ax.text(0.02, 0.98, text, transform=ax.transAxes, va="top", fontsize=8,
                bbox=dict(fc="white", ec="0.7"))
    ax.set_xlabel("sinkage z [mm]")
    ax.set_ylabel("pressure p [kPa]")
    ax.set_xlim(0, 21)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Soil03 (psi = 31°, soil table's phi, gamma) against the seed's Figure 7\n"
                 "circles: p at 5, 10, 15, 20 mm", fontsize=10)
    fig.tight_layout()
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
