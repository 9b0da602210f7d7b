#!/usr/bin/python3
"""Compares one column of two coupling.csv files window by window.

    compare_columns.py TESTED.csv REFERENCE.csv COLUMN TOLERANCE [--min-wall-s S]

Both files must have the same windows (window, start_s, end_s columns equal as text), and
|tested - reference| <= TOLERANCE x max |reference| in every row: relative to the column's
amplitude, because a displacement passes through zero. Prints the largest difference found.
--min-wall-s: the tested run's longest window must have taken at least S seconds of wall time.
"""
import argparse
import csv
import sys


def read(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("tested")
    parser.add_argument("reference")
    parser.add_argument("column")
    parser.add_argument("tolerance", type=float)
    parser.add_argument("--min-wall-s", type=float, default=0.0)
    args = parser.parse_args()
    tested, reference = read(args.tested), read(args.reference)
    if not reference:
        sys.exit(f"{args.reference} has no rows")
    if len(tested) != len(reference):
        sys.exit(f"{len(tested)} windows in {args.tested}, {len(reference)} in {args.reference}")
    for t, r in zip(tested, reference):
        if (t["window"], t["start_s"], t["end_s"]) != (r["window"], r["start_s"], r["end_s"]):
            sys.exit(f"window {t['window']} [{t['start_s']}, {t['end_s']}] s against window "
                     f"{r['window']} [{r['start_s']}, {r['end_s']}] s")
    scale = max(abs(float(r[args.column])) for r in reference)
    worst, at = max(((abs(float(t[args.column]) - float(r[args.column])), r["window"])
                     for t, r in zip(tested, reference)), key=lambda pair: pair[0])
    passes = (sum(int(row["iterations"]) for row in tested),
              sum(int(row["iterations"]) for row in reference))
    print(f"{args.column}: {len(tested)} windows, max |difference| {worst:.3g} "
          f"(window {at}) = {worst / scale:.3g} of max |value| {scale:.6g} "
          f"(tolerance {args.tolerance:g}); final {tested[-1][args.column]} against "
          f"{reference[-1][args.column]}; passes {passes[0]} against {passes[1]}")
    if worst > args.tolerance * scale:
        sys.exit(f"{args.column} differs by more than {args.tolerance:g} x {scale:.6g}")
    longest = max(float(row["wall_s"]) for row in tested)
    if longest < args.min_wall_s:
        sys.exit(f"the longest window took {longest:.3g} s of wall time, less than "
                 f"{args.min_wall_s:g} s: the test does not exercise what it should")


if __name__ == "__main__":
    main()
