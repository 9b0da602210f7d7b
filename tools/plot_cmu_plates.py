#!/usr/bin/python3
"""Simulated against measured plate sinkage: the CMU 3d-terramechanics plate tests.

Reads the measured trials from ../shared/data/cmu-3d-terramechanics (relative to the repository;
never copied into it) and a `grainlink lab bevameter scenarios/lab/cmu_plates.yaml` output
directory, plots p(z) per plate size (measured: median over the trials of both boxes with the
min-max band, on a common sinkage grid; simulated: the plate of the same diameter) and prints the
gap, sim / measured pressure at 10 and 20 mm sinkage per plate (docs/lab.md, "First look at real
data").

Measured columns: sinkage_synced_m and pressure_synced_kPa, the data README's recommendation for
a DEM comparison (force and carriage paired on the exact time stamps; section 6.1 there).

  tools/plot_cmu_plates.py out/cmu_plates [--out docs/cmu_plates.png] [--data DIR]
  tools/plot_cmu_plates.py --check [--data DIR]   # the reader against the data's summary.csv

Exit status 77 (ctest's "skipped") when the data directory is absent.
"""
import argparse
import csv
import glob
import os
import sys
import warnings

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DEFAULT_DATA = os.path.join(REPO, "..", "shared", "data", "cmu-3d-terramechanics")
SKIP = 77
SINKAGE = "sinkage_synced_m"
PRESSURE = "pressure_synced_kPa"
GAP_SINKAGES_MM = (10.0, 20.0)
# The measured zero is the authors' hand-picked first contact; the simulated one is the bed
# surface (98th percentile of grain tops), below the first grains the plate meets. The gap is
# printed for both zeros; "first contact" in the simulation: p first above this.
FIRST_CONTACT_KPA = 0.2


def read_trial(path):
    """One plate trial: dict of column name -> numpy array (the '#' lines are comments)."""
    with open(path, newline="") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    if not rows:
        raise ValueError(f"{path}: no data rows")
    return {key: np.array([float(r[key]) for r in rows]) for key in rows[0]}


def read_trials(data):
    """Every plate trial: list of (trial id, box, diameter in mm, columns)."""
    trials = []
    for path in sorted(glob.glob(os.path.join(data, "plates", "plate_*_d*mm_*.csv"))):
        trial_id = os.path.splitext(os.path.basename(path))[0]
        _, box, diameter, _ = trial_id.split("_", 3)
        trials.append((trial_id, box, int(diameter[1:4]), read_trial(path)))
    if not trials:
        raise ValueError(f"{data}/plates: no plate_*.csv files")
    return trials


def on_grid(z, p, grid):
    """p(z) of one trial on the common grid; NaN outside the trial's sinkage range. The synced
    sinkage is not strictly monotone at the start (carriage noise), so samples are sorted."""
    order = np.argsort(z, kind="stable")
    z, p = z[order], p[order]
    out = np.interp(grid, z, p)
    out[(grid < z[0]) | (grid > z[-1])] = np.nan
    return out


def measured_by_size(trials, grid):
    """Diameter -> (median, min, max, number of trials) on the grid; a grid point needs at least
    half of that size's trials."""
    out = {}
    for d in sorted({t[2] for t in trials}):
        curves = np.array([on_grid(t[3][SINKAGE], t[3][PRESSURE], grid)
                           for t in trials if t[2] == d])
        enough = np.sum(~np.isnan(curves), axis=0) >= (len(curves) + 1) // 2
        with warnings.catch_warnings():  # all-NaN columns: NaN, as wanted
            warnings.simplefilter("ignore", RuntimeWarning)
            med = np.where(enough, np.nanmedian(curves, axis=0), np.nan)
            lo = np.where(enough, np.nanmin(curves, axis=0), np.nan)
            hi = np.where(enough, np.nanmax(curves, axis=0), np.nan)
        out[d] = (med, lo, hi, curves)
    return out


def at_sinkage(curves, grid, z_mm):
    """Median, min, max over the trials that reach z, and how many do."""
    values = np.array([np.interp(z_mm, grid * 1e3, c) for c in curves])
    values = values[~np.isnan(values)]
    if values.size == 0:
        return np.nan, np.nan, np.nan, 0
    return np.median(values), values.min(), values.max(), values.size


def read_simulation(directory):
    """Plate diameter in mm -> (sinkage in m, pressure in kPa) from pressure_sinkage.csv."""
    path = os.path.join(directory, "pressure_sinkage.csv")
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    sim = {}
    for r in rows:
        d = int(round(2000.0 * float(r["plate_radius_m"])))
        z, p = sim.setdefault(d, ([], []))
        z.append(float(r["sinkage_m"]))
        p.append(float(r["pressure_Pa"]) / 1000.0)
    return {d: (np.array(z), np.array(p)) for d, (z, p) in sim.items()}


def check(data):
    """The reader reproduces summary.csv per trial: row count, max authors' pressure (given to
    0.01 kPa, so |diff| <= 0.005 kPa + rounding), max synced sinkage (given to 1e-5 m, so
    |diff| <= 0.51e-5 m: half the last digit plus the float rounding of the printed value)."""
    with open(os.path.join(data, "summary.csv"), newline="") as f:
        summary = {r["id"]: r for r in csv.DictReader(f) if r["kind"] == "plate"}
    trials = read_trials(data)
    failures = 0
    for trial_id, box, d, cols in trials:
        s = summary.get(trial_id)
        if s is None:
            print(f"FAIL {trial_id}: not in summary.csv")
            failures += 1
            continue
        got = (len(cols["pressure_kPa"]), cols["pressure_kPa"].max(), cols[SINKAGE].max())
        want = (int(s["n_points"]), float(s["max_pressure_kPa"]),
                float(s["max_sinkage_synced_m"]))
        ok = (got[0] == want[0] and abs(got[1] - want[1]) <= 0.005 + 1e-9
              and abs(got[2] - want[2]) <= 0.51e-5 and int(s["plate_diameter_mm"]) == d
              and s["box"] == box)
        print(f"{'ok  ' if ok else 'FAIL'} {trial_id}: {got[0]} rows, max p {got[1]:.4f} kPa "
              f"(summary {want[1]}), max z {got[2]:.6f} m (summary {want[2]})")
        failures += 0 if ok else 1
    if len(trials) != len(summary):
        print(f"FAIL: {len(trials)} plate files, {len(summary)} plate rows in summary.csv")
        failures += 1
    print(f"{len(trials)} trials read, {failures} mismatches")
    return 1 if failures else 0


def plot(sim_dir, data, out_path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    trials = read_trials(data)
    grid = np.linspace(0.0, 0.04, 401)
    measured = measured_by_size(trials, grid)
    sim = read_simulation(sim_dir)
    colours = {60: "tab:blue", 80: "tab:orange", 100: "tab:green"}
    fig, ax = plt.subplots(figsize=(7.5, 5))
    print("gap: simulated / measured median pressure (measured: synced columns, both boxes)")
    for d, (med, lo, hi, curves) in measured.items():
        n = len(curves)
        c = colours.get(d, "k")
        ax.fill_between(grid * 1e3, lo, hi, color=c, alpha=0.2, lw=0)
        ax.plot(grid * 1e3, med, color=c, lw=1.5, label=f"measured {d} mm: median, min-max of {n}")
        if d in sim:
            z, p = sim[d]
            contact = z[np.argmax(p > FIRST_CONTACT_KPA)]
            keep = z >= contact - 1e-3
            ax.plot(z[keep] * 1e3, p[keep], color=c, lw=1.5, ls="--",
                    label=f"DEM {d} mm (R = {d / 2:g} mm)")
            print(f"  {d} mm plate (simulated first contact at z = {contact * 1e3:.2f} mm):")
            for z_mm in GAP_SINKAGES_MM:
                m, m_lo, m_hi, reach = at_sinkage(curves, grid, z_mm)
                sims = [np.interp(zz, z, p) if z[-1] >= zz else np.nan
                        for zz in (z_mm * 1e-3, contact + z_mm * 1e-3)]
                print(f"    z = {z_mm:g} mm: measured {m:.2f} kPa [{m_lo:.2f}, {m_hi:.2f}] "
                      f"({reach} of {n} trials reach it); sim {sims[0]:.2f} kPa, ratio "
                      f"{sims[0] / m:.2f} (zero at the surface); sim {sims[1]:.2f} kPa, ratio "
                      f"{sims[1] / m:.2f} (zero at first contact)")
        else:
            print(f"  {d} mm plate: no simulated plate of this diameter in {sim_dir}")
    ax.set_xlabel("sinkage z [mm]")
    ax.set_ylabel("pressure p [kPa]")
    ax.set_xlim(-4, 40)
    ax.axvline(0.0, color="0.6", lw=0.8)
    ax.set_ylim(bottom=0)
    ax.set_title("CMU plate sinkage: measured (solid, band) vs DEM (dashed)\n"
                 "z = 0: measured first contact; DEM bed surface (98th percentile)", fontsize=10)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(out_path, dpi=110)
    print(f"written: {out_path}")
    return 0


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("simulation", nargs="?", help="grainlink lab bevameter output directory")
    parser.add_argument("--data", default=DEFAULT_DATA, help="the CMU data directory")
    parser.add_argument("--out", default=os.path.join(REPO, "docs", "cmu_plates.png"))
    parser.add_argument("--check", action="store_true",
                        help="check the reader against summary.csv and exit")
    args = parser.parse_args()
    if not os.path.isdir(os.path.join(args.data, "plates")):
        print(f"skipped: no CMU data at {os.path.normpath(args.data)} (it is read from there, "
              "never copied into the repository)")
        return SKIP
    if args.check:
        return check(args.data)
    if not args.simulation:
        parser.error("give the simulation's output directory (or --check)")
    return plot(args.simulation, args.data, args.out)


if __name__ == "__main__":
    sys.exit(main())
