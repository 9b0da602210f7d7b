#!/usr/bin/python3
"""Plots a virtual lab run (grainlink lab TEST SCENARIO --out RUN_DIR).

bevameter: the measured p(z) of every plate and Bekker's fitted p = (k_c/b + k_phi) z^n over it,
with the fit's values and 95 % intervals (RUN_DIR/pressure_sinkage.csv, bekker_fit.csv)
-> RUN_DIR/bevameter.png.
repose: the heap profile (highest grain top per radial bin, RUN_DIR/heap_profile.csv) with the
angle from RUN_DIR/report.txt -> RUN_DIR/repose.png.
direct_shear: tau against displacement per normal stress (RUN_DIR/shear_curves.csv) and the peak
and residual strengths with their Mohr-Coulomb lines (RUN_DIR/mohr_coulomb.csv)
-> RUN_DIR/direct_shear.png.
bevameter_shear: tau(j) per normal pressure with the Janosi-Hanamoto fit, and the normal pressure
the servo held while shearing (RUN_DIR/shear_displacement.csv, janosi_fit.csv)
-> RUN_DIR/bevameter_shear.png.

Usage: tools/plot_lab.py RUN_DIR
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import math
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
        angle = next((l.strip() for l in f if "angle of repose" in l or "no heap" in l), "")
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


def direct_shear(run_dir):
    curves = read(f"{run_dir}/shear_curves.csv")
    points = read(f"{run_dir}/mohr_coulomb.csv")
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    stresses = sorted({float(r["target_normal_stress_Pa"]) for r in curves})
    for i, s in enumerate(stresses):
        rows = [r for r in curves if float(r["target_normal_stress_Pa"]) == s]
        left.plot([1e3 * float(r["displacement_m"]) for r in rows],
                  [1e-3 * float(r["shear_stress_Pa"]) for r in rows], "-", color=f"C{i}",
                  label=f"sigma = {1e-3 * s:g} kPa")
    left.set_xlabel("horizontal displacement d [mm]")
    left.set_ylabel("shear stress tau [kPa]")
    left.grid(alpha=0.3)
    left.legend(fontsize=8)
    left.set_title("Direct shear: tau(d)")
    top = 0.0
    for kind, marker in (("peak", "o"), ("residual", "s")):
        rows = [r for r in points if r["kind"] == kind]
        sig = [1e-3 * float(r["normal_stress_Pa"]) for r in rows]
        tau = [1e-3 * float(r["shear_stress_Pa"]) for r in rows]
        top = max([top] + sig)
        right.plot(sig, tau, marker, label=kind)
        if rows and rows[0]["friction_angle_deg"]:
            psi, dpsi, c, dc = (float(rows[0][k]) for k in (
                "friction_angle_deg", "friction_angle_half_width_95_deg", "cohesion_Pa",
                "cohesion_half_width_95_Pa"))
            xs = [top * 1.1 * k / 50 for k in range(51)]
            right.plot(xs, [1e-3 * c + x * math.tan(math.radians(psi)) for x in xs], "--",
                       color=right.lines[-1].get_color(),
                       label=f"{kind}: psi = {psi:.1f} ± {dpsi:.1f} deg, "
                             f"c = {1e-3 * c:.2f} ± {1e-3 * dc:.2f} kPa (95 %)")
    right.set_xlabel("normal stress sigma [kPa]")
    right.set_ylabel("shear stress tau [kPa]")
    right.set_xlim(left=0)
    right.set_ylim(bottom=0)
    right.grid(alpha=0.3)
    right.legend(fontsize=7, loc="upper left")
    right.set_title("Mohr-Coulomb")
    fig.tight_layout()
    out = f"{run_dir}/direct_shear.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def bevameter_shear(run_dir):
    rows = read(f"{run_dir}/shear_displacement.csv")
    fit_rows = read(f"{run_dir}/janosi_fit.csv")
    fit = {r["parameter"]: r for r in fit_rows if r["parameter"] != "sigma_mean"}
    sigma_mean = [float(r["value"]) for r in fit_rows if r["parameter"] == "sigma_mean"]
    fig, (left, right) = plt.subplots(1, 2, figsize=(11, 4.5))
    targets = sorted({float(r["target_pressure_Pa"]) for r in rows})
    for i, s in enumerate(targets):
        run = [r for r in rows if float(r["target_pressure_Pa"]) == s]
        j = [1e3 * float(r["shear_displacement_m"]) for r in run]
        left.plot(j, [1e-3 * float(r["shear_stress_Pa"]) for r in run], ".", ms=2.5,
                  color=f"C{i}", label=f"DEM, sigma = {1e-3 * s:g} kPa (target)")
        right.plot(j, [1e-3 * float(r["normal_pressure_Pa"]) for r in run], "-", lw=0.8,
                   color=f"C{i}")
        right.axhline(1e-3 * s, color=f"C{i}", ls="--", lw=0.8)
        if fit and i < len(sigma_mean):
            c, phi, k = (float(fit[n]["value"]) for n in ("c", "phi", "K"))
            js = [max(j) * x / 100 for x in range(101)]
            strength = c + sigma_mean[i] * math.tan(math.radians(phi))
            left.plot(js, [1e-3 * strength * (1 - math.exp(-1e-3 * x / k)) for x in js], "-",
                      color=f"C{i}", lw=1.2)
    if fit:
        text = "Janosi-Hanamoto fit (lines, at the mean sigma held), 95 % CI:\n" + "\n".join(
            f"{n} = {float(fit[n]['value']) * f:.4g} ± {float(fit[n]['half_width_95']) * f:.2g} {u}"
            for n, f, u in (("c", 1e-3, "kPa"), ("phi", 1, "deg"), ("K", 1e3, "mm")))
        left.text(0.02, 0.98, text, transform=left.transAxes, va="top", fontsize=8,
                  bbox=dict(fc="white", ec="0.7"))
    left.set_xlabel("shear displacement j = theta R_mean [mm]")
    left.set_ylabel("shear stress tau [kPa]")
    left.set_xlim(left=0)
    # Head room above the curves for the fit's text box.
    left.set_ylim(0, 1.45e-3 * max(float(r["shear_stress_Pa"]) for r in rows))
    left.grid(alpha=0.3)
    left.legend(fontsize=8, loc="lower right")
    left.set_title("Bevameter shear: tau(j)")
    right.set_xlabel("shear displacement j [mm]")
    right.set_ylabel("normal pressure sigma [kPa]")
    right.set_ylim(bottom=0)
    right.grid(alpha=0.3)
    right.set_title("Load servo: sigma held (dashed: target)")
    fig.tight_layout()
    out = f"{run_dir}/bevameter_shear.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    if os.path.exists(f"{run_dir}/heap_profile.csv"):
        return repose(run_dir)
    if os.path.exists(f"{run_dir}/shear_curves.csv"):
        return direct_shear(run_dir)
    if os.path.exists(f"{run_dir}/shear_displacement.csv"):
        return bevameter_shear(run_dir)
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
