#!/usr/bin/env python3
"""Plots a study's table: every observable against every varied key, mean with standard-error
bars over the replicates; one line per combination of the other varied keys.

    tools/plot_study.py out/my_study          # writes out/my_study/study.png

Reads study.json (the keys and observables) and table.csv (written by `grainlink study`).
"""
import csv
import json
import math
import os
import re
import sys

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def number(text):
    try:
        return float(text)
    except ValueError:
        return math.nan


def short(text):
    """A value as a tick label: a mapping's leaves only, one per line
    ("{tangential: {stick_angle_deg: 5}}" -> "stick_angle_deg: 5"); anything else as it is."""
    if not text.startswith("{"):
        return text
    leaves = re.sub(r"[\w.]+:\s*\{", "", text).replace("{", "").replace("}", "")
    return "\n".join(part.strip() for part in leaves.split(","))


def main(folder):
    with open(os.path.join(folder, "study.json")) as f:
        study = json.load(f)
    observables = study["observables"]
    with open(os.path.join(folder, "table.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    # A key given one value (a setting shared by the whole study) has nothing to plot against,
    # nor has one that moves in step with an earlier key (zipped, one value per value of it).
    keys = []
    for k in study["varied_keys"]:
        if len({r[k] for r in rows}) < 2:
            continue
        if any(len({(r[e], r[k]) for r in rows}) == len({r[e] for r in rows}) ==
               len({r[k] for r in rows}) for e in keys):
            continue
        keys.append(k)
    columns = keys if keys else ["(base)"]
    fig, axes = plt.subplots(len(observables), len(columns), squeeze=False,
                             figsize=(max(7.0, 4.5 * len(columns)), 3.4 * len(observables)))
    for o, name in enumerate(observables):
        for k, key in enumerate(columns):
            ax = axes[o][k]
            # x: a number at its value; text values (lists, mappings) in the design's order.
            values = list(dict.fromkeys(r[key] for r in rows)) if keys else [""]
            numeric = keys and all(not math.isnan(number(v)) for v in values)
            position = {v: (number(v) if numeric else i) for i, v in enumerate(values)}
            others = [c for c in keys if c != key]
            groups = {}
            for r in rows:
                groups.setdefault(tuple(r[c] for c in others), []).append(r)
            if all(len(g) == 1 for g in groups.values()):
                groups = {(): rows}  # the other keys move with this one (zipped): one line
                others = []
            for label, members in groups.items():
                members.sort(key=lambda r: position[r[key]] if keys else 0)
                x = [position[r[key]] if keys else 0 for r in members]
                y = [number(r[name + ":mean"]) for r in members]
                err = [0.0 if math.isnan(number(r[name + ":sem"])) else number(r[name + ":sem"])
                       for r in members]
                text = ", ".join(f"{c}={v}" for c, v in zip(others, label)) or None
                ax.errorbar(x, y, yerr=err, marker="o", capsize=3, label=text)
            if keys and not numeric:
                ax.set_xticks(range(len(values)))
                ax.set_xticklabels([short(v) for v in values], fontsize=7, rotation=20,
                                   ha="right")
            ax.set_xlabel(key)
            ax.set_ylabel(name)
            if len(groups) > 1:
                ax.legend(fontsize=7, loc="best")
    fig.suptitle(f"study '{study['name']}': mean ± standard error over the replicates")
    fig.tight_layout(rect=(0, 0, 1, 0.985))  # room for the title
    out = os.path.join(folder, "study.png")
    fig.savefig(out, dpi=110)
    print(f"plot_study: {len(observables)} observables x {len(keys)} varied key"
          f"{'' if len(keys) == 1 else 's'}, {len(rows)} design points -> {out}")


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: tools/plot_study.py STUDY_FOLDER")
    main(sys.argv[1])
