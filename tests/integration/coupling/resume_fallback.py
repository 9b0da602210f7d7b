#!/usr/bin/python3
"""A coupled run resumes past a damaged checkpoint (resume_good.yaml: the implicit two-mass
problem, 50 windows, a checkpoint every 10):

0. a run keeps its last three checkpoints (windows 20, 30, 40), the older ones removed;
1. a finished run's latest checkpoint (window 40) has one byte of a participant's state changed:
   `--resume` names the checkpoint and the file, resumes from window 30, and ends with
   coupling.csv (without its wall-time column) row for row the uninterrupted run's;
2. with window 40's soil state deleted, window 30's manifest cut before its end line and window
   20's coordinator.pb cut short, `--resume` fails with one error naming each
   checkpoint and what is wrong with it, and the run's coupling.csv is left as it was.
Usage: resume_fallback.py GRAINLINK CONFIG WORK"""
import os
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from coupled_runs import arguments  # noqa: E402

grainlink, config, work = arguments(3)
failures = []


def run(out, *extra):
    done = subprocess.run([grainlink, "run", config, "--out", out, "--progress-interval", "0",
                           *extra], cwd=work, capture_output=True, text=True)
    return done.returncode, done.stdout + done.stderr


def rows(out):
    """coupling.csv without the wall-time column (the 11th)."""
    with open(os.path.join(work, out, "coupling.csv")) as f:
        return [",".join(c for k, c in enumerate(line.rstrip("\n").split(",")) if k != 10)
                for line in f]


def checkpoint(out, window):
    return os.path.join(work, out, "checkpoints", f"window_{window:09d}")


for out in ("straight", "damaged"):
    code, output = run(out)
    if code != 0:
        sys.exit(f"{out}: the run failed:\n{output[-2000:]}")

kept = sorted(os.listdir(os.path.join(work, "damaged", "checkpoints")))
print("checkpoints kept:", kept)
if kept != ["latest", "window_000000020", "window_000000030", "window_000000040"]:
    failures.append(f"the run kept the checkpoints {kept}, not the last three")

state = os.path.join(checkpoint("damaged", 40), "soil", "soil.state")
with open(state, "r+b") as f:
    f.seek(3)
    byte = f.read(1)
    f.seek(3)
    f.write(bytes([byte[0] ^ 0x20]))
code, output = run("damaged", "--resume")
print("\n".join(line for line in output.splitlines() if "damaged" in line))
if code != 0:
    failures.append(f"the resume past a damaged checkpoint failed:\n{output[-2000:]}")
if not ("window_000000040 is damaged: soil/soil.state does not match its checksum" in output):
    failures.append(f"the warning does not name window 40 and soil/soil.state:\n{output[-2000:]}")
if rows("damaged") != rows("straight"):
    failures.append("coupling.csv after resuming from window 30 differs from the uninterrupted run's")

os.remove(state)
manifest = os.path.join(checkpoint("damaged", 30), "manifest.txt")
with open(manifest) as f:
    lines = f.readlines()
with open(manifest, "w") as f:
    f.writelines(lines[:-1])
for window in (20,):
    with open(os.path.join(checkpoint("damaged", window), "coordinator.pb"), "r+b") as f:
        f.truncate(5)
before = rows("damaged")
code, output = run("damaged", "--resume")
last = output.strip().splitlines()[-1] if output.strip() else ""
print(last)
if code == 0:
    failures.append("a resume with every checkpoint damaged succeeded")
for expected in ("every checkpoint in", "window_000000040: soil/soil.state is missing",
                 "window_000000030: manifest.txt is cut short",
                 "window_000000020: coordinator.pb is missing or unreadable"):
    if expected not in last:
        failures.append(f"the error does not say '{expected}': {last}")
if rows("damaged") != before:
    failures.append("the refused resume changed coupling.csv")

if failures:
    sys.exit("FAILED:\n" + "\n\n".join(failures))
print("resumed past a damaged checkpoint; refused when none is whole, nothing lost")
