#!/usr/bin/python3
"""One column-naming scheme across a run's CSV files (docs/scenario.md, "Outputs of a run"):
every column is `<quantity>_<unit>` (or a unitless quantity: phase, slip, step, window, body,
contacts, ...), a body's quantity is `<body>.<quantity>_<unit>`, and a wrench is
Fx_N Fy_N Fz_N Tx_N_m Ty_N_m Tz_N_m wherever it appears. Checked on the files runs write:
series.csv of `grainlink dem` (tiny.yaml, body `plate`), and rig.csv, floor.csv and
coupling.csv of a coupled wheel on a rigid floor (wheel_floor.yaml, body `wheel`); the wheel's
wrench has the same column names in rig.csv and coupling.csv.
Usage: columns.py GRAINLINK TINY_YAML WHEEL_FLOOR_YAML WORK"""
import csv
import os
import re
import subprocess
import sys

from coupled_runs import arguments, run_variant

grainlink, tiny, wheel_floor, work = arguments(4)
failures = []

UNITLESS = {"phase", "slip", "step", "window", "body", "contacts", "wall_contacts", "iterations",
            "residual", "max_overlap_ratio", "qw", "qx", "qy", "qz", "touching_vertices"}
QUANTITY = re.compile(r"^[a-zA-Z][a-zA-Z0-9]*(_[a-zA-Z0-9]+)*$")
WRENCH_LIKE = re.compile(r"(^|[._])[fFtT][xyz]_N(_m)?$")
WRENCH = {"Fx_N", "Fy_N", "Fz_N", "Tx_N_m", "Ty_N_m", "Tz_N_m"}


def header(path):
    with open(path) as f:
        return next(csv.reader(f))


def check(path, bodies):
    columns = header(path)
    for column in columns:
        body, dot, quantity = column.rpartition(".")
        if dot and body not in bodies:
            failures.append(f"{path}: column '{column}' names '{body}', which is not a body here")
        if not QUANTITY.match(quantity):
            failures.append(f"{path}: column '{column}' is not <quantity>_<unit>")
        elif "_" not in quantity and quantity not in UNITLESS:
            failures.append(f"{path}: column '{column}' has no unit")
        if WRENCH_LIKE.search(quantity) and quantity not in WRENCH:
            failures.append(f"{path}: '{column}' is a wrench component not named Fx_N ... Tz_N_m")
        if not dot and any(quantity.startswith(b + "_") for b in bodies):
            failures.append(f"{path}: '{column}' joins a body to its quantity with '_', not '.'")
    print(f"{os.path.relpath(path, work)}: {','.join(columns)}")
    return columns


def run(*argv):
    done = subprocess.run([grainlink, *argv], cwd=work, capture_output=True, text=True,
                          env={**os.environ, "OMP_WAIT_POLICY": "PASSIVE"})
    if done.returncode != 0:
        failures.append(f"grainlink {' '.join(argv)} failed:\n{(done.stdout + done.stderr)[-2000:]}")


run("dem", tiny, "--out", "dem", "--progress-interval", "0")
series = check(os.path.join(work, "dem", "series.csv"), {"plate"})
if "plate.Fz_N" not in series:
    failures.append("series.csv has no plate.Fz_N")

# The headers are all that is checked: 0.05 s of the run (cheap under ASan).
text = open(wheel_floor).read()
assert "end_time_s: 1.5" in text
done, output = run_variant(grainlink, work, "wheel", text.replace("end_time_s: 1.5", "end_time_s: 0.05"))
if done.returncode != 0:
    failures.append(f"the wheel run failed:\n{output[-2000:]}")
rig = check(os.path.join(work, "wheel", "rig.csv"), {"wheel"})
check(os.path.join(work, "wheel", "floor.csv"), {"wheel"})
coupling = check(os.path.join(work, "wheel", "coupling.csv"), {"wheel"})
shared = [c for c in rig if c.startswith("wheel.")]
if not shared or any(c not in coupling for c in shared):
    failures.append(f"rig.csv's wheel columns {shared} are not all coupling.csv's")

if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("one naming scheme across series.csv, rig.csv, floor.csv and coupling.csv")
