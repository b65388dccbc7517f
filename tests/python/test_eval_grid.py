"""`scripts/eval-grid`: a run's occupancy grid against the rendered room it was made in."""
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "eval-grid"
DATASET = ROOT / "datasets" / "sim-room-10"


def omnislam():
    return os.environ.get("OMNISLAM_BIN", str(ROOT / "build" / "modules" / "app" / "omnislam"))


def eval_grid(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args)], capture_output=True, text=True)


def test_grid_figures_of_a_replay(tmp_path):
    run = tmp_path / "run"
    replay = subprocess.run([omnislam(), "replay", str(DATASET), "--out", str(run)], capture_output=True, text=True)
    assert replay.returncode == 0, replay.stderr
    result = eval_grid(run, DATASET, "--json", tmp_path / "grid.json")
    assert result.returncode == 0, result.stderr
    report = json.loads((tmp_path / "grid.json").read_text())
    print(result.stdout)
    assert report["occupied_cells"] > 100
    assert report["occupied_within_0_1_m_of_plan"] >= 0.9
    assert report["free_m2"] > 5.0
    assert report["path"]["occupied"] == 0 and report["path"]["free"] > 0.9 * report["path"]["cells"]
    # sim-room's cabinets, platform, boxes, column and sphere stand on the floor; the table's
    # top and the board overhang it. Each count adds up.
    for name in ("standing_objects", "overhanging_objects"):
        part = report[name]
        assert part["cells"] > 0
        assert part["occupied"] + part["free"] + part["unknown"] == part["cells"]
    # The floor is seen free only where it was seen: inside what stands on it, hardly any.
    assert report["standing_objects"]["free"] <= 0.2 * report["standing_objects"]["cells"]
    assert "pits" not in report and "cables" not in report
    assert "within 0.25 m of the true path: occupied 0" in result.stdout


def test_a_run_without_a_grid_is_named(tmp_path):
    result = eval_grid(tmp_path, DATASET)
    assert result.returncode == 1
    assert f"{tmp_path / 'map.yaml'}: no such file" in result.stderr
