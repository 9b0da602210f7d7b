#!/usr/bin/python3
"""Resuming with a changed scenario is refused, naming what changed (a checkpoint records what it
depends on):
1. `grainlink dem` (tiny.yaml): a run that wrote its checkpoint, resumed with the time step
   halved and a second body added, stops with both changes named and leaves its files as they
   were;
2. `grainlink run` (the two-mass problem, checkpoints every 10 windows): resumed with another
   macro step, it stops naming coupling.macro_step_s with the old and the new value.
Usage: resume_changed.py GRAINLINK TINY_YAML WORK"""
import os
import shutil
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from coupled_runs import two_mass  # noqa: E402

grainlink, tiny, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def run(*args):
    return subprocess.run([grainlink, *args], cwd=work, capture_output=True, text=True)


def write(name, text):
    path = os.path.join(work, name)
    open(path, "w").write(text)
    return path


base = open(tiny).read()
first = run("dem", write("tiny.yaml", base), "--out", "dem")
if first.returncode != 0:
    failures.append("the first run failed:\n" + first.stderr[-2000:])
series = open(os.path.join(work, "dem", "series.csv")).read()
changed = base.replace("time_step_s: 1.0e-4", "time_step_s: 5.0e-5").replace(
    "run: {duration_s: 0.1}",
    "  - name: probe\n    mesh: {type: cylinder, radius_m: 0.01, width_m: 0.005}\n"
    "    position_m: [0.03, 0.03, 0.15]\nrun: {duration_s: 0.1}")
resumed = run("dem", write("changed.yaml", changed), "--out", "dem", "--resume")
message = resumed.stderr.strip().splitlines()[-1] if resumed.stderr.strip() else ""
print("dem:", message)
expected = ["the scenario changed since it was written", "simulation.time_step_s was 0.0001, "
            "is 5e-05", "bodies (count) was 1, is 2", "bodies.probe (triangles) is new"]
if resumed.returncode == 0 or not all(e in message for e in expected):
    failures.append("the changed DEM scenario was not refused by name:\n" + resumed.stderr[-2000:])
if open(os.path.join(work, "dem", "series.csv")).read() != series:
    failures.append("the refused resume changed series.csv")

coupled = two_mass(0.3, 0.01, "  checkpoint_every_windows: 10\n")
if run("run", write("two_mass.yaml", coupled), "--out", "coupled",
       "--progress-interval", "0").returncode != 0:
    failures.append("the two-mass run failed")
shorter = coupled.replace("macro_step_s: 0.01", "macro_step_s: 0.005")
resumed = run("run", write("two_mass_changed.yaml", shorter), "--out", "coupled", "--resume",
              "--progress-interval", "0")
output = resumed.stdout + resumed.stderr
line = next((l for l in output.splitlines() if "cannot resume" in l), "")
print("run:", line)
if resumed.returncode == 0 or "coupling.macro_step_s was 0.01 s when it was written, is 0.005 s" \
        not in line:
    failures.append("the changed macro step was not refused by name:\n" + output[-2000:])

if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("a changed scenario is refused on resume, by name")
