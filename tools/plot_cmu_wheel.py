#!/usr/bin/env python3
"""The CMU single-wheel study against the test bed's measurements (docs/studies/cmu_wheel.md).

    tools/plot_cmu_wheel.py --slip out/cmu_wheel --beta out/cmu_wheel_beta \
        [--checks out/cmu_wheel_checks] [--data ../shared/data/cmu-3d-terramechanics] \
        [--out docs/studies/cmu_wheel.png]

Reads each finished point's summary.json (and the study's study.json for what it varied) and the
measured steady_state_wheel/{smooth,grouser}.csv. Simulated: mean over the bed seeds, with the
seeds' sd (n = 2: their half difference times sqrt 2). Measured: mean and sd over the test bed's
three runs at each set rim speed. The measured depth Z_mm has the authors' offset as its zero, so
sinkage is compared as its change from slip 0. Prints the tables of the results page.
"""
import argparse
import csv
import json
import math
import os
import statistics
import sys
from collections import defaultdict

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

WHEELS = ("smooth", "grouser")


def mean_sd(values):
    values = [v for v in values if not math.isnan(v)]
    if not values:
        return math.nan, math.nan, 0
    sd = statistics.stdev(values) if len(values) > 1 else math.nan
    return statistics.fmean(values), sd, len(values)


def simulated(folder):
    """Each finished point: its wheel, settings and the steady values of its one slip run."""
    with open(os.path.join(folder, "study.json")) as f:
        study = json.load(f)
    points = []
    for p in study["points"]:
        path = os.path.join(folder, "points", p["id"], "summary.json")
        if not os.path.exists(path):
            continue
        with open(path) as f:
            run = json.load(f)["runs"][0]
        settings = dict(p["settings"])
        points.append({"wheel": "grouser" if "grouser_count" in settings.get("wheel.shape", "")
                       else "smooth",
                       "settings": settings,
                       "slip": run["slip"],
                       "beta": run.get("slip_angle_deg", 0.0),
                       **{k: run.get(k, math.nan) for k in
                          ("traction_N", "side_force_N", "vertical_load_N", "torque_N_m",
                           "sinkage_m", "traction_sd_N")}})
    return points


def measured(data_dir):
    """(wheel, beta, rim speed set-point) -> list of runs."""
    runs = defaultdict(list)
    for wheel in WHEELS:
        with open(os.path.join(data_dir, "steady_state_wheel", wheel + ".csv")) as f:
            for r in csv.DictReader(f):
                runs[(wheel, int(r["beta_deg"]), int(r["Vry_cmd_mm_s"]))].append(
                    {k: float(v) for k, v in r.items() if k != "wheel"})
    return runs


def by_slip(points, beta=0.0):
    """(wheel, slip) -> points at that slip angle."""
    out = defaultdict(list)
    for p in points:
        if abs(p["beta"] - beta) < 1e-9:
            out[(p["wheel"], round(p["slip"], 3))].append(p)
    return out


def nearest_measured(meas, wheel, beta, slip):
    """The measured set-point whose mean slip is nearest to `slip`."""
    keys = [k for k in meas if k[0] == wheel and k[1] == beta]
    return min(keys, key=lambda k: abs(statistics.fmean(r["slip"] for r in meas[k]) - slip))


def fmt(m, sd, digits=1):
    if math.isnan(m):
        return "–"
    return f"{m:.{digits}f}" + ("" if math.isnan(sd) else f" ± {sd:.{digits}f}")


def slip_table(points, meas):
    cells = by_slip(points)
    print("| wheel | s | traction sim [N] | traction measured [N] | load sim [N] | "
          "load measured [N] | Δ sinkage sim [mm] | Δ sinkage measured [mm] | torque sim [N m] |")
    print("|---|---|---|---|---|---|---|---|---|")
    curves = {}
    for wheel in WHEELS:
        slips = sorted(s for w, s in cells if w == wheel)
        if not slips:
            continue
        zero_sim = mean_sd([1e3 * p["sinkage_m"] for p in cells.get((wheel, 0.0), [])])[0]
        zero_meas = statistics.fmean(r["Z_mm"] for r in meas[nearest_measured(meas, wheel, 0, 0.0)])
        rows = []
        for s in slips:
            ps = cells[(wheel, s)]
            runs = meas[nearest_measured(meas, wheel, 0, s)]
            row = {"s": s,
                   "sim": {k: mean_sd([p[k] for p in ps]) for k in
                           ("traction_N", "vertical_load_N", "torque_N_m")},
                   "sink_sim": mean_sd([1e3 * p["sinkage_m"] - zero_sim for p in ps]),
                   "meas": {k: mean_sd([r[c] for r in runs]) for k, c in
                            (("traction_N", "F_tractive_N"), ("vertical_load_N", "F_load_N"))},
                   "sink_meas": mean_sd([r["Z_mm"] - zero_meas for r in runs]),
                   "slip_meas": statistics.fmean(r["slip"] for r in runs)}
            rows.append(row)
            print(f"| {wheel} | {s:g} | {fmt(*row['sim']['traction_N'][:2])} | "
                  f"{fmt(*row['meas']['traction_N'][:2])} | "
                  f"{fmt(*row['sim']['vertical_load_N'][:2])} | "
                  f"{fmt(*row['meas']['vertical_load_N'][:2])} | {fmt(*row['sink_sim'][:2])} | "
                  f"{fmt(*row['sink_meas'][:2])} | {fmt(*row['sim']['torque_N_m'][:2], 2)} |")
        curves[wheel] = rows
    return curves


def beta_table(points, meas, slip):
    cells = defaultdict(list)
    for p in points:
        cells[(p["wheel"], p["beta"])].append(p)
    print("| wheel | β [deg] | traction sim [N] | traction measured [N] | side sim [N] | "
          "side measured [N] | load sim [N] | load measured [N] |")
    print("|---|---|---|---|---|---|---|---|")
    curves = {}
    for wheel in WHEELS:
        rows = []
        for beta in sorted(b for w, b in cells if w == wheel):
            ps = cells[(wheel, beta)]
            runs = meas[nearest_measured(meas, wheel, int(round(beta)), slip)]
            row = {"beta": beta,
                   "sim": {k: mean_sd([p[k] for p in ps]) for k in
                           ("traction_N", "side_force_N", "vertical_load_N")},
                   "meas": {k: mean_sd([r[c] for r in runs]) for k, c in
                            (("traction_N", "F_tractive_N"), ("side_force_N", "F_side_N"),
                             ("vertical_load_N", "F_load_N"))}}
            rows.append(row)
            print(f"| {wheel} | {beta:g} | {fmt(*row['sim']['traction_N'][:2])} | "
                  f"{fmt(*row['meas']['traction_N'][:2])} | "
                  f"{fmt(*row['sim']['side_force_N'][:2])} | "
                  f"{fmt(*row['meas']['side_force_N'][:2])} | "
                  f"{fmt(*row['sim']['vertical_load_N'][:2])} | "
                  f"{fmt(*row['meas']['vertical_load_N'][:2])} |")
        curves[wheel] = rows
    return curves


def checks_table(checks, base_points):
    """Each check point against the base point of the same wheel, slip and seed."""
    base = {(p["wheel"], round(p["slip"], 3), p["settings"].get("soil.deposition.seed")): p
            for p in base_points}
    print("| wheel | changed | traction [N] | against [N] | sinkage [mm] | against [mm] |")
    print("|---|---|---|---|---|---|")
    for p in checks:
        s = p["settings"]
        if s.get("wheel.carriage_speed_m_s", "0.05") != "0.05":
            what = f"carriage {1e3 * float(s['wheel.carriage_speed_m_s']):g} mm/s"
        elif "0.32" in s.get("soil.walls.0.upper_m", ""):
            what = "bin 320 mm wide"
        else:
            what = "grains x 0.75"
        b = base.get((p["wheel"], round(p["slip"], 3), s.get("soil.deposition.seed")))
        if b is None:
            continue
        print(f"| {p['wheel']} | {what} | {p['traction_N']:.2f} | {b['traction_N']:.2f} | "
              f"{1e3 * p['sinkage_m']:.1f} | {1e3 * b['sinkage_m']:.1f} |")


def band(ax, x, ms, color, label, fmt_="o-"):
    m = [v[0] for v in ms]
    sd = [0.0 if math.isnan(v[1]) else v[1] for v in ms]
    ax.errorbar(x, m, yerr=sd, fmt=fmt_, color=color, capsize=3, label=label, ms=4)


def main():
    a = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    a.add_argument("--slip", required=True)
    a.add_argument("--beta")
    a.add_argument("--checks")
    a.add_argument("--data", default=os.path.join(os.path.dirname(__file__), "..", "..",
                                                  "shared", "data", "cmu-3d-terramechanics"))
    a.add_argument("--out", default="cmu_wheel.png")
    args = a.parse_args()
    if not os.path.isdir(os.path.join(args.data, "steady_state_wheel")):
        sys.exit(f"plot_cmu_wheel.py: no steady_state_wheel/ in {args.data} (give --data)")
    meas = measured(args.data)
    slip_points = simulated(args.slip)
    print("## Slip at slip angle 0\n")
    slip_curves = slip_table(slip_points, meas)
    beta_curves, beta_slip = {}, None
    if args.beta:
        beta_points = simulated(args.beta)
        beta_slip = statistics.fmean(p["slip"] for p in beta_points) if beta_points else None
        print(f"\n## Slip angle at slip {beta_slip:g}\n")
        beta_curves = beta_table(beta_points, meas, beta_slip)
    if args.checks:
        print("\n## Numerical checks (seed 1)\n")
        checks_table(simulated(args.checks), slip_points)

    rows = 2 if beta_curves else 1
    fig, axes = plt.subplots(rows, 3, figsize=(14, 4.2 * rows), squeeze=False)
    for i, wheel in enumerate(WHEELS):
        rs = slip_curves.get(wheel, [])
        x = [r["s"] for r in rs]
        xm = [r["slip_meas"] for r in rs]
        for ax, sim, mea, label in (
                (axes[0][0], [r["sim"]["traction_N"] for r in rs],
                 [r["meas"]["traction_N"] for r in rs], "traction [N]"),
                (axes[0][1], [r["sim"]["vertical_load_N"] for r in rs],
                 [r["meas"]["vertical_load_N"] for r in rs], "vertical load [N]"),
                (axes[0][2], [r["sink_sim"] for r in rs], [r["sink_meas"] for r in rs],
                 "sinkage change from s = 0 [mm]")):
            band(ax, x, sim, f"C{i}", f"{wheel}, DEM")
            band(ax, xm, mea, f"C{i}", f"{wheel}, measured", "s--")
            ax.set_xlabel("slip s [-]")
            ax.set_ylabel(label)
            ax.grid(alpha=0.3)
    axes[0][0].legend(fontsize=8)
    axes[0][0].set_title("CMU single wheel, slip angle 0 (mean ± sd)")
    if beta_curves:
        for i, wheel in enumerate(WHEELS):
            rs = beta_curves.get(wheel, [])
            x = [r["beta"] for r in rs]
            for ax, key, label in ((axes[1][0], "traction_N", "traction [N]"),
                                   (axes[1][1], "side_force_N", "side force [N]"),
                                   (axes[1][2], "vertical_load_N", "vertical load [N]")):
                band(ax, x, [r["sim"][key] for r in rs], f"C{i}", f"{wheel}, DEM")
                band(ax, x, [r["meas"][key] for r in rs], f"C{i}", f"{wheel}, measured", "s--")
                ax.set_xlabel("slip angle β [deg]")
                ax.set_ylabel(label)
                ax.grid(alpha=0.3)
        axes[1][0].set_title(f"against slip angle at s = {beta_slip:g}")
        axes[1][1].legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(args.out, dpi=110)
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
