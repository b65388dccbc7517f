"""`omnislam calibrate level`: the rig's tilt off level from the floor its own images show
(stereo floor contacts, no target): sim-room-37 through a rig turned 0.8 / -0.6 deg off level
(datasets/sim-room-37-level-tilt) read with a config that says level; the level room stays
level; the YAML written is what --config reads; bad input named, nothing written."""
import os
import pathlib
import re
import subprocess

import numpy as np
import yaml
from omnislam_render.pngio import write_png_gray

ROOT = pathlib.Path(__file__).resolve().parents[2]


def omnislam():
    return os.environ.get("OMNISLAM_BIN", str(ROOT / "build" / "modules" / "app" / "omnislam"))


def run(*args):
    return subprocess.run([omnislam(), *map(str, args)], capture_output=True, text=True)


def every_third(name):
    return sorted((ROOT / "datasets" / name / "images").glob("*.png"))[::3]


def level_config(tmp_path, name):
    """The dataset's camera without its level tilt (what a user who assumed level would have)."""
    dataset = yaml.safe_load((ROOT / "datasets" / name / "dataset.yaml").read_text())
    camera = dict(dataset["camera"])
    camera.pop("level_tilt_deg", None)
    camera["camera_height_m"] = dataset.get("camera_height_m", 1.0)
    path = tmp_path / "config.yaml"
    path.write_text(yaml.safe_dump({"camera": camera}))
    return path


def tilt_of(path):
    return yaml.safe_load(path.read_text())["camera"]["level_tilt_deg"]


def test_calibrate_level_finds_a_rig_off_level(tmp_path):
    # Measured (13 images): 0.817 / -0.584 +- 0.017 / 0.011 deg in four passes; all 37
    # images 0.815 / -0.583 +- 0.009 / 0.005 deg (docs/calibration.md).
    out = tmp_path / "level.yaml"
    result = run("calibrate", "level", *every_third("sim-room-37-level-tilt"), "--config",
                 level_config(tmp_path, "sim-room-37-level-tilt"), "--out", out)
    assert result.returncode == 0, result.stderr
    print(result.stdout)
    x, y = tilt_of(out)
    sigma = [float(s) for s in re.search(r"1 sigma ([0-9.]+) / ([0-9.]+) deg", result.stdout).groups()]
    assert abs(x - 0.8) < max(4 * sigma[0], 0.02) and abs(x - 0.8) < 0.05
    assert abs(y + 0.6) < max(4 * sigma[1], 0.02) and abs(y + 0.6) < 0.05
    assert "pass 2:" in result.stdout  # a tilt this large takes more than one pass
    assert "range error this uncertainty implies" in result.stdout
    # What it wrote is a camera key --config reads.
    check = run("scan", every_third("sim-room-37-level-tilt")[0], "--config", out, "--quiet")
    assert check.returncode == 0, check.stderr


def test_calibrate_level_keeps_a_level_rig_level_and_measures_the_height(tmp_path):
    # Measured (13 images): -0.026 / 0.003 +- 0.013 / 0.017 deg.
    out = tmp_path / "level.yaml"
    result = run("calibrate", "level", *every_third("sim-room-37"), "--config", level_config(tmp_path, "sim-room-37"),
                 "--with-height", "--out", out)
    assert result.returncode == 0, result.stderr
    x, y = tilt_of(out)
    assert abs(x) < 0.05 and abs(y) < 0.05
    # --with-height: the floor's depth by stereo, 1.0 m rendered (measured 0.9996 m).
    assert abs(yaml.safe_load(out.read_text())["camera"]["camera_height_m"] - 1.0) < 0.003


def test_calibrate_level_bad_input_is_named_and_nothing_written(tmp_path):
    out = tmp_path / "level.yaml"
    black = tmp_path / "black.png"
    write_png_gray(black, np.zeros((1024, 1024), np.uint8))
    images = every_third("sim-room-37")[:4]
    result = run("calibrate", "level", *images, black, "--out", out)
    assert result.returncode == 0, result.stderr
    assert f"{black}: skipped: no floor contact found" in result.stderr
    out.unlink()
    # Nothing to measure the floor by.
    result = run("calibrate", "level", black, black, black, "--out", out)
    assert result.returncode != 0
    assert "0 floor contact(s) in 0 image(s)" in result.stderr and "nothing written" in result.stderr
    small = tmp_path / "small.png"
    write_png_gray(small, np.zeros((100, 100), np.uint8))
    result = run("calibrate", "level", *images, small, "--out", out)
    assert result.returncode != 0
    assert str(small) in result.stderr
    result = run("calibrate", "level", *images, "--max-tilt-deg", "0", "--out", out)
    assert result.returncode != 0
    assert "--max-tilt-deg must be in (0, 5]" in result.stderr
    assert not out.exists()
