#!/usr/bin/python3
"""Checks that the mean of COLUMN in CSV over rows with time_s >= FROM_S is EXPECTED within
RELATIVE tolerance. Usage: check_mean.py CSV COLUMN FROM_S EXPECTED RELATIVE"""
import csv
import sys

path, column, start, expected, relative = sys.argv[1], sys.argv[2], *map(float, sys.argv[3:6])
with open(path) as f:
    values = [float(r[column]) for r in csv.DictReader(f) if float(r["time_s"]) >= start]
if not values:
    sys.exit(f"{path}: no rows with time_s >= {start}")
mean = sum(values) / len(values)
print(f"{path}: mean {column} over {len(values)} rows from t = {start} s: {mean:.4f} "
      f"(expected {expected} within {relative:.0%})")
sys.exit(0 if abs(mean - expected) <= relative * abs(expected) else 1)
