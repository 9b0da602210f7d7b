"""Shared by the command-line checks that run variants of a coupled scenario: write the variant
beside the others and run it through `grainlink run`."""
import os
import subprocess


def run_variant(grainlink, work, name, text, *extra):
    """Writes `text` to WORK/NAME.yaml and runs it into WORK/NAME; returns the finished process
    and its stdout and stderr together."""
    path = os.path.join(work, name + ".yaml")
    with open(path, "w") as f:
        f.write(text)
    done = subprocess.run([grainlink, "run", path, "--out", os.path.join(work, name),
                           "--progress-interval", "0", *extra], cwd=work, capture_output=True,
                          text=True)
    return done, done.stdout + done.stderr
