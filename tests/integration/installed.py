#!/usr/bin/python3
"""`make install` (cmake --install) into a fresh prefix, then the installed grainlink run from
an unrelated folder: it finds the soil table it ships beside itself (<prefix>/share/grainlink)
and inverts it (`grainlink params --friction-angle 30`), and a coupled run finds its participant
programs beside itself (the two-mass problem).
Usage: installed.py BUILD_DIR WORK"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from coupled_runs import two_mass  # noqa: E402

build, work = map(os.path.abspath, sys.argv[1:3])
shutil.rmtree(work, ignore_errors=True)
prefix, elsewhere = os.path.join(work, "prefix"), os.path.join(work, "elsewhere")
os.makedirs(elsewhere)
done = subprocess.run(["cmake", "--install", build, "--prefix", prefix], capture_output=True,
                      text=True)
if done.returncode != 0:
    sys.exit("FAILED: cmake --install:\n" + done.stderr[-2000:])
grainlink = os.path.join(prefix, "bin", "grainlink")
env = {k: v for k, v in os.environ.items() if k != "GRAINLINK_SHARE"}
failures = []
params = subprocess.run([grainlink, "params", "--friction-angle", "30", "--out", "p.yaml"],
                        cwd=elsewhere, capture_output=True, text=True, env=env)
table = os.path.join(prefix, "share", "grainlink", "data", "soil_table.csv")
print(params.stdout.splitlines()[0] if params.stdout else params.stderr[-500:])
if params.returncode != 0 or f"Soil table {table}:" not in params.stdout:
    failures.append("the installed params did not use the shipped soil table:\n" + params.stderr)
open(os.path.join(elsewhere, "two_mass.yaml"), "w").write(two_mass(0.1, 0.01))
run = subprocess.run([grainlink, "run", "two_mass.yaml", "--out", "out", "--progress-interval",
                      "0"], cwd=elsewhere, capture_output=True, text=True, env=env)
if run.returncode != 0:
    failures.append("the installed run failed:\n" + run.stderr[-2000:])
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("the installed grainlink runs from any folder")
