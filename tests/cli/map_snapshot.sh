#!/usr/bin/env bash
# `omnislam map save|info|load|export` on a replay of a small dataset: the snapshot holds the
# run's map, occupancy grid and last pose, exports them unchanged (map.yaml + map.pgm equal to
# the replay's own), and a corrupt, missing, foreign or future-version file is named.
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
grep -q "saved $points map points, the occupancy grid, the keyframe graph and the pose of frame 10" "$work/save.txt" || fail "save: $(cat "$work/save.txt")"

"$omnislam" map info "$work/state.snap" >"$work/info.txt"
last=$(tail -n 1 "$work/run/trajectory.tum")
x=$(echo "$last" | awk '{ printf "%.4f", $2 }')
y=$(echo "$last" | awk '{ printf "%.4f", $3 }')
grep -q "^version: 7$" "$work/info.txt" || fail "info: no version line"
grep -Eq "^odometry distance factor: [0-9.]+ \+- [0-9.]+ \(learnt" "$work/info.txt" ||
  fail "info: no odometry distance factor: $(grep factor "$work/info.txt")"
grep -q "^map points: $points " "$work/info.txt" || fail "info: map points differ from map.csv ($points)"
grep -q "^pose: x $x m, y $y m, .* t 0.900 s$" "$work/info.txt" || fail "info: pose is not the last of trajectory.tum ($x, $y)"
grep -Eq "^frames: 10, integrated [0-9]+, not integrated [0-9]+, skipped 0, dropped 0$" "$work/info.txt" ||
  fail "info: counters: $(grep frames "$work/info.txt")"

width_height=$(sed -n 2p "$work/run/map.pgm")
grep -q "^occupancy grid: ${width_height/ / x } cells at 0.050 m" "$work/info.txt" || fail "info: $(grep grid "$work/info.txt")"
# The replay's map.snapshot gives the snapshot its keyframe graph (one scan per frame here).
grep -Eq "^keyframe graph: [0-9]+ keyframes, [0-9]+ edges \(0 loop\), [0-9]+ integrated scans, path [0-9.]+ m$" "$work/info.txt" ||
  fail "info: no keyframe graph from the replay's map.snapshot: $(grep graph "$work/info.txt")"
grep -Eq "^map uncertainty \(keyframes, 1 sigma, min / median / max\): position [0-9.]+ / [0-9.]+ / [0-9.]+ mm, heading [0-9.]+ / [0-9.]+ / [0-9.]+ deg$" "$work/info.txt" ||
  fail "info: no map uncertainty line: $(grep uncertainty "$work/info.txt")"
cmp <("$omnislam" map info "$work/run/map.snapshot" | grep "^keyframe graph") <(grep "^keyframe graph" "$work/info.txt") ||
  fail "info: the saved keyframe graph is not the replay's"
# A replay without loop closure keeps no graph, and leaves no earlier run's map.snapshot behind.
printf 'slam: {loop_closure: {enabled: false}}\n' >"$work/no-loops.yaml"
"$omnislam" replay "$dataset" --out "$work/rerun" >/dev/null 2>&1
[ -e "$work/rerun/map.snapshot" ] || fail "a replay with loop closure wrote no map.snapshot"
"$omnislam" replay "$dataset" --out "$work/rerun" --config "$work/no-loops.yaml" >/dev/null 2>&1
[ ! -e "$work/rerun/map.snapshot" ] || fail "a replay without loop closure left the earlier run's map.snapshot"
# Without it (an older replay's output) the snapshot holds none.
mkdir -p "$work/old-run"
cp "$work/run/"{trajectory.tum,covariance.csv,summary.json,map.csv,map.yaml,map.pgm} "$work/old-run/"
"$omnislam" map save "$work/old-run" "$work/old.snap" >/dev/null
"$omnislam" map info "$work/old.snap" | grep -q "^keyframe graph: none$" || fail "info: a graph from an output without map.snapshot"

# map export: from the replay's directory and from the snapshot, the replay's own files.
for source in run state.snap; do
  "$omnislam" map export "$work/$source" --out "$work/export-$source" >/dev/null
  for name in map.yaml map.pgm; do
    cmp "$work/run/$name" "$work/export-$source/$name" || fail "export from $source: $name differs from the replay's"
  done
done
# A version-2 snapshot (no grid section) exports its map points as occupied cells, with a note.
python3 - "$work/state.snap" "$work/v2.snap" <<'PY'
import sys, zlib
data = bytearray(open(sys.argv[1], "rb").read())
payload = data[24:]
# Drop the grid section: it starts after the points (count at the end of the fixed part).
fixed = 8 + 8 * 4 + 8 * 9 + 8 * 5 + 8 + 32
count = int.from_bytes(payload[fixed:fixed + 8], "little")
payload = payload[:fixed + 8 + 24 * count]
header = (2).to_bytes(4, "little") + len(payload).to_bytes(8, "little")
crc = zlib.crc32(header + payload)
open(sys.argv[2], "wb").write(b"OMNISNAP" + header + crc.to_bytes(4, "little") + payload)
PY
"$omnislam" map export "$work/v2.snap" --out "$work/export-v2" >/dev/null 2>"$work/v2.txt"
grep -q "note: .*v2.snap (snapshot version 2) holds no occupancy grid: exporting its $points map points as occupied cells at 0.050 m; free space is unknown" "$work/v2.txt" ||
  fail "v2 export: $(cat "$work/v2.txt")"
occupied=$(tail -c +$(($(head -3 "$work/export-v2/map.pgm" | wc -c) + 1)) "$work/export-v2/map.pgm" | tr -cd '\000' | wc -c)
free=$(tail -c +$(($(head -3 "$work/export-v2/map.pgm" | wc -c) + 1)) "$work/export-v2/map.pgm" | tr -cd '\376' | wc -c)
[ "$occupied" -gt 50 ] && [ "$occupied" -le "$points" ] || fail "v2 export: $occupied occupied cells for $points points"
[ "$free" -eq 0 ] || fail "v2 export: $free free cells from a snapshot without free space"

# Bad sources: named, exit code 1, nothing written.
printf 'OMNISNAP' >"$work/future.snap"
python3 - "$work/state.snap" "$work/future.snap" <<'PY'
import sys, zlib
data = bytearray(open(sys.argv[1], "rb").read())
data[8:12] = (9).to_bytes(4, "little")
data[20:24] = zlib.crc32(bytes(data[8:20]) + bytes(data[24:])).to_bytes(4, "little")
open(sys.argv[2], "wb").write(data)
PY
mkdir -p "$work/empty-dir"
check_bad() {  # source, expected message
  set +e
  "$omnislam" map export "$1" --out "$work/bad-export" 2>"$work/stderr"
  local status=$?
  set -e
  [ "$status" -eq 1 ] || fail "export $1: exit code $status, expected 1"
  grep -q "error: $2" "$work/stderr" || fail "export $1: $(cat "$work/stderr")"
  [ ! -e "$work/bad-export" ] || fail "export $1 wrote files"
}
check_bad "$work/absent.snap" ".*/absent.snap: no such file or directory"
check_bad "$work/run/map.pgm" ".*/run/map.pgm: not an omnislam snapshot (bad magic)"
check_bad "$work/future.snap" ".*/future.snap: unsupported snapshot version 9 (this build reads versions 1 to 7)"
check_bad "$work/empty-dir" ".*/empty-dir: no map.yaml (not an omnislam replay or omnislamd output directory)"

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
