#!/usr/bin/python3
"""`grainlink run --progress-interval` reaches every node it starts (wheel_floor.yaml: the
Simbody rig and the rigid floor):

1. every 0.2 s of wall time each node prints its own line, named by the participant, with the
   simulated time rising to the run's end and an ETA; the rig's line names its phase and slip;
2. a node's own --progress-interval in the scenario's command overrides the run's (the floor's
   0: no line from it, the rig's go on);
3. --progress-interval 0 silences the coordinator and every node;
4. an inherited GRAINLINK_PROGRESS_INTERVAL that is not seconds >= 0 stops a node at once,
   naming the variable and the value.
Usage: progress.py GRAINLINK FLOOR_YAML WORK"""
import os
import re
import subprocess
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from coupled_runs import arguments, run_variant  # noqa: E402

grainlink, floor, work = arguments(3)
failures = []
LINE = re.compile(r"^\[(\w+)\] t = ([0-9.]+) s \(\s*([0-9.]+) %\)  wall \S+  ETA \S+(.*)$")


def progress_lines(name, text, interval):
    done, output = run_variant(grainlink, work, name, text, progress=interval)
    if done.returncode != 0:
        failures.append(f"{name}: the run failed:\n{output[-2000:]}")
    lines = {}
    for line in output.splitlines():
        m = LINE.match(line)
        if m:
            lines.setdefault(m.group(1), []).append((float(m.group(2)), m.group(4)))
    coordinator = [line for line in output.splitlines() if line.startswith("coupling: t = ")]
    return lines, coordinator, output


# 0.6 s of the 1.5 s run: the drop and the start of the drive are enough (and cheap under ASan).
text = open(floor).read()
assert "end_time_s: 1.5" in text
text = text.replace("end_time_s: 1.5", "end_time_s: 0.6")
lines, coordinator, output = progress_lines("every", text, "0.2")
for node in ("rig", "floor"):
    times = [t for t, _ in lines.get(node, [])]
    print(f"{node}: {len(times)} progress lines, t = {times}")
    if len(times) < 2 or times != sorted(times) or times[-1] > 0.6:
        failures.append(f"{node}: expected two or more lines with t rising within the 0.6 s "
                        f"run, got {times}:\n{output[-2000:]}")
if not all(re.search(r"phase (drop|drive)  slip -?[0-9.]+$", note) for _, note in lines.get("rig", [])):
    failures.append(f"the rig's lines do not name its phase and slip: {lines.get('rig')}")
if not coordinator:
    failures.append("the coordinator printed no progress line")

quiet_floor = text.replace("--out, \"{out}\", --bodies, wheel]",
                           "--out, \"{out}\", --bodies, wheel, --progress-interval, \"0\"]")
assert quiet_floor != text
lines, _, output = progress_lines("node-overrides", quiet_floor, "0.2")
print(f"floor's own 0: floor {len(lines.get('floor', []))} lines, rig {len(lines.get('rig', []))}")
if lines.get("floor") or not lines.get("rig"):
    failures.append(f"the floor's own --progress-interval 0 did not silence only it:\n{output[-2000:]}")

lines, coordinator, output = progress_lines("none", text, "0")
print(f"--progress-interval 0: {sum(map(len, lines.values()))} node lines, "
      f"{len(coordinator)} coordinator lines")
if lines or coordinator:
    failures.append(f"--progress-interval 0 still printed progress:\n{output[-2000:]}")

for bad in ("abc", "-1", "nan"):
    done = subprocess.run([grainlink, "floor-node", floor, "--name", "floor", "--endpoint",
                           "tcp://127.0.0.1:1", "--out", work, "--bodies", "wheel"],
                          env={**os.environ, "GRAINLINK_PROGRESS_INTERVAL": bad},
                          capture_output=True, text=True, timeout=30)
    expected = f"floor: error: GRAINLINK_PROGRESS_INTERVAL = '{bad}' is not a number of seconds >= 0"
    if done.returncode == 0 or expected not in done.stderr:
        failures.append(f"GRAINLINK_PROGRESS_INTERVAL={bad}: exit {done.returncode}, {done.stderr[-500:]}")
print("a bad GRAINLINK_PROGRESS_INTERVAL stops the node naming it")

if failures:
    sys.exit("FAILED:\n" + "\n\n".join(failures))
print("every node follows the run's --progress-interval")
