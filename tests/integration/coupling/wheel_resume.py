#!/usr/bin/python3
"""A coupled wheel run (wheel_resume.yaml: Simbody rig, DEM soil, coordinator) whose soil process
is killed with SIGKILL after its first checkpoint, then resumed with --resume: the results
written before the crash stay readable, and the resumed run ends bit-identically to an
uninterrupted one (coupling.csv without its wall-time column, rig.csv and soil.csv row for row, and the
ParaView snapshots).
Usage: wheel_resume.py GRAINLINK CONFIG WORK"""
import csv
import os
import shutil
import signal
import subprocess
import sys
import time

grainlink, config, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)


def run(out, *extra):
    return subprocess.run([grainlink, "run", config, "--out", out, "--progress-interval", "0",
                           *extra], cwd=work, capture_output=True, text=True)


def rows(path, drop=()):
    with open(path) as f:
        table = list(csv.reader(f))
    keep = [i for i, name in enumerate(table[0]) if name not in drop]
    return [[r[i] for i in keep] for r in table]


def fail(message):
    sys.exit("FAILED: " + message)


straight = os.path.join(work, "straight")
if run(straight).returncode != 0:
    fail("the uninterrupted run failed")

resumed = os.path.join(work, "resumed")
coordinator = subprocess.Popen([grainlink, "run", config, "--out", resumed, "--progress-interval",
                                "0"], cwd=work, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                               text=True)
latest = os.path.join(resumed, "checkpoints", "latest")
soil = None
while coordinator.poll() is None and soil is None:
    if os.path.exists(latest):  # a complete checkpoint exists: crash the soil process now
        for pid in filter(str.isdigit, os.listdir("/proc")):
            try:
                with open(f"/proc/{pid}/cmdline", "rb") as f:
                    argv = f.read().split(b"\0")
            except OSError:
                continue
            if b"dem-node" in argv and resumed.encode() in b" ".join(argv):
                soil = int(pid)
                os.kill(soil, signal.SIGKILL)
                break
    time.sleep(0.005)
output = coordinator.communicate()[0]
if soil is None:
    fail("the run ended before the soil process could be killed:\n" + output)
if coordinator.returncode == 0:
    fail("the run whose soil process was killed succeeded:\n" + output)
print(output.strip().splitlines()[-1])
if "soil" not in output:
    fail("the failure message does not name the soil participant")
written = rows(os.path.join(resumed, "rig.csv"))
print(f"after the crash: rig.csv readable with {len(written) - 1} rows; checkpoint "
      f"{open(latest).read().strip()}")

again = run(resumed, "--resume")
if again.returncode != 0:
    fail("the resumed run failed:\n" + again.stdout + again.stderr)
for name, drop in (("coupling.csv", ("wall_s",)), ("rig.csv", ()), ("soil.csv", ())):
    a = rows(os.path.join(straight, name), drop)
    b = rows(os.path.join(resumed, name), drop)
    if len(a) != len(b):
        fail(f"{name}: {len(b)} rows after resuming, {len(a)} uninterrupted")
    for ra, rb in zip(a, b):
        if ra != rb:
            fail(f"{name}: resumed row\n{rb}\ndiffers from the uninterrupted\n{ra}")
    print(f"{name}: {len(a) - 1} rows, identical to the uninterrupted run")
# The ParaView snapshots: the same collection, the last snapshot byte for byte.
for name in ("snapshots/particles.pvd", "snapshots/particles_000003.vtu"):
    if open(os.path.join(straight, name), "rb").read() != open(os.path.join(resumed, name),
                                                               "rb").read():
        fail(f"{name} differs after resuming")
print("snapshots: particles.pvd and the last snapshot identical to the uninterrupted run")
