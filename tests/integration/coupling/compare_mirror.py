#!/usr/bin/python3
"""Mirror symmetry (DIGEST §5): the half model (mirror_half.yaml: half the grains, a frictionless
symmetry wall, the half wheel, the wrench completed by its mirror image) gives the full model's
(mirror_full.yaml) wheel forces within statistical scatter. The two beds are different random
packings, so the runs agree only statistically: over the driving phase from t = 0.4 s, the
mean of each quantity may differ by at most 3 standard errors of the difference (each standard
error from the means of 0.1 s blocks, which are near independent at this slip), and the mean
vertical force of each must be the 9.81 N load within 5 %.
Usage: compare_mirror.py FULL/rig.csv HALF/rig.csv"""
import csv
import math
import sys

START, BLOCK = 0.4, 0.1


def blocks(path, column):
    means = {}
    for r in csv.DictReader(open(path)):
        t = float(r["time_s"])
        if t > START:
            means.setdefault(int((t - START) / BLOCK - 1e-9), []).append(float(r[column]))
    values = [sum(v) / len(v) for v in means.values()]
    mean = sum(values) / len(values)
    spread = math.sqrt(sum((v - mean) ** 2 for v in values) / (len(values) - 1))
    return mean, spread / math.sqrt(len(values))


failures = []
for column in ("wheel.Fx_N", "wheel.Fz_N", "wheel.Ty_N_m", "motor_torque_N_m", "z_m", "slip"):
    (full, se_full), (half, se_half) = blocks(sys.argv[1], column), blocks(sys.argv[2], column)
    allowed = 3.0 * math.hypot(se_full, se_half)
    verdict = "ok" if abs(half - full) <= allowed else "DIFFERENT"
    print(f"{column:18s} full {full:9.4f} ± {se_full:.4f}   half {half:9.4f} ± {se_half:.4f}   "
          f"|difference| {abs(half - full):.4f} (allowed {allowed:.4f}) {verdict}")
    if verdict != "ok":
        failures.append(column)
    if column == "wheel.Fz_N":
        for name, value in (("full", full), ("half", half)):
            if abs(value - 9.81) > 0.05 * 9.81:
                failures.append(f"{name} model's vertical force {value:.3f} N is not the load")
for f in failures:
    print("FAILED:", f)
sys.exit(1 if failures else 0)
