#!/bin/sh
# Every study file shipped in scenarios/studies passes `grainlink study --dry-run`: each of its
# points is a valid scenario of its kind (the coupled runs' reader included), so a results
# page's command runs as written. The dry run writes nothing.
# Usage: shipped_studies.sh GRAINLINK SCENARIOS_STUDIES OUT
set -eu
grainlink=$1 studies=$2 out=$3
rm -rf "$out"
count=0
for f in "$studies"/*.yaml; do
    grep -q '^base:' "$f" || continue # a base scenario kept beside its studies
    name=$(basename "$f" .yaml)
    line=$("$grainlink" study "$f" --out "$out/$name" --dry-run) || {
        echo "FAILED: $f" >&2
        exit 1
    }
    echo "$line"
    printf '%s\n' "$line" | grep -Eq "points, every scenario valid; 0 done, 0 failed, [0-9]+ to run" || {
        echo "unexpected dry-run line for $f" >&2
        exit 1
    }
    if [ -e "$out/$name" ]; then
        echo "the dry run wrote $out/$name" >&2
        exit 1
    fi
    count=$((count + 1))
done
[ "$count" -ge 20 ] || { echo "only $count studies found in $studies" >&2; exit 1; }
echo "$count studies checked"
