#!/usr/bin/python3
"""The rover on the rigid floor (rover_floor.yaml), averaged over t >= 1 s:
- each wheel's vertical load equals the hand calculation of docs/physics.md §9 (moments about
  the bogie and rocker pivots, ExoMars-class defaults, 300 kg x 3.71 m/s^2): front 182.36 N,
  middle and rear 187.07 N, within 1 % (the facetted wheels bump; measured 182.12, 187.13,
  187.25 N);
- the rover drives at ω r = 0.35 rad/s x 0.1425 m = 0.049875 m/s within 1 % (no slip on the
  floor; measured 0.04982 m/s).
Usage: check_rover_floor.py mbs.csv"""
import csv
import sys

rows = [r for r in csv.DictReader(open(sys.argv[1])) if float(r["time_s"]) >= 1.0]


def mean(column):
    return sum(float(r[column]) for r in rows) / len(rows)


failures = []
expected = {"lf": 182.36, "lm": 187.07, "lr": 187.07, "rf": 182.36, "rm": 187.07, "rr": 187.07}
for wheel, load in expected.items():
    value = mean(f"wheel_{wheel}.Fz_N")
    print(f"wheel_{wheel}: mean vertical load {value:.2f} N (hand calculation {load} N)")
    if abs(value - load) > 0.01 * load:
        failures.append(f"wheel_{wheel} load")
speed = mean("chassis_vx_m_s")
print(f"chassis speed {speed:.5f} m/s (ω r = 0.049875 m/s)")
if abs(speed - 0.049875) > 0.01 * 0.049875:
    failures.append("chassis speed")
for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
