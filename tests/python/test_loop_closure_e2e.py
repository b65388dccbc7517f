"""End-to-end: loop closure on the pose graph (issue 13) over the bundled datasets.

Each dataset is replayed twice, with the default configuration (loop closure on) and with
`slam.loop_closure.enabled: false` (the tracking alone, what main did before the pose
graph), and both runs are evaluated. Asserts the issue's acceptance lines for the
optimised trajectory (trajectory.tum), that it is no worse than the tracking alone, that
the correction reaches the live pose (trajectory_online.tum), and that the thesis preset
keeps loop closure off.
"""
import json
import os
import pathlib
import subprocess

import pytest

from helpers import covariance_consistency

ROOT = pathlib.Path(__file__).resolve().parents[2]


def omnislam():
    return os.environ.get("OMNISLAM_BIN", str(ROOT / "build" / "modules" / "app" / "omnislam"))


def run(*args):
    result = subprocess.run([omnislam(), *map(str, args)], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return result.stdout


def replay(tmp_path, name, label, config=None, extra=()):
    dataset = ROOT / "datasets" / name
    assert (dataset / "dataset.yaml").exists(), f"missing bundled dataset {dataset}"
    out = tmp_path / label
    args = ["replay", dataset, "--out", out, *extra]
    if config is not None:
        args += ["--config", config]
    run(*args)
    print(run("evaluate", out, dataset))
    return json.loads((out / "summary.json").read_text()), json.loads((out / "evaluation.json").read_text())


# Issue 13's acceptance on the optimised trajectory (metres), and "no worse than today" for
# the rooms where the tracking is already at its floor (today: sim-room-37 max 7.3 mm,
# sim-room-turning 6.9 mm; 0.5 mm allowed for rounding).
ACCEPTANCE = {
    "l-room-1lap": {"final_m": 0.060, "max_m": 0.120},
    "l-room-2laps": {"final_m": 0.050},
    "sim-room-37": {"max_m": 0.0078},
    "sim-room-turning": {"max_m": 0.0074},
}


@pytest.mark.parametrize("name", sorted(ACCEPTANCE))
def test_loop_closure_meets_the_issue_and_is_no_worse_than_tracking(tmp_path, name):
    off = tmp_path / "off.yaml"
    off.write_text("slam:\n  loop_closure: {enabled: false}\n")
    summary, evaluation = replay(tmp_path, name, "on")
    summary_off, evaluation_off = replay(tmp_path, name, "off", off)
    ate, ate_off = evaluation["ate"], evaluation_off["ate"]
    want = ACCEPTANCE[name]
    for key, limit in want.items():
        assert ate[key] <= limit, f"{key} {ate[key]} > {limit}"
    # The pose graph never makes a run worse than the tracking it starts from (1 mm slack:
    # the optimum spreads a correction over frames the tracking had right).
    assert ate["max_m"] <= ate_off["max_m"] + 0.001
    assert ate["final_m"] <= ate_off["final_m"] + 0.001
    # Without the graph both trajectories are the tracking's.
    assert evaluation_off["online_ate"] == evaluation_off["ate"]
    assert summary_off["keyframes"] == 0 and summary_off["loop_closures"] == 0
    # The correction reaches the live pose: the online final error within 1.5x of the
    # optimised one (or within 5 mm where both are at the tracking's floor).
    online = evaluation["online_ate"]
    assert online["final_m"] <= max(1.5 * ate["final_m"], ate["final_m"] + 0.005)
    lines = [l for l in (tmp_path / "on" / "trajectory_online.tum").read_text().splitlines()
             if not l.startswith("#")]
    assert len(lines) == summary["frames"]
    assert summary["keyframes"] > 0


def test_two_laps_close_loops_and_the_thesis_preset_does_not(tmp_path):
    summary, _ = replay(tmp_path, "l-room-2laps", "on")
    assert summary["loop_closures"] >= 1
    thesis, _ = replay(tmp_path, "l-room-2laps", "thesis", ROOT / "deploy" / "thesis-2008.yaml")
    assert thesis["keyframes"] == 0 and thesis["loop_closures"] == 0
    assert (tmp_path / "thesis" / "trajectory.tum").read_text() == \
        (tmp_path / "thesis" / "trajectory_online.tum").read_text()


def test_building_two_laps_through_plain_corridors(tmp_path):
    """building-2laps (96 m): along a plain corridor a scan fits anywhere. Without the
    odometry gate a registration that undid a whole step of travel was taken (max 2.1 m);
    with it but without the odometry prior the trimmed fit still pulled each step back by a
    few centimetres (max 376.9 mm); with it the walls' slightly tilted normals still placed
    the robot along the corridor by their millimetres (max 146.4 mm, final 29.5 mm, map
    median 26.7 mm). Measured since the direction the walls do not pin is left to the prior
    (`slam.min_constraining_pairs`) and the map's normals weigh each point by its hits: max
    88.9 mm, final 28.0 mm, online max 103.5 mm, map median 22.3 mm / 67.7% (over the thesis
    model's odometry seeds 1-6 max 83-142 mm, map median 9-26 mm). The issue asks final <= 100
    mm, max <= 250 mm, and the online final within 1.5x of the optimised one."""
    summary, evaluation = replay(tmp_path, "building-2laps", "on")
    ate = evaluation["ate"]
    assert ate["final_m"] <= 0.100
    assert ate["max_m"] <= 0.250
    assert evaluation["online_ate"]["final_m"] <= 1.5 * ate["final_m"] + 0.005
    assert evaluation["map"]["median_distance_m"] <= 0.05
    assert summary["loop_closures"] >= 10
    # Published covariance (issue 13): measured mean NEES 1.08, 100% inside the 95% ellipse
    # (along the corridors the covariance is the odometry's; seeds 2-6 of the thesis model's
    # odometry give 1.5-3.6).
    mean_nees, inside = covariance_consistency(tmp_path / "on", ROOT / "datasets" / "building-2laps")
    assert 1.0 <= mean_nees <= 10.0
    assert inside >= 0.80
