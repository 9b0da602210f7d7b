#!/bin/bash
# LIGGGHTS side of the grainlink speed benchmark. Prints exactly one line:
#   LIGGGHTS case=CASE procs=P particles=M steps=N seconds=X particle_steps_per_s=Y
# usage: run.sh CASE DATAFILE NPROCS [STEPS] [STL] [CX CZ]
#   CASE     settle | cylinder
#   DATAFILE read_data file of the settled bed (format: README.md)
#   STEPS    timed steps (default 2000; a 200-step warm-up runs before)
#   STL      cylinder mesh (ASCII STL centred at the origin), cylinder only
#   CX CZ    cylinder start centre; default CX=0.15 and CZ such that the
#            cylinder bottom is 3 cm below the bed surface (99th percentile
#            of particle tops in DATAFILE)
# Env: LIGGGHTS (default liggghts), MPIRUN (default mpirun),
#      KEEP_LOG=FILE to keep the full LIGGGHTS screen output.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
[ $# -ge 3 ] || { sed -n '2,13p' "$0" >&2; exit 2; }
case=$1; data=$(realpath "$2"); np=$3; steps=${4:-2000}
[ -f "$here/$case.in" ] || { echo "unknown case '$case'" >&2; exit 2; }

vars=(-var data "$data" -var steps "$steps")
if [ "$case" = cylinder ]; then
    [ $# -ge 5 ] || { echo "cylinder needs STL" >&2; exit 2; }
    cx=${6:-0.15}
    cz=${7:-$(awk '/^Atoms/{a=1;next} /^[A-Z][a-z]/{a=0} a&&NF>=7{print $7+$3/2}' "$data" |
              sort -g | awk '{z[NR]=$1} END{printf "%.4f", z[int(0.99*NR)] - 0.03 + 0.125}')}
    # the mesh must stay inside the box (x <= 0.6) for warm-up + timed steps
    awk -v cx="$cx" -v n="$steps" 'BEGIN{exit !(cx + 0.125 + (n + 200)*5e-5*0.5 < 0.6)}' ||
        { echo "too many steps: cylinder would hit the x wall" >&2; exit 2; }
    echo "cylinder start centre: cx=$cx cz=$cz" >&2
    vars+=(-var stl "$(realpath "$5")" -var cx "$cx" -var cz "$cz")
fi

lmp=${LIGGGHTS:-liggghts}
if [ "$np" -gt 1 ]; then
    mpiflags=(-np "$np" --oversubscribe)
    [ "$(id -u)" = 0 ] && mpiflags+=(--allow-run-as-root)
    cmd=("${MPIRUN:-mpirun}" "${mpiflags[@]}" "$lmp")
else
    cmd=("$lmp")   # serial: no mpirun needed (and no difference in speed)
fi

out=$(mktemp); trap 'rm -f "$out"' EXIT
# common.in is included by relative path, so run from this directory
if ! (cd "$here" && "${cmd[@]}" -in "$case.in" -log none "${vars[@]}") >"$out" 2>&1; then
    tail -20 "$out" >&2; echo "LIGGGHTS failed" >&2; exit 1
fi
[ -n "${KEEP_LOG:-}" ] && cp "$out" "$KEEP_LOG"
# the last "Loop time" line is the timed run (the first one is the warm-up)
grep '^Loop time of' "$out" | tail -1 | awk -v c="$case" '{
    x=$4; p=$6; n=$9; m=$12
    printf "LIGGGHTS case=%s procs=%d particles=%d steps=%d seconds=%.4f particle_steps_per_s=%.0f\n",
           c, p, m, n, x, m*n/x }'
