#!/usr/bin/python3
"""The URDF single-wheel rig on the rigid floor (urdf_on_floor.yaml), from t = 0.3 s on:
- it rolls without slip: mean carriage speed = ω r = 3 rad/s x 0.125 m = 0.375 m/s within 0.5 %
  (measured 0.3749 m/s; the rolling radius is r minus the ~0.2 mm penalty depth);
- the floor carries the normal load 8.33 kg x 9.81 m/s^2 = 81.72 N within 1 % on average
  (measured 81.88 N; the 72-facet rim bumps, ±25 N per window).
Usage: check_urdf_floor.py mbs.csv"""
import csv
import sys

rows = [r for r in csv.DictReader(open(sys.argv[1])) if float(r["time_s"]) >= 0.3]


def mean(column):
    return sum(float(r[column]) for r in rows) / len(rows)


speed, load = mean("carriage_x_speed_m_s"), mean("wheel.Fz_N")
print(f"mean carriage speed {speed:.5f} m/s (ω r = 0.375), mean vertical floor force "
      f"{load:.3f} N (load 81.717 N) over {len(rows)} windows")
ok = abs(speed - 0.375) <= 0.005 * 0.375 and abs(load - 81.7173) <= 0.01 * 81.7173
print("ok" if ok else "FAILED")
sys.exit(0 if ok else 1)
