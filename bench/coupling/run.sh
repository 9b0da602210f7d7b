#!/usr/bin/env bash
# Coupling latency benchmark, one command: wall time of one coupling window with 6 bodies, the
# coordinator and two participant processes, over ipc:// and tcp://127.0.0.1, explicit serial and
# parallel, each beside its bare-ZeroMQ floor (rows marked *). Prints the table (stdout); the
# per-run lines go to stderr. Figures only: nothing asserts. See bench/coupling/README.md.
# usage: bench/coupling/run.sh BUILD_DIR [WINDOWS] [more coupling_bench options]
#   e.g. bench/coupling/run.sh build-bench 20000 --no-csv
#        taskset -c 0 bench/coupling/run.sh build-bench     (every process on one CPU)
set -euo pipefail
build=${1:-build}
windows=${2:-20000}
shift $(($# > 2 ? 2 : $#))
bench="$build/bench/coupling/coupling_bench"
if [ ! -x "$bench" ]; then
    echo "run.sh: $bench is missing; build it with" >&2
    echo "  cmake -S . -B $build -DCMAKE_BUILD_TYPE=Release && cmake --build $build --target coupling_bench" >&2
    exit 1
fi
exec "$bench" --windows "$windows" --warmup 1000 --runs 3 --floor "$@"
