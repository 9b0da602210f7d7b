#!/usr/bin/python3
"""rig.clearance_above_bed_m through the whole stack: the multibody node sets the wheel's start
height from the bed, and the soil, measuring with its own mesh and its own settled surface,
finds the wheel's lowest point that far above it.

1. DEM soil (wheel_static.yaml with start z 0.5 m and clearance 10 mm): the soil node reports
   the lowest point 10.00 mm above the bed surface;
2. the same with clearance 0.1 mm: the wheel cuts the grains standing above the surface, and
   the run is refused before its first step, naming a grain and how much higher to start;
3. rigid floor (wheel_floor.yaml, floor at z = 0, with clearance 5 mm): the 150 mm wheel's
   centre starts at 0.075 + 0.005 = 0.0800 m, the start wheel_floor.yaml gives by hand.
Usage: clearance.py GRAINLINK STATIC_YAML FLOOR_YAML WORK"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from coupled_runs import arguments, run_variant  # noqa: E402

grainlink, static, floor, work = arguments(4)
failures = []


def run(name, text):
    done, output = run_variant(grainlink, work, name, text)
    if done.returncode != 0:
        failures.append(f"{name}: the run failed:\n{output[-2000:]}")
    return output


text = open(static).read()
text = text.replace("start_position_m: [0.1, 0.04, 0.095]",
                    "start_position_m: [0.1, 0.04, 0.5]\n  clearance_above_bed_m: 0.01")
text = text.replace("end_time_s: 1.5 ", "end_time_s: 0.01")
output = run("dem", text)
print("\n".join(line for line in output.splitlines() if "lowest point" in line))
if "lowest point 10.00 mm above the bed surface" not in output:
    failures.append("the soil does not find the wheel 10 mm above the bed:\n" + output[-2000:])

# A wheel whose lowest point is just above the bed surface (its 98th percentile) cuts the grains
# that stand above it: refused before the first step, naming a grain and the height to add.
text = open(static).read()
text = text.replace("start_position_m: [0.1, 0.04, 0.095]",
                    "start_position_m: [0.1, 0.04, 0.5]\n  clearance_above_bed_m: 0.0001")
text = text.replace("end_time_s: 1.5 ", "end_time_s: 0.01")
done, output = run_variant(grainlink, work, "cutting", text)
refusal = [line for line in output.splitlines() if "starts cutting" in line]
print(refusal[-1] if refusal else "(no refusal)")
if done.returncode == 0 or not refusal or "mm higher" not in refusal[-1]:
    failures.append("a wheel cutting the grains above the surface was not refused:\n" + output[-2000:])

text = open(floor).read()
text = text.replace("start_position_m: [0.0, 0.0, 0.080]",
                    "start_position_m: [0.0, 0.0, 0.3]\n  clearance_above_bed_m: 0.005")
text = text.replace("end_time_s: 1.5", "end_time_s: 0.01")
output = run("floor", text)
print("\n".join(line for line in output.splitlines() if line.startswith("rig: bed")))
if "wheel centre starts at z = 0.0800 m" not in output:
    failures.append("the wheel does not start 5 mm above the floor:\n" + output[-2000:])

if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("the rig starts at its clearance above the bed and the floor")
