#!/usr/bin/env bash
# Bad input to `omnislam replay` on a copy of a small dataset: a clear error naming the
# frame, file or key, and the run either goes on (images: the frame is skipped and counted)
# or stops with the documented exit code (config: 2, odometry: 1).
# Usage: bad_input.sh OMNISLAM DATASET WORK_DIR CASE
set -euo pipefail
omnislam=$1 dataset=$2 work=$3 case=$4
rm -rf "$work"
mkdir -p "$work"
cp -r "$dataset" "$work/data"
images="$work/data/images"

fail() { echo "FAIL ($case): $*" >&2; echo "--- stderr:" >&2; cat "$work/stderr" >&2; exit 1; }
expect_stderr() { grep -Eq -- "$1" "$work/stderr" || fail "stderr does not match: $1"; }
replay() {
  set +e
  "$omnislam" replay "$work/data" --out "$work/out" "$@" 2>"$work/stderr" >"$work/stdout"
  status=$?
  set -e
}
# The run completed: every frame has a pose, and exactly $1 frames were skipped.
expect_completed_with_skipped() {
  [ "$status" -eq 0 ] || fail "exit code $status, expected 0"
  frames=$(grep -vc '^#' "$work/out/trajectory.tum")
  [ "$frames" -eq 10 ] || fail "trajectory.tum has $frames poses, expected 10"
  grep -Eq "\"skipped\": $1," "$work/out/summary.json" || fail "summary.json does not count $1 skipped frame(s)"
}

case $case in
  truncated-image)
    head -c 20000 "$images/000003.png" >"$work/cut" && mv "$work/cut" "$images/000003.png"
    replay
    expect_stderr 'frame 3 skipped: .*/images/000003\.png: not a readable image'
    expect_completed_with_skipped 1 ;;
  missing-image)
    rm "$images/000005.png"
    replay
    expect_stderr 'frame 5 skipped: .*/images/000005\.png: no such image file'
    expect_completed_with_skipped 1 ;;
  garbage-image)
    echo "not a png" >"$images/000007.png"
    replay
    expect_stderr 'frame 7 skipped: .*/images/000007\.png: not a readable image'
    expect_completed_with_skipped 1 ;;
  wrong-size-image)
    # A valid 64x48 grey PNG, built with the standard library only.
    python3 - "$images/000009.png" <<'PY'
import struct, sys, zlib
def chunk(kind, data):
    return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data))
rows = b"".join(b"\x00" + bytes(64) for _ in range(48))
png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 64, 48, 8, 0, 0, 0, 0))
png += chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")
open(sys.argv[1], "wb").write(png)
PY
    replay
    expect_stderr 'frame 9 skipped: .*/images/000009\.png: image is 64x48 px, the camera is configured for 1024x1024'
    expect_completed_with_skipped 1 ;;
  empty-image)
    : >"$images/000002.png"
    replay
    expect_stderr 'frame 2 skipped: .*/images/000002\.png: image file is empty'
    expect_completed_with_skipped 1 ;;
  config-unknown-key)
    printf 'slam:\n  overlap: 0.7\n  max_iteratons: 20\n' >"$work/bad.yaml"
    replay --config "$work/bad.yaml"
    [ "$status" -eq 2 ] || fail "exit code $status, expected 2 (configuration error)"
    expect_stderr "configuration error: .*/bad\.yaml:3:3: unknown key 'slam\.max_iteratons'" ;;
  config-out-of-range)
    printf 'stereo:\n  min_range_m: 2.0\n  max_range_m: 1.0\n' >"$work/bad.yaml"
    replay --config "$work/bad.yaml"
    [ "$status" -eq 2 ] || fail "exit code $status, expected 2 (configuration error)"
    expect_stderr "configuration error: .*/bad\.yaml:3:16: 'stereo\.max_range_m' must exceed min_range_m" ;;
  config-wrong-type)
    printf 'camera:\n  width: wide\n' >"$work/bad.yaml"
    replay --config "$work/bad.yaml"
    [ "$status" -eq 2 ] || fail "exit code $status, expected 2 (configuration error)"
    expect_stderr "configuration error: .*/bad\.yaml:2:10: 'camera\.width' must be an integer" ;;
  odometry-nan)
    awk 'NR == 6 { $2 = "nan" } { print }' "$work/data/odometry.tum" >"$work/odometry.tum"
    replay --odometry "$work/odometry.tum"
    [ "$status" -eq 1 ] || fail "exit code $status, expected 1"
    expect_stderr "error: .*/odometry\.tum:6: 'x' is 'nan', not a finite number" ;;
  odometry-backwards)
    awk 'NR == 7 { $1 = "0.05" } { print }' "$work/data/odometry.tum" >"$work/odometry.tum"
    replay --odometry "$work/odometry.tum"
    [ "$status" -eq 1 ] || fail "exit code $status, expected 1"
    expect_stderr "error: .*/odometry\.tum:7: time goes backwards: t = 0\.05 s after t = " ;;
  odometry-malformed)
    awk 'NR == 4 { $8 = "" } { print }' "$work/data/odometry.tum" >"$work/odometry.tum"
    replay --odometry "$work/odometry.tum"
    [ "$status" -eq 1 ] || fail "exit code $status, expected 1"
    expect_stderr 'error: .*/odometry\.tum:4: expected 8 numbers "t x y z qx qy qz qw", found 7 fields' ;;
  *)
    echo "unknown case $case" >&2
    exit 2 ;;
esac
echo "ok ($case)"
