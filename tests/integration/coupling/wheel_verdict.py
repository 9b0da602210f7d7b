#!/usr/bin/python3
"""The wheel test's verdict through the whole coupled stack (rig, rigid floor, coordinator), on
variants of wheel_floor.yaml, whose torque-driven wheel rolls without slip:

1. steady: judged over two spans of 0.2 s after 0.6 s of driving, the run ends early with exit
   status 0 and rig_summary.json says steady, slip 0 within 0.005 (pure rolling), the vertical
   force the normal load 3 kg x 9.81 m/s^2 within 1 %, each with its sd and standard error;
2. not steady: drive_min_s 5 s beyond the run's 1.5 s end and no `run_until: end_time`: the run
   exits non-zero, says which phase and for how long, and rig_summary.json says not steady.
Usage: wheel_verdict.py GRAINLINK FLOOR_YAML WORK"""
import json
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from coupled_runs import arguments, run_variant  # noqa: E402

grainlink, config, work = arguments(3)
base = open(config).read()
failures = []


def run(name, settings):
    text = base.replace("  run_until: end_time", "").replace("  drive_min_s: 5.0", settings)
    done, _ = run_variant(grainlink, work, name, text)
    summary = json.load(open(os.path.join(work, name, "rig_summary.json")))
    print(f"{name}: exit status {done.returncode}; {summary['message']}")
    return done, summary


done, s = run("steady", "  drive_min_s: 0.6\n  steady_window_s: 0.2")
load = 3.0 * 9.81
if done.returncode != 0:
    failures.append("the steady run failed:\n" + done.stderr[-2000:])
if not s["steady"] or s["phase"] != "steady":
    failures.append("the steady run is not reported steady")
elif not s["run_end_s"] < 1.4:
    failures.append(f"the steady run did not end at its steady state (t = {s['run_end_s']} s)")
else:
    if abs(s["slip"]["mean"]) > 0.005:
        failures.append(f"steady slip {s['slip']['mean']} is not pure rolling's 0")
    if abs(s["vertical_force_N"]["mean"] - load) > 0.01 * load:
        failures.append(f"steady vertical force {s['vertical_force_N']['mean']} N is not {load}")
    for key in ("slip", "motor_torque_N_m", "drawbar_pull_N", "vertical_force_N", "wheel_z_m"):
        if set(s[key]) != {"mean", "sd", "standard_error"}:
            failures.append(f"{key}: {s[key]}")

done, s = run("unsteady", "  drive_min_s: 5.0")
expected = ("wheel test: no steady state: the run ended at t = 1.5 s (coupling.end_time_s) "
            "after 1 s of the drive phase")
if done.returncode == 0:
    failures.append("a run that ended without a steady state exited with status 0")
if expected not in done.stdout + done.stderr:
    failures.append("the unsteady run did not say where it stopped:\n" + done.stderr[-2000:])
if s["steady"] or s["phase"] != "drive" or not s["message"].startswith(expected):
    failures.append(f"rig_summary.json of the unsteady run: {s}")
if "run: participant rig exited with status 3" not in done.stderr:
    failures.append("the run did not name the failed participant:\n" + done.stderr[-2000:])

if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("the wheel test's verdict reaches the exit status and rig_summary.json")
