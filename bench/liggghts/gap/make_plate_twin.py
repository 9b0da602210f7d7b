#!/usr/bin/python3
"""Plate-sinkage "measurements" made with LIGGGHTS, another DEM code, for a blind check of
`grainlink gap diagnose` (docs/gap.md, "Data from another code").

The soil is the self-test base's (scenarios/gap/selftest-full/base.yaml) written in LIGGGHTS'
own laws: Hertz, Mindlin with history, EPSD2 rolling friction, SJKR cohesion, restitution
damping. The laws differ from grainlink's (its linear tangential spring with stick and slip
angles, viscous normal damping), so even the unaltered soil is not grainlink's base: every
twin carries a code difference besides its hidden effect, as real data would.

    make_plate_twin.py --out MEAS [--set coh=2e5] [--zero-offset M] [--compliance M_PER_N]
                       [--seeds 3] [--label NAME]

writes MEAS/experiments.yaml and MEAS/data/*.csv (three plates in the 50 mm box, one in the
35 mm box, one bed per seed and box, every plate on a copy of it) and the key (what was
changed) to MEAS.key.json, outside the folder the diagnosis reads. `--zero-offset` and
`--compliance` hide an error of the measuring chain instead of the soil's: every written
sinkage reads M more (a zero picked early), or c F more (a rig deflecting under the plate's
force F).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))

# grainlink's self-test soil in LIGGGHTS' terms (scenarios/gap/crosscode/base.yaml). e = 0.3 is
# the restitution of grainlink's viscous 0.2 N s/m at a typical contact of this bed (damping
# ratio ~0.33). dt is 2e-5 s, not the self-test's 4e-5: with Mindlin's tangential spring both
# codes press the plates 6-10x softer at 4e-5 s than at 2e-5 s (unresolved).
# "scale" multiplies every grain's radius and divides the count by its cube (the same bed height):
# finer grains than the base's, as a real soil always has.
BASE = {"E": 2.7e7, "e": 0.3, "mu": math.tan(math.radians(32)), "mur": 0.3, "coh": 0.0,
        "rho": 2400.0, "dt": 2.0e-5, "scale": 1.0}
RADII = (0.0018, 0.0019, 0.0020)  # m, the base's three grain sizes
BOXES = {"wide": {"x0": 0.0, "x1": 0.05, "count": 1300, "height": 0.08},
         "narrow": {"x0": 0.0075, "x1": 0.0425, "count": 640, "height": 0.09}}
PLATES = [("wide", 0.020), ("wide", 0.025), ("wide", 0.030), ("narrow", 0.020)]
SPEED = 0.05          # m/s, the base's bevameter speed
REACH = 0.008         # m of sinkage below the bed surface (deeper, soft grains overlap by 0.4 r)
CLEARANCE = 0.001     # m above the highest grain under the plate at the start
SAMPLE_S = 0.002      # force averaging interval
SETTLE_S = 0.5
PRIMES = [15485863, 15485867, 32452843, 32452867, 49979687, 49979693, 67867967, 67867979,
          86028121, 86028157, 104395301, 104395303]


def run_liggghts(script, variables, workdir):
    args = ["stdbuf", "-o0", "liggghts", "-in", os.path.join(HERE, script), "-log", "none", "-echo", "none"]
    for key, value in variables.items():
        args += ["-var", key, str(value)]
    done = subprocess.run(args, cwd=HERE, capture_output=True, text=True, errors="replace")
    if done.returncode != 0 or "ERROR" in done.stdout:
        sys.exit(f"LIGGGHTS failed on {script}:\n{done.stdout[-3000:]}{done.stderr[-2000:]}")
    return done.stdout


def read_grains(data_file):
    """(x, y, z, r) of every atom of a LIGGGHTS granular data file."""
    grains, in_atoms = [], False
    with open(data_file) as f:
        for line in f:
            words = line.split()
            if not words:
                continue
            if words[0] == "Atoms":
                in_atoms = True
                continue
            if words[0] in ("Velocities", "Bonds"):
                in_atoms = False
            if in_atoms and len(words) >= 7:
                # id type diameter density x y z
                grains.append((float(words[4]), float(words[5]), float(words[6]),
                               0.5 * float(words[2])))
    return grains


def disc_stl(path, radius, thickness, segments=48):
    """A closed flat disc, bottom face at z = 0, axis vertical, centred at the origin."""
    rim = [(radius * math.cos(2 * math.pi * k / segments),
            radius * math.sin(2 * math.pi * k / segments)) for k in range(segments)]
    tris = []
    for k in range(segments):
        (xa, ya), (xb, yb) = rim[k], rim[(k + 1) % segments]
        tris.append(((0, 0, 0), (xb, yb, 0), (xa, ya, 0)))                      # bottom, down
        tris.append(((0, 0, thickness), (xa, ya, thickness), (xb, yb, thickness)))
        tris.append(((xa, ya, 0), (xb, yb, 0), (xb, yb, thickness)))
        tris.append(((xa, ya, 0), (xb, yb, thickness), (xa, ya, thickness)))
    with open(path, "w") as f:
        f.write("solid disc\n")
        for a, b, c in tris:
            f.write(" facet normal 0 0 0\n  outer loop\n")
            for v in (a, b, c):
                f.write("   vertex %.9g %.9g %.9g\n" % v)
            f.write("  endloop\n endfacet\n")
        f.write("endsolid disc\n")


def percentile(values, q):
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def plate_curve(data_file, box, diameter, soil, workdir, tag):
    """(sinkage [m], pressure [Pa]) of one plate pressed into a copy of the bed."""
    grains = read_grains(data_file)
    surface = percentile([z + r for _, _, z, r in grains], 0.98)   # grainlink's bed surface
    centre = 0.5 * (box["x0"] + box["x1"])
    radius = 0.5 * diameter
    under = [z + r for x, y, z, r in grains if math.hypot(x - centre, y - centre) < radius + r]
    z0 = max(under) + CLEARANCE
    steps = int(math.ceil((z0 - (surface - REACH)) / (SPEED * soil["dt"])))
    sample = max(1, int(round(SAMPLE_S / soil["dt"])))
    stl = os.path.join(workdir, f"plate_{tag}.stl")
    disc_stl(stl, radius, radius / 5)
    out = os.path.join(workdir, f"force_{tag}.txt")
    run_liggghts("plate.in", dict(soil, data=data_file, stl=stl, cx=centre, z0=z0, speed=SPEED,
                                  steps=steps, sample=sample, out=out,
                                  x0=box["x0"], x1=box["x1"]), workdir)
    curve = []
    with open(out) as f:
        for line in f:
            if line.startswith("#"):
                continue
            step, fz = line.split()[:2]
            t_mid = (int(step) - 0.5 * sample) * soil["dt"]
            sinkage = surface - (z0 - SPEED * t_mid)
            curve.append((sinkage, float(fz) / (math.pi * radius ** 2)))
    return curve


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--out", required=True)
    parser.add_argument("--set", action="append", default=[],
                        help="NAME=VALUE over the base soil: E, e, mu, mur, coh, rho, dt, scale")
    parser.add_argument("--zero-offset", type=float, default=0.0, metavar="M",
                        help="add M metres to every written sinkage")
    parser.add_argument("--compliance", type=float, default=0.0, metavar="M_PER_N",
                        help="add c times the plate's force to every written sinkage")
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--first-seed", type=int, default=0)
    parser.add_argument("--label", default="")
    opts = parser.parse_args()

    soil = dict(BASE)
    for item in opts.set:
        name, value = item.split("=", 1)
        if name not in soil:
            sys.exit(f"--set {item}: unknown name '{name}' (one of {', '.join(soil)})")
        soil[name] = float(value)

    os.makedirs(os.path.join(opts.out, "data"), exist_ok=True)
    workdir = tempfile.mkdtemp(prefix="lig_twin_")
    files = {f"{b}_d{round(d * 1000):03d}": [] for b, d in PLATES}
    for rep in range(opts.seeds):
        seed = PRIMES[(opts.first_seed + rep) % len(PRIMES)]   # LIGGGHTS wants primes > 1e4
        for box_name, box in BOXES.items():
            bed = os.path.join(workdir, f"bed_{box_name}_{rep}.data")
            radii = {f"r{i + 1}": r * soil["scale"] for i, r in enumerate(RADII)}
            run_liggghts("bed.in", dict(soil, **radii, x0=box["x0"], x1=box["x1"],
                                        height=box["height"],
                                        count=round(box["count"] / soil["scale"] ** 3), seed=seed,
                                        settle_steps=int(SETTLE_S / soil["dt"]), out=bed), workdir)
            for plate_box, diameter in PLATES:
                if plate_box != box_name:
                    continue
                exp_id = f"{box_name}_d{round(diameter * 1000):03d}"
                curve = plate_curve(bed, box, diameter, soil, workdir, f"{exp_id}_{rep}")
                name = f"data/{exp_id}_{rep + 1}.csv"
                with open(os.path.join(opts.out, name), "w") as f:
                    f.write(f"# LIGGGHTS 3.8 plate sinkage, bench/liggghts/gap ({opts.label})\n")
                    f.write("sinkage_mm,pressure_kPa\n")
                    area = math.pi * diameter ** 2 / 4
                    for z, p in curve:
                        read = z + opts.zero_offset + opts.compliance * p * area
                        f.write(f"{read * 1000:.4f},{p / 1000:.5f}\n")
                files[exp_id].append(name)
                print(f"{exp_id} seed {rep + 1}: {len(curve)} samples, "
                      f"p({z * 1000:.1f} mm) = {p / 1000:.2f} kPa", flush=True)

    with open(os.path.join(opts.out, "experiments.yaml"), "w") as f:
        f.write(f"# Plate sinkage made with LIGGGHTS (bench/liggghts/gap/make_plate_twin.py)\n")
        f.write(f"name: {os.path.basename(os.path.normpath(opts.out))}\nexperiments:\n")
        for exp_id, names in files.items():
            box_name, diameter = exp_id.split("_d")
            f.write(f"  - id: {exp_id}\n    type: plate_sinkage\n")
            f.write(f"    conditions: {{plate_diameter_m: {int(diameter) / 1000}, box: {box_name}, "
                    f"speed_m_s: {SPEED}}}\n")
            f.write(f"    data:\n      files: [{', '.join(names)}]\n")
            f.write("      x: {column: sinkage_mm, unit: mm}\n")
            f.write("      y:\n        pressure_Pa: {column: pressure_kPa, unit: kPa}\n")
            f.write("    zero: {method: as_recorded}\n")
            f.write("    uncertainty: {y_relative: 0.01, repeats: rebuilt_bed}\n")
    changed = {k: soil[k] for k in soil if soil[k] != BASE[k]}
    for name in ("zero_offset", "compliance"):
        if getattr(opts, name):
            changed[name] = getattr(opts, name)
    key = {"code": "LIGGGHTS 3.8", "label": opts.label, "changed": changed, "soil": soil}
    with open(os.path.normpath(opts.out) + ".key.json", "w") as f:
        json.dump(key, f, indent=2)
    shutil.rmtree(workdir)


if __name__ == "__main__":
    main()
