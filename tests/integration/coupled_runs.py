"""Shared by the command-line checks that run variants of a coupled scenario: write the variant
beside the others and run it through `grainlink run`."""
import os
import shutil
import subprocess
import sys


def arguments(count):
    """The script's first `count` arguments as absolute paths; the last, its work folder, is
    emptied."""
    paths = [os.path.abspath(a) for a in sys.argv[1:count + 1]]
    shutil.rmtree(paths[-1], ignore_errors=True)
    os.makedirs(paths[-1])
    return paths


def run_variant(grainlink, work, name, text, *extra, progress="0"):
    """Writes `text` to WORK/NAME.yaml and runs it into WORK/NAME with progress lines every
    `progress` seconds (0: none); returns the finished process and its stdout and stderr
    together."""
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    done = subprocess.run([grainlink, "run", path, "--out", os.path.join(work, name),
                           "--progress-interval", progress, *extra], cwd=work, capture_output=True,
                          text=True)
    return done, done.stdout + done.stderr


def two_mass(end_time_s, macro_step_s, extra=""):
    """The two-mass problem (examples/two_mass) coupled explicitly: the smallest coupled run, for
    checks of the machinery rather than of physics. `extra`: more `coupling:` lines."""
    return f"""coupling:
  scheme: explicit-serial
  end_time_s: {end_time_s}
  macro_step_s: {macro_step_s}
{extra}participants:
  - name: mbs
    role: multibody
    command: [grainlink-two-mass-node, --side, multibody, --name, "{{name}}", --endpoint, "{{endpoint}}"]
  - name: soil
    role: soil
    command: [grainlink-two-mass-node, --side, soil, --name, "{{name}}", --endpoint, "{{endpoint}}"]
"""
