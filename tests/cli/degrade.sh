#!/usr/bin/env bash
# `omnislam degrade` on a 2-frame copy of a dataset: the images degraded (PNG), every other
# file copied unchanged, the bytes fixed by the seed; `replay --degrade` gives the same run
# as a replay of the degraded copy; bad input is named.
# Usage: degrade.sh OMNISLAM DATASET WORK_DIR
set -euo pipefail
omnislam=$1 dataset=$2 work=$3
rm -rf "$work"
mkdir -p "$work/data/images"
others="dataset.yaml groundtruth.tum odometry.tum odometry_exact.tum odometry.txt floorplan.csv"
for file in $others; do cp "$dataset/$file" "$work/data/"; done
sed -i 's/^frames: .*/frames: 2/' "$work/data/dataset.yaml"
cp "$dataset/images/000001.png" "$dataset/images/000002.png" "$work/data/images/"

fail() { echo "FAIL: $*" >&2; [ -f "$work/stderr" ] && cat "$work/stderr" >&2; exit 1; }
degrade() { "$omnislam" degrade "$work/data" "$@" >"$work/stdout" 2>"$work/stderr"; }

degrade --out "$work/degraded" || fail "omnislam degrade exited with $?"
grep -q "2 frames degraded (exposure,vignetting,dust,blur,noise,jpeg; seed 1)" "$work/stdout" ||
  fail "unexpected summary: $(cat "$work/stdout")"
for file in $others; do cmp -s "$work/data/$file" "$work/degraded/$file" || fail "$file not copied unchanged"; done
for frame in 000001 000002; do
  image="$work/degraded/images/$frame.png"
  [ "$(head -c 4 "$image" | tail -c 3)" = "PNG" ] || fail "$image is not a PNG"
  ! cmp -s "$image" "$work/data/images/$frame.png" || fail "$image was not degraded"
done
cmp -s "$work/degraded/images/000001.png" "$work/degraded/images/000002.png" && fail "frames 1 and 2 equal"

# The seed fixes the bytes.
degrade --out "$work/again" || fail "second run exited with $?"
cmp -s "$work/degraded/images/000002.png" "$work/again/images/000002.png" || fail "same seed, other bytes"
degrade --out "$work/seed2" --seed 2 --factors noise || fail "--seed 2 --factors noise exited with $?"
grep -q "(noise; seed 2)" "$work/stdout" || fail "unexpected summary: $(cat "$work/stdout")"
cmp -s "$work/degraded/images/000002.png" "$work/seed2/images/000002.png" && fail "other seed, same bytes"

# On the fly equals on disk; --degrade none equals no option.
"$omnislam" replay "$work/data" --out "$work/fly" --degrade all >/dev/null 2>"$work/stderr" || fail "replay --degrade all"
"$omnislam" replay "$work/degraded" --out "$work/disk" >/dev/null 2>"$work/stderr" || fail "replay of the copy"
for file in trajectory.tum map.csv; do
  cmp -s "$work/fly/$file" "$work/disk/$file" || fail "replay --degrade all and the degraded copy differ in $file"
done
grep -q '"factors": "exposure,vignetting,dust,blur,noise,jpeg"' "$work/fly/summary.json" ||
  fail "summary.json does not record the degradation"
"$omnislam" replay "$work/data" --out "$work/plain" >/dev/null 2>"$work/stderr" || fail "replay"
"$omnislam" replay "$work/data" --out "$work/none" --degrade none >/dev/null 2>"$work/stderr" || fail "replay none"
for file in trajectory.tum map.csv; do cmp -s "$work/plain/$file" "$work/none/$file" || fail "--degrade none changed $file"; done
grep -q '"degradation"' "$work/plain/summary.json" && fail "summary.json names a degradation that was not applied"

# Bad input: an unknown factor, a missing dataset, an unreadable image.
degrade --out "$work/bad" --factors noise,smudge && fail "an unknown factor was accepted"
grep -q "unknown degradation factor 'smudge'" "$work/stderr" || fail "the unknown factor is not named"
"$omnislam" degrade "$work/missing" --out "$work/bad" 2>"$work/stderr" && fail "a missing dataset was accepted"
grep -q "$work/missing/dataset.yaml" "$work/stderr" || fail "the missing dataset is not named"
echo "not a png" >"$work/data/images/000002.png"
degrade --out "$work/bad" && fail "an unreadable image was accepted"
grep -q "images/000002.png: not a readable image" "$work/stderr" || fail "the unreadable image is not named"
echo "ok"
