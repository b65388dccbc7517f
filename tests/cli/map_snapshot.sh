#!/usr/bin/env bash
# `omnislam map save|info|load` on a replay of a small dataset: the snapshot holds the run's
# map and last pose, exports them unchanged, and a corrupt snapshot is named.
# Usage: map_snapshot.sh OMNISLAM DATASET WORK_DIR
set -euo pipefail
omnislam=$1 dataset=$2 work=$3
rm -rf "$work"
mkdir -p "$work"
fail() { echo "FAIL: $*" >&2; exit 1; }

"$omnislam" replay "$dataset" --out "$work/run" >/dev/null 2>&1
"$omnislam" map save "$work/run" "$work/state.snap" >"$work/save.txt"
points=$(($(wc -l <"$work/run/map.csv") - 1))
[ "$points" -gt 100 ] || fail "the replay mapped only $points points"
grep -q "saved $points map points and the pose of frame 10" "$work/save.txt" || fail "save: $(cat "$work/save.txt")"

"$omnislam" map info "$work/state.snap" >"$work/info.txt"
last=$(tail -n 1 "$work/run/trajectory.tum")
x=$(echo "$last" | awk '{ printf "%.4f", $2 }')
y=$(echo "$last" | awk '{ printf "%.4f", $3 }')
grep -q "^version: 2$" "$work/info.txt" || fail "info: no version line"
grep -q "^map points: $points " "$work/info.txt" || fail "info: map points differ from map.csv ($points)"
grep -q "^pose: x $x m, y $y m, .* t 0.900 s$" "$work/info.txt" || fail "info: pose is not the last of trajectory.tum ($x, $y)"
grep -Eq "^frames: 10, integrated [0-9]+, not integrated [0-9]+, skipped 0, dropped 0$" "$work/info.txt" ||
  fail "info: counters: $(grep frames "$work/info.txt")"

"$omnislam" map load "$work/state.snap" --out "$work/loaded" >/dev/null
cmp "$work/run/map.csv" "$work/loaded/map.csv" || fail "map.csv exported from the snapshot differs from the run's"
grep -q "^element vertex $points$" "$work/loaded/map.ply" || fail "map.ply does not hold $points points"

# One flipped byte in the middle: named, exit code 1, nothing written.
size=$(stat -c %s "$work/state.snap")
printf '\x55' | dd of="$work/state.snap" bs=1 seek=$((size / 2)) conv=notrunc status=none
set +e
"$omnislam" map load "$work/state.snap" --out "$work/corrupt" 2>"$work/stderr"
status=$?
set -e
[ "$status" -eq 1 ] || fail "exit code $status on a corrupt snapshot, expected 1"
grep -q "error: .*/state.snap: checksum mismatch (the file is corrupt)" "$work/stderr" || fail "$(cat "$work/stderr")"
[ ! -e "$work/corrupt" ] || fail "a corrupt snapshot was exported"
echo ok
