#!/usr/bin/python3
"""The mole on the rigid floor (mole_floor.yaml):
- two strokes happened (stroke_count 2 at the end);
- the coordinator followed the hints: the smallest windows are the mole's 50 µs impact step, the
  largest its 1 ms cocking step (to 1e-12 s);
- the floor's impulse on the hull over the whole run, divided by the run's length, is the mole's
  weight 0.85 kg x 3.71 m/s^2 = 3.1535 N within 1 %: the hammer's internal forces cancel, the
  mole ends near rest (measured 3.1524 N; the impacts throw the mole up to 19 mm high);
- mbs_summary.json (what a study reads) lists the two strokes, each ending where mbs.csv's
  stroke count last has its number, with the penetration there and the floor's impulse over its
  windows, recomputed here from mbs.csv; and every column's mean and sd over the windows of the
  run's second half, recomputed here for the hull's force and the penetration.
Usage: check_mole_floor.py RUN_DIR"""
import csv
import json
import sys

run = sys.argv[1]
rows = list(csv.DictReader(open(f"{run}/mbs.csv")))
impulse, previous = 0.0, 0.0
for r in rows:
    t = float(r["time_s"])
    impulse += float(r["mole.Fz_N"]) * (t - previous)
    previous = t
mean_force = impulse / previous
steps = [float(r["macro_step_s"]) for r in csv.DictReader(open(f"{run}/coupling.csv"))]
strokes = int(float(rows[-1]["stroke_count"]))
print(f"strokes {strokes}, windows from {min(steps):.6g} s to {max(steps):.6g} s, mean floor "
      f"force {mean_force:.4f} N (weight 3.1535 N)")
ok = (strokes == 2 and abs(min(steps) - 5e-5) < 1e-12 and abs(max(steps) - 1e-3) < 1e-12
      and abs(mean_force - 3.1535) <= 0.01 * 3.1535)
summary = json.load(open(f"{run}/mbs_summary.json"))
listed = summary["strokes"]
ok = ok and len(listed) == 2 and summary["stroke_count"] == 2
for k, s in enumerate(listed, start=1):
    index = [i for i, r in enumerate(rows) if int(float(r["stroke_count"])) == k]
    last = rows[index[-1]]
    stroke_impulse = sum(float(rows[i]["mole.Fz_N"]) *
                         (float(rows[i]["time_s"]) - (float(rows[i - 1]["time_s"]) if i else 0.0))
                         for i in index)
    print(f"stroke {k}: summary ends {s['end_time_s']:.6g} s at {1000 * s['penetration_m']:.4f} mm, "
          f"impulse {s['hull_impulse_N_s']:.6g} N s; mbs.csv {float(last['time_s']):.6g} s, "
          f"{1000 * float(last['penetration_m']):.4f} mm, {stroke_impulse:.6g} N s")
    ok = (ok and s["stroke"] == k and abs(s["end_time_s"] - float(last["time_s"])) < 1e-12
          and abs(s["penetration_m"] - float(last["penetration_m"])) < 1e-12
          and abs(s["hull_impulse_N_s"] - stroke_impulse) <= 1e-9 * max(1.0, abs(stroke_impulse)))
# The end penetration is the model's own (full precision); mbs.csv has six digits.
ok = ok and abs(summary["penetration_m"] - float(rows[-1]["penetration_m"])) < 1e-8
ok = ok and all(s["complete"] for s in listed)  # the run ends 0.1 s after its last release
half_from = float(rows[-1]["time_s"]) / 2
for column in ("mole.Fz_N", "penetration_m"):
    values = [float(r[column]) for r in rows if float(r["time_s"]) >= half_from]
    mean = sum(values) / len(values)
    sd = (sum((v - mean) ** 2 for v in values) / (len(values) - 1)) ** 0.5
    got = summary["second_half"]
    for part in column.split("."):  # a body's column is nested: second_half.mole.Fz_N
        got = got[part]
    print(f"second half of {column}: mean {got['mean']:.6g} sd {got['sd']:.6g}; "
          f"recomputed {mean:.6g} {sd:.6g} over {len(values)} windows")
    ok = (ok and abs(got["mean"] - mean) <= 1e-9 * max(1.0, abs(mean))
          and abs(got["sd"] - sd) <= 1e-9 * max(1.0, sd))
print("ok" if ok else "FAILED")
sys.exit(0 if ok else 1)
