#!/usr/bin/python3
"""A damaged latest checkpoint costs one checkpoint interval, not the run (tiny.yaml with a
checkpoint every 0.03 s): the finished run's checkpoint.bin gets 64 bytes overwritten in its
middle; `--resume` reports it as damaged (its checksum), resumes from checkpoint.previous.bin and
ends with series.csv row for row as the uninterrupted run's.
Usage: resume_damaged.py GRAINLINK TINY_YAML WORK"""
import os
import shutil
import subprocess
import sys

grainlink, tiny, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
scenario = os.path.join(work, "tiny.yaml")
open(scenario, "w").write(open(tiny).read().replace(
    "output: {series_interval_s: 0.01,", "output: {series_interval_s: 0.01, checkpoint_interval_s: 0.03,"))
out = os.path.join(work, "out")


def run(*extra):
    return subprocess.run([grainlink, "dem", scenario, "--out", out, *extra], cwd=work,
                          capture_output=True, text=True)


failures = []
if run().returncode != 0:
    sys.exit("FAILED: the first run failed")
straight = open(os.path.join(out, "series.csv")).read()
latest = os.path.join(out, "checkpoint.bin")
if not os.path.exists(os.path.join(out, "checkpoint.previous.bin")):
    failures.append("no checkpoint.previous.bin beside checkpoint.bin")
# The previous checkpoint is the latest's second name only until the next one is written over it.
if os.path.samefile(latest, os.path.join(out, "checkpoint.previous.bin")):
    failures.append("checkpoint.previous.bin is the same file as checkpoint.bin")
size = os.path.getsize(latest)
with open(latest, "r+b") as f:
    f.seek(size // 2)
    f.write(b"\x5a" * 64)
resumed = run("--resume")
report = [l for l in resumed.stderr.splitlines() if l.startswith("[resume]")]
print("\n".join(report))
if resumed.returncode != 0:
    failures.append("the resume failed:\n" + resumed.stderr[-2000:])
if not report or "is damaged: its checksum does not match its contents; resuming from the " \
        "previous checkpoint" not in report[0]:
    failures.append("the damaged checkpoint was not reported and passed over")
if open(os.path.join(out, "series.csv")).read() != straight:
    failures.append("series.csv after resuming from the previous checkpoint differs from the "
                    "uninterrupted run's")
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("resumed from the previous checkpoint; series.csv identical to the uninterrupted run's")
