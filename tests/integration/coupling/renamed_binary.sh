#!/bin/sh
# grainlink copied under another name, with no `grainlink` on PATH or beside it, runs a coupled
# scenario whose participants are `grainlink ...`: they are this very executable, not whatever
# `grainlink` PATH would find (another version's nodes). Before, the spawn failed here ("cannot
# start participant").
# Usage: renamed_binary.sh GRAINLINK SCENARIO WORK
set -e
rm -rf "$3" && mkdir -p "$3/bin"
cp "$1" "$3/bin/grainlink-renamed"
PATH=/usr/bin:/bin "$3/bin/grainlink-renamed" run "$2" --out "$3/out" --progress-interval 0
test -s "$3/out/mbs_summary.json"
echo ok
