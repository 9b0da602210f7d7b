#!/usr/bin/python3
"""A coupled wheel run (wheel_resume.yaml: Simbody rig, DEM soil, coordinator) crashed twice and
resumed, ending bit-identically to an uninterrupted one:

1. its soil process is killed with SIGKILL once the checkpoint at window 200 (or a later one, on a
   slow machine) is complete — the wheel test drives from about 0.15 s, so the rig's procedure
   is resumed in its drive phase; a row cut by the crash is left at the end of rig.csv (`0.2`,
   what a crash in the middle of writing the row at 0.201 s leaves: a time up to the checkpoint);
2. it is resumed with --resume and its soil process killed again as soon as it has cut its
   soil.csv back to the checkpoint, before the next checkpoint: the kept rows must be on disk;
3. it is resumed again to the end.

The results written before each crash stay readable; the run ends as an uninterrupted one does:
coupling.csv (without its wall-time column), rig.csv (phase included) and soil.csv row for row
and column for column, rig_summary.txt, and the ParaView snapshots. The rig reports the sinkage
steady once, not again after the resume. The soil's series holds each window's push on the
bin's two end walls, positive (the settled grains lean on both).
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
CRASH_CHECKPOINT = "window_000000200"


def command(out, *extra):
    return [grainlink, "run", config, "--out", out, "--progress-interval", "0", *extra]


def run(out, *extra):
    return subprocess.run(command(out, *extra), cwd=work, capture_output=True, text=True)


def rows(path, drop=()):
    with open(path) as f:
        table = list(csv.reader(f))
    keep = [i for i, name in enumerate(table[0]) if name not in drop]
    return [[r[i] for i in keep if i < len(r)] for r in table]  # a cut row stays short


def fail(message):
    sys.exit("FAILED: " + message)


def latest_checkpoint(out):
    try:
        with open(os.path.join(out, "checkpoints", "latest")) as f:
            return f.read().strip()
    except OSError:
        return None


def kill_soil(out):
    """SIGKILLs this run's soil process (found by its command line); its pid, or None."""
    for pid in filter(str.isdigit, os.listdir("/proc")):
        try:
            with open(f"/proc/{pid}/cmdline", "rb") as f:
                argv = f.read().split(b"\0")
        except OSError:
            continue
        if b"dem-node" in argv and out.encode() in b" ".join(argv):
            os.kill(int(pid), signal.SIGKILL)
            return int(pid)
    return None


def crash(out, when, *extra):
    """Runs the scenario, SIGKILLs its soil process once when() holds; the run's output."""
    coordinator = subprocess.Popen(command(out, *extra), cwd=work, stdout=subprocess.PIPE,
                                   stderr=subprocess.STDOUT, text=True)
    soil = None
    while coordinator.poll() is None and soil is None:
        if when():
            soil = kill_soil(out)
        time.sleep(0.005)
    output = coordinator.communicate()[0]
    if soil is None:
        fail("the run ended before the soil process could be killed:\n" + output)
    if coordinator.returncode == 0:
        fail("the run whose soil process was killed succeeded:\n" + output)
    if "soil" not in output:
        fail("the failure message does not name the soil participant:\n" + output)
    print(output.strip().splitlines()[-1])
    return output


straight = os.path.join(work, "straight")
first = run(straight)
if first.returncode != 0:
    fail("the uninterrupted run failed:\n" + first.stdout + first.stderr)
if "sinkage steady" not in first.stdout + first.stderr:
    fail("the uninterrupted run does not report the sinkage steady:\n" + first.stderr)
# The soil's push on the bin's end walls, each window (grainlink run judges a steady state by it).
soil_table = rows(os.path.join(straight, "soil.csv"))
walls = [soil_table[0].index(c) for c in ("end_wall_ahead_N", "end_wall_behind_N")
         if c in soil_table[0]]
if len(walls) != 2:
    fail(f"soil.csv has no end wall columns: {soil_table[0]}")
# The grains lean on both end walls of the settled bed (a few newtons on this 80 x 120 mm bed).
for i in walls:
    pushes = [float(r[i]) for r in soil_table[1:]]
    if not all(0.0 < p < 100.0 for p in pushes):
        fail(f"{soil_table[0][i]} out of (0, 100) N: {min(pushes)} .. {max(pushes)}")
phases = {r[0]: r[1] for r in rows(os.path.join(straight, "rig.csv"))[1:]}
if phases.get("0.2") != "drive":
    fail(f"the wheel does not drive at the crash (phase {phases.get('0.2')} at 0.2 s)")

resumed = os.path.join(work, "resumed")
crash(resumed, lambda: (latest_checkpoint(resumed) or "") >= CRASH_CHECKPOINT)
checkpoint = latest_checkpoint(resumed)
for name in ("rig.csv", "soil.csv"):
    written = rows(os.path.join(resumed, name))
    print(f"after the crash: {name} readable with {len(written) - 1} rows; checkpoint "
          f"{checkpoint}")
with open(os.path.join(resumed, "rig.csv"), "a") as f:
    f.write(f"{int(checkpoint[len('window_'):]) * 1e-3:g}")  # a row cut by the crash

# Killed again as soon as the resumed soil process has cut soil.csv back to the checkpoint.
soil_csv = os.path.join(resumed, "soil.csv")
before = os.stat(soil_csv)


def rewritten():
    now = os.stat(soil_csv)
    return (now.st_ino, now.st_size, now.st_mtime_ns) != (before.st_ino, before.st_size,
                                                          before.st_mtime_ns)


crash(resumed, rewritten, "--resume")
if latest_checkpoint(resumed) != checkpoint:
    fail(f"the second crash came after the next checkpoint ({latest_checkpoint(resumed)})")
kept = rows(soil_csv)
print(f"after the crash right after resuming: soil.csv readable with {len(kept) - 1} rows")

again = run(resumed, "--resume")
if again.returncode != 0:
    fail("the resumed run failed:\n" + again.stdout + again.stderr)
for name, drop in (("coupling.csv", ("wall_s",)), ("rig.csv", ()), ("soil.csv", ())):
    a = rows(os.path.join(straight, name), drop)
    b = rows(os.path.join(resumed, name), drop)
    for ra, rb in zip(a, b):
        if ra != rb:
            fail(f"{name}: resumed row\n{rb}\ndiffers from the uninterrupted\n{ra}")
    if len(a) != len(b):
        fail(f"{name}: {len(b)} rows after resuming, {len(a)} uninterrupted")
    print(f"{name}: {len(a) - 1} rows, identical to the uninterrupted run")
summary = open(os.path.join(straight, "rig_summary.txt")).read()
if open(os.path.join(resumed, "rig_summary.txt")).read() != summary:
    fail("rig_summary.txt differs after resuming")
output = again.stdout + again.stderr
if "sinkage steady" in output:
    fail("the resumed run reported the sinkage steady again:\n" + output)
# The ParaView snapshots: the same collection, the last snapshot byte for byte.
for name in ("snapshots/particles.pvd", "snapshots/particles_000003.vtu"):
    if open(os.path.join(straight, name), "rb").read() != open(os.path.join(resumed, name),
                                                               "rb").read():
        fail(f"{name} differs after resuming")
print("rig_summary.txt and the snapshots (particles.pvd, the last .vtu) identical to the "
      "uninterrupted run")
