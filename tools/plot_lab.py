#!/usr/bin/python3
"""Plots a virtual lab run (grainlink lab TEST SCENARIO --out RUN_DIR) from RUN_DIR/summary.json
(format in docs/lab.md) into RUN_DIR/TEST.png. `grainlink lab` runs it after every test.

bevameter: the measured p(z) of every plate and Bekker's fitted p = (k_c/b + k_phi) z^n over it,
with the fit's values and 95 % intervals.
repose: the heap profile (highest grain top per radial bin) with the angle.
direct_shear: tau against displacement per normal stress, and the peak and residual strengths
with their Mohr-Coulomb lines.
bevameter_shear: tau(j) per normal pressure with the Janosi-Hanamoto fit, and the normal pressure
the servo held while shearing.
wheel: steady traction, vertical load, motor torque and sinkage against slip (mean +- sd over the
steady stretch), and traction against travel per slip.

Usage: tools/plot_lab.py RUN_DIR
Runs under Debian's /usr/bin/python3 (python3-matplotlib).
"""
import csv
import json
import math
import sys

try:
    import matplotlib
except ImportError:
    sys.exit("plot_lab.py: python3-matplotlib is not installed (scripts/install-deps installs it)")

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def read(path):
    """Rows of a lab CSV as dicts (plot_soil03.py and plot_cmu_plates.py read the CSVs)."""
    with open(path) as f:
        return list(csv.DictReader(f))


def fitted(summary, law):
    """{parameter: {value, half_width_95, unit}} of a fitted law, or None without that fit."""
    fit = summary["fits"].get(law)
    return fit["parameters"] if fit else None


def value(x):
    """A summary number; JSON null is NaN."""
    return math.nan if x is None else x


def fit_text(title, parameters, names, scale=None):
    """Text box lines 'name = value ± half width unit' (scale: name -> (factor, unit))."""
    lines = [title]
    for n in names:
        p = parameters[n]
        f, unit = (scale or {}).get(n, (1.0, p["unit"]))
        lines.append(f"{n} = {value(p['value']) * f:.4g} ± {value(p['half_width_95']) * f:.2g} {unit}")
    return "\n".join(lines)


def repose(summary, ax):
    run = summary["runs"][0]
    angle = fitted(summary, "repose")
    title = (f"angle of repose {angle['angle']['value']:.4g} ± {angle['angle']['half_width_95']:.4g}"
             f" deg (95 %, {int(run['flank_bins'])} flank bins)" if angle
             else f"no heap: {summary['fit_note']}")
    ax.step([1e3 * r for r in run["radius_m"]], [1e3 * h for h in run["height_m"]], where="mid",
            label="highest grain top per radial bin")
    ax.set_xlabel("distance from the tube axis [mm]")
    ax.set_ylabel("heap height [mm]")
    ax.set_aspect("equal")
    ax.grid(alpha=0.3)
    ax.set_title(title, fontsize=9)
    ax.legend(fontsize=8)


def direct_shear(summary, left, right):
    for i, run in enumerate(summary["runs"]):
        left.plot([1e3 * d for d in run["displacement_m"]],
                  [1e-3 * t for t in run["shear_stress_Pa"]], "-", color=f"C{i}",
                  label=f"sigma = {1e-3 * run['target_normal_stress_Pa']:g} kPa")
    left.set_xlabel("horizontal displacement d [mm]")
    left.set_ylabel("shear stress tau [kPa]")
    left.grid(alpha=0.3)
    left.legend(fontsize=8)
    left.set_title("Direct shear: tau(d)")
    top = 0.0
    for kind, marker in (("peak", "o"), ("residual", "s")):
        sig = [1e-3 * r[f"{kind}_normal_stress_Pa"] for r in summary["runs"]]
        tau = [1e-3 * r[f"{kind}_shear_stress_Pa"] for r in summary["runs"]]
        top = max([top] + sig)
        right.plot(sig, tau, marker, label=kind)
        fit = fitted(summary, f"mohr_coulomb_{kind}")
        if fit:
            psi, dpsi = fit["psi"]["value"], fit["psi"]["half_width_95"]
            c = fit["c"]["value"] if "c" in fit else 0.0  # through the origin: c not fitted
            cohesion = (f"c = {1e-3 * c:.2f} ± {1e-3 * fit['c']['half_width_95']:.2f} kPa"
                        if "c" in fit else "c = 0 (not fitted)")
            xs = [top * 1.1 * k / 50 for k in range(51)]
            right.plot(xs, [1e-3 * c + x * math.tan(math.radians(psi)) for x in xs], "--",
                       color=right.lines[-1].get_color(),
                       label=f"{kind}: psi = {psi:.1f} ± {dpsi:.1f} deg, {cohesion} (95 %)")
    right.set_xlabel("normal stress sigma [kPa]")
    right.set_ylabel("shear stress tau [kPa]")
    right.set_xlim(left=0)
    right.set_ylim(bottom=0)
    right.grid(alpha=0.3)
    right.legend(fontsize=7, loc="upper left")
    right.set_title("Mohr-Coulomb")


def bevameter_shear(summary, left, right):
    fit = fitted(summary, "janosi")
    tau_max = 0.0
    for i, run in enumerate(summary["runs"]):
        j = [1e3 * x for x in run["shear_displacement_m"]]
        tau_max = max([tau_max] + run["shear_stress_Pa"])
        left.plot(j, [1e-3 * t for t in run["shear_stress_Pa"]], ".", ms=2.5, color=f"C{i}",
                  label=f"DEM, sigma = {1e-3 * run['target_pressure_Pa']:g} kPa (target)")
        right.plot(j, [1e-3 * s for s in run["normal_pressure_Pa"]], "-", lw=0.8, color=f"C{i}")
        right.axhline(1e-3 * run["target_pressure_Pa"], color=f"C{i}", ls="--", lw=0.8)
        if fit:
            c, phi, k = (fit[n]["value"] for n in ("c", "phi", "K"))
            js = [max(j) * x / 100 for x in range(101)]
            strength = c + run["mean_pressure_Pa"] * math.tan(math.radians(phi))
            left.plot(js, [1e-3 * strength * (1 - math.exp(-1e-3 * x / k)) for x in js], "-",
                      color=f"C{i}", lw=1.2)
    if fit:
        text = fit_text("Janosi-Hanamoto fit (lines, at the mean sigma held), 95 % CI:", fit,
                        ("c", "phi", "K"), {"c": (1e-3, "kPa"), "K": (1e3, "mm")})
        left.text(0.02, 0.98, text, transform=left.transAxes, va="top", fontsize=8,
                  bbox=dict(fc="white", ec="0.7"))
    left.set_xlabel("shear displacement j = theta R_mean [mm]")
    left.set_ylabel("shear stress tau [kPa]")
    left.set_xlim(left=0)
    left.set_ylim(0, 1.45e-3 * tau_max)  # head room above the curves for the fit's text box
    left.grid(alpha=0.3)
    left.legend(fontsize=8, loc="lower right")
    left.set_title("Bevameter shear: tau(j)")
    right.set_xlabel("shear displacement j [mm]")
    right.set_ylabel("normal pressure sigma [kPa]")
    right.set_ylim(bottom=0)
    right.grid(alpha=0.3)
    right.set_title("Load servo: sigma held (dashed: target)")


def bevameter(summary, ax):
    fit = fitted(summary, "bekker")
    for i, run in enumerate(summary["runs"]):
        b = run["plate_radius_m"]
        z = [1e3 * x for x in run["sinkage_m"]]
        ax.plot(z, [1e-3 * p for p in run["pressure_Pa"]], ".", color=f"C{i}", ms=3,
                label=f"DEM, plate R = {1e3 * b:g} mm")
        if fit:
            kc, kphi, n = (fit[k]["value"] for k in ("k_c", "k_phi", "n"))
            zs = [x * max(z) / 100 for x in range(101)]
            ax.plot(zs, [1e-3 * (kc / b + kphi) * (1e-3 * zz) ** n for zz in zs], "-",
                    color=f"C{i}", lw=1.2)
    if fit:
        ax.text(0.02, 0.98, fit_text("Bekker fit (lines), 95 % CI:", fit, ("k_c", "k_phi", "n")),
                transform=ax.transAxes, va="top", fontsize=8, bbox=dict(fc="white", ec="0.7"))
    ax.set_xlabel("sinkage z [mm]")
    ax.set_ylabel("pressure p [kPa]")
    ax.set_xlim(left=0)
    ax.set_ylim(bottom=0)
    ax.grid(alpha=0.3)
    ax.legend(loc="lower right", fontsize=8)
    ax.set_title("Virtual bevameter: pressure-sinkage")


def wheel(summary, axes):
    runs = sorted(summary["runs"], key=lambda r: r["slip"])
    slip = [r["slip"] for r in runs]
    panels = (("traction_N", "traction_sd_N", "traction [N]", 1),
              ("vertical_load_N", "vertical_load_sd_N", "vertical load [N]", 1),
              ("torque_N_m", "torque_sd_N_m", "motor torque [N m]", 1),
              ("sinkage_m", "sinkage_sd_m", "sinkage [mm]", 1e3))
    for ax, (key, sd, label, scale) in zip(axes[:4], panels):
        ax.errorbar(slip, [scale * r[key] for r in runs], yerr=[scale * r[sd] for r in runs],
                    fmt="o-", capsize=3)
        ax.set_xlabel("slip s [-]")
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
    for r in runs:
        axes[4].plot([1e3 * x for x in r["travel_m"]], r["traction_series_N"], lw=0.8,
                     label=f"s = {r['slip']:g}")
    axes[4].set_xlabel("travel [mm]")
    axes[4].set_ylabel("traction [N]")
    axes[4].legend(fontsize=8)
    axes[4].grid(alpha=0.3)
    if all("side_force_N" in r for r in runs):
        axes[5].errorbar(slip, [r["side_force_N"] for r in runs],
                         yerr=[r["side_force_sd_N"] for r in runs], fmt="o-", capsize=3)
        axes[5].set_xlabel("slip s [-]")
        axes[5].set_ylabel(f"side force [N] (slip angle {runs[0]['slip_angle_deg']:g} deg)")
        axes[5].grid(alpha=0.3)
    else:  # a summary from before the side force
        axes[5].axis("off")
    axes[0].set_title("Single-wheel test: steady values (mean +- sd)")


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    run_dir = sys.argv[1]
    with open(f"{run_dir}/summary.json") as f:
        summary = json.load(f)
    test = summary["test"]
    if test in ("direct_shear", "bevameter_shear"):
        fig, axes = plt.subplots(1, 2, figsize=(11, 4.5))
        (direct_shear if test == "direct_shear" else bevameter_shear)(summary, *axes)
    elif test == "repose":
        fig, ax = plt.subplots(figsize=(7, 4))
        repose(summary, ax)
    elif test == "bevameter":
        fig, ax = plt.subplots(figsize=(7, 5))
        bevameter(summary, ax)
    elif test == "wheel":
        fig, axes = plt.subplots(2, 3, figsize=(13, 7))
        wheel(summary, axes.flat)
    else:
        sys.exit(f"plot_lab.py: {run_dir}/summary.json: unknown test '{test}'")
    fig.tight_layout()
    out = f"{run_dir}/{test}.png"
    fig.savefig(out, dpi=120)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()
