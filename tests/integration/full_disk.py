#!/usr/bin/python3
"""A full disk, as `ulimit -f` with SIGXFSZ ignored makes it (every write past the limit fails
with EFBIG): a run must stop with one line naming the file and the reason and exit non-zero,
never end "finished" with its series cut short.
1. `grainlink dem` (tiny.yaml, files limited to 4 kB): stops naming series.csv or a snapshot;
2. `grainlink run` (the two-mass problem for 20 s, files limited to 64 kB): stops naming
   coupling.csv.
Usage: full_disk.py GRAINLINK TINY_YAML WORK"""
import os
import resource
import shutil
import signal
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from coupled_runs import two_mass  # noqa: E402

grainlink, tiny, work = map(os.path.abspath, sys.argv[1:4])
shutil.rmtree(work, ignore_errors=True)
os.makedirs(work)
failures = []


def limited(limit_bytes):
    def apply():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit_bytes, limit_bytes))
    return apply


def run(args, limit_bytes):
    done = subprocess.run([grainlink, *args], cwd=work, capture_output=True, text=True,
                          preexec_fn=limited(limit_bytes))
    last = done.stderr.strip().splitlines()[-1] if done.stderr.strip() else ""
    return done.returncode, last


code, last = run(["dem", tiny, "--out", "dem"], 4096)
print(f"dem: exit {code}: {last}")
if code == 0 or "File too large" not in last or "cannot write" not in last:
    failures.append("grainlink dem did not stop on the full disk by name")

coupled = os.path.join(work, "two_mass.yaml")
open(coupled, "w").write(two_mass(20.0, 0.001))
code, last = run(["run", coupled, "--out", "coupled", "--progress-interval", "0"], 65536)
print(f"run: exit {code}: {last}")
if code == 0 or "coupling.csv: File too large" not in last:
    failures.append("grainlink run did not stop on the full disk by name")
if failures:
    sys.exit("FAILED:\n" + "\n".join(failures))
print("both commands stop on a full disk, naming the file and the reason")
