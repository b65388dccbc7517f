"""Wheels that read every distance 5% long (scripts/bias-odometry): sim-room-37's odometry
with each step's translation scaled by 1.05. The SLAM learns the odometry's distance factor
where the scans pin the position (slam.odometry_scale, docs/slam.md "The odometry's distance
factor"): summary.json reports it, within three of its sigmas of 1 / 1.05 (measured 0.9617
+- 0.0096), and applied; the plain dataset's odometry reads true and its factor is not
applied (the run is then exactly as without the option)."""
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
DATASETS = ROOT / "datasets"


def omnislam():
    return os.environ.get("OMNISLAM_BIN", str(ROOT / "build" / "modules" / "app" / "omnislam"))


def replay(dataset, out):
    result = subprocess.run([omnislam(), "replay", str(dataset), "--out", str(out)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return json.loads((out / "summary.json").read_text())


def test_a_long_reading_odometry_is_learnt_and_a_true_one_left_alone(tmp_path):
    dataset = tmp_path / "long"
    made = subprocess.run([sys.executable, str(ROOT / "scripts" / "bias-odometry"), str(DATASETS / "sim-room-37"),
                           str(dataset), "--scale", "1.05"], capture_output=True, text=True)
    assert made.returncode == 0, made.stderr
    assert "odometry x 1.05" in made.stdout
    summary = replay(dataset, tmp_path / "run")
    scale = summary["odometry_scale"]
    print(scale, summary["ate"])
    assert scale["applied"]
    assert abs(scale["factor"] - 1.0 / 1.05) <= 3.0 * scale["sigma"]
    assert 0.0 < scale["sigma"] < 0.02
    assert summary["ate"]["max_m"] < 0.010  # the plain run: 5.1 mm

    plain = replay(DATASETS / "sim-room-37", tmp_path / "plain")
    print(plain["odometry_scale"])
    assert not plain["odometry_scale"]["applied"]


def test_bias_odometry_names_a_bad_scale(tmp_path):
    made = subprocess.run([sys.executable, str(ROOT / "scripts" / "bias-odometry"), str(DATASETS / "sim-room-37"),
                           str(tmp_path / "x"), "--scale", "3"], capture_output=True, text=True)
    assert made.returncode == 1
    assert "--scale 3" in made.stderr
