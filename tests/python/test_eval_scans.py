"""`scripts/eval-scans`: the scans' range errors at the true poses, floor contacts and stereo
points apart; and the scan CSV's columns it relies on."""
import csv
import io
import json
import os
import pathlib
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCRIPT = ROOT / "scripts" / "eval-scans"


def omnislam():
    return os.environ.get("OMNISLAM_BIN", str(ROOT / "build" / "modules" / "app" / "omnislam"))


def eval_scans(*args):
    return subprocess.run([sys.executable, str(SCRIPT), *map(str, args), "--omnislam", omnislam()],
                          capture_output=True, text=True)


def test_scan_csv_says_how_each_point_was_ranged():
    image = ROOT / "datasets" / "l-room-1lap" / "images" / "000001.png"
    result = subprocess.run([omnislam(), "scan", str(image), "--quiet"], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    rows = list(csv.DictReader(io.StringIO(result.stdout)))
    assert rows and list(rows[0]) == ["azimuth_deg", "range_m", "x_m", "y_m", "z_m", "inner_row", "outer_row",
                                      "floor_ranged", "range_per_px_m", "elevated"]
    kinds = {row["floor_ranged"] for row in rows}
    assert kinds == {"0", "1"}  # the room's walls give floor contacts, its tables stereo points
    for row in rows:
        if row["floor_ranged"] == "1":
            assert abs(float(row["z_m"])) < 1e-9  # a floor contact lies on the floor
            assert row["elevated"] == "0"
        else:  # the floor boundary's stereo points are the edges it found above the floor
            assert row["elevated"] == "1" and float(row["z_m"]) > 0.04
        assert float(row["range_per_px_m"]) > 0.0


def test_flat_room_scans_are_within_the_issue_lines(tmp_path):
    out = tmp_path / "scans.json"
    result = eval_scans(ROOT / "datasets" / "l-room-1lap", "--every", "10", "--json", out)
    assert result.returncode == 0, result.stderr
    print(result.stdout)
    report = json.loads(out.read_text())
    contacts, stereo = report["floor_contacts"], report["stereo_points"]
    assert contacts["points"] > 300 and stereo["points"] > 100
    # The flat-shaded room (measured: contacts 0.09% median, 99.6% within 0.1 m; stereo 1.0%, 95%).
    assert contacts["median_relative_error"] <= 0.005
    assert contacts["share_within_0_1_m"] >= 0.97
    assert stereo["median_relative_error"] <= 0.02
    assert stereo["share_within_0_1_m"] >= 0.9
    histogram = contacts["histogram_percent"]
    assert sum(histogram["counts"]) == contacts["points"]
    assert len(histogram["counts"]) == len(histogram["edges"]) - 1


def test_degraded_frames_are_scanned(tmp_path):
    out = tmp_path / "scans.json"
    result = eval_scans(ROOT / "datasets" / "office-real", "--degrade", "all", "--every", "100", "--json", out)
    assert result.returncode == 0, result.stderr
    assert "degrade all" in result.stdout
    assert json.loads(out.read_text())["floor_contacts"]["points"] > 50


def test_a_directory_without_a_dataset_is_named(tmp_path):
    result = eval_scans(tmp_path)
    assert result.returncode == 1
    assert str(tmp_path / "dataset.yaml") in result.stderr
