#!/usr/bin/python3
"""The wheel on the rigid floor (wheel_floor.yaml), through the whole coupled stack:
- resting (drop phase, t in [0.2, 0.5) s): the floor carries the normal load, 3.0 kg x 9.81 m/s^2
  = 29.43 N, within 1 % (the issue's tolerance; measured 29.430 N);
- rolling under the small drive torque (t >= 0.6 s): the mean vertical force is still the normal
  load within 1 % (the 72-facet rim bumps, but the wheel does not climb or sink: measured
  29.40 N), and the wheel rolls without slip: |mean slip| < 0.5 % and every window within 5 %
  (measured mean 0.10 %, the rolling radius is r minus the 0.05 mm penalty depth), while it
  turns (omega > 2 rad/s at the end).
Usage: check_floor.py rig.csv"""
import csv
import sys

rows = list(csv.DictReader(open(sys.argv[1])))


def column(name, start, end=1e9):
    return [float(r[name]) for r in rows if start <= float(r["time_s"]) < end]


failures = []
load = 3.0 * 9.81
for label, start, end in (("resting", 0.2, 0.5), ("rolling", 0.6, 1e9)):
    fz = column("wheel.Fz_N", start, end)
    mean = sum(fz) / len(fz)
    print(f"{label}: mean vertical floor force {mean:.3f} N over {len(fz)} windows "
          f"(normal load {load:.3f} N, tolerance 1 %)")
    if abs(mean - load) > 0.01 * load:
        failures.append(f"{label}: vertical force {mean:.3f} N is not the normal load")
slip = column("slip", 0.6)
mean_slip = sum(slip) / len(slip)
omega = column("omega_rad_s", 0.6)[-1]
print(f"rolling: mean slip {mean_slip:.5f}, largest {max(map(abs, slip)):.5f}, final omega "
      f"{omega:.2f} rad/s")
if abs(mean_slip) > 0.005 or max(map(abs, slip)) > 0.05:
    failures.append("the wheel slips on the floor")
if omega < 2.0:
    failures.append("the wheel is not driven")
for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
