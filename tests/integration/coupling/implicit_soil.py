#!/usr/bin/python3
"""Implicit coupling with the DEM soil rolled back (wheel_static.yaml, the wheel dropped on a
1,500-grain bed, with `scheme: implicit` and 5 ms windows):
- windows are repeated (more than one pass per window), yet rig.csv and soil.csv hold one row per
  window with strictly increasing times: a rejected try's rows never reach the files;
- the wheel comes to rest carried by the soil: from 0.3 s the mean vertical force is the normal
  load 1.0 kg x 9.81 m/s^2 within 1 % and its window-to-window sd is under 0.5 N (measured 0.16 N;
  explicit coupling at the same 5 ms bounces the wheel, sd 12 N, and at 1 ms leaves 1.8 N).
Usage: implicit_soil.py GRAINLINK STATIC_YAML WORK"""
import csv
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from coupled_runs import arguments, run_variant  # noqa: E402

grainlink, static, work = arguments(3)
text = open(static).read().replace(
    "  scheme: explicit-serial",
    "  scheme: implicit\n  implicit: {relative_tolerance: 1.0e-3, acceleration: iqn-ils, "
    "max_iterations: 30}").replace("macro_step_s: 1.0e-3", "macro_step_s: 5.0e-3")
done, output = run_variant(grainlink, work, "implicit", text)
if done.returncode != 0:
    sys.exit("FAILED: the implicit run failed:\n" + output[-3000:])
failures = []
out = os.path.join(work, "implicit")
coupling = list(csv.DictReader(open(os.path.join(out, "coupling.csv"))))
passes = sum(int(r["iterations"]) for r in coupling) / len(coupling)
print(f"{len(coupling)} windows, {passes:.2f} passes each")
if passes <= 1.0:
    failures.append("no window was repeated: the check would prove nothing")
for name in ("rig.csv", "soil.csv"):
    times = [float(r["time_s"]) for r in csv.DictReader(open(os.path.join(out, name)))]
    if len(times) != len(coupling) or any(b <= a for a, b in zip(times, times[1:])):
        failures.append(f"{name}: {len(times)} rows for {len(coupling)} windows, or times "
                        "not increasing")
fz = [float(r["wheel.Fz_N"]) for r in csv.DictReader(open(os.path.join(out, "rig.csv")))
      if float(r["time_s"]) >= 0.3]
mean = sum(fz) / len(fz)
sd = (sum((f - mean) ** 2 for f in fz) / len(fz)) ** 0.5
print(f"from 0.3 s: mean vertical force {mean:.3f} N (load 9.81 N), sd {sd:.3f} N")
if abs(mean - 9.81) > 0.01 * 9.81 or sd > 0.5:
    failures.append("the wheel does not rest carried by the soil")
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("implicit coupling rolls the soil back: one row per window, the wheel at rest")
