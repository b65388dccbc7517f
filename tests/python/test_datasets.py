"""Tests of scripts/render-dataset: metadata, odometry, floor plan, rendering.

Run from the repository root:  python3 -m pytest tests/python -q
"""
from __future__ import annotations

import math
import re
import subprocess
import sys

import numpy as np
import pytest
import yaml

from conftest import DATASET_NAMES, REPO, SCRIPTS
from helpers import angle_diff, floor_wall_edge_errors, poses, steps, table_mm, times

from omnislam_render import convention, datasets, geocheck, mirror, odometry, rooms
from omnislam_render.pngio import read_png, to_gray, write_png_gray

RENDER = [sys.executable, str(SCRIPTS / "render-dataset")]

# World (room-frame) pose lists the datasets are built from, per the brief.
EXPECTED_POINTS = {
    "sim-room-10": table_mm("3.1"),
    "sim-room-37": table_mm("3.2"),
    "sim-room-turning": table_mm("3.2"),
    "l-room-1lap": table_mm("3.3") + table_mm("3.3")[:1],
    "l-room-2laps": table_mm("3.3") * 2 + table_mm("3.3")[:1],
    # realistic looks of the same geometry: the same poses as their flat twins
    "sim-room-37-real": table_mm("3.2"),
    "l-room-1lap-real": table_mm("3.3") + table_mm("3.3")[:1],
    # no table: the office loop is checked by test_office_loop_circles_the_pillar
    "office-real": [(x * 1000.0, y * 1000.0) for x, y, _ in datasets.office_loop()],
    # no table: the building loop is checked by test_building_loop_two_laps_through_rooms
    "building-2laps": [(x * 1000.0, y * 1000.0) for x, y, _ in datasets.building_loop()],
}
EXPECTED_FRAMES = {"sim-room-10": 10, "sim-room-37": 37, "sim-room-turning": 37,
                   "l-room-1lap": 60, "l-room-2laps": 119,
                   "sim-room-37-real": 37, "l-room-1lap-real": 60, "office-real": 45,
                   "building-2laps": 385}
# Datasets facing the direction of travel (heading not constant): no thesis odometry.txt.
TURNING = {"sim-room-turning", "office-real", "building-2laps"}
CAMERA_HEIGHT_M = {"office-real": 0.8}      # the others 1.0
# Realistic datasets (rooms_real.py), their flat twin (same geometry) and the floor pattern.
REALISTIC = {"sim-room-37-real": ("sim-room-37", "cells"), "l-room-1lap-real": ("l-room-1lap", "brick"),
             "office-real": (None, "hexagon")}
# Flat-shaded datasets stored as grey PNGs (too many frames for RGB).
GREY_FLAT = {"building-2laps"}
SKIRTING_DEPTH_M = 0.012
METADATA_FILES = ["groundtruth.tum", "odometry.tum", "odometry_exact.tum", "odometry.txt", "floorplan.csv",
                  "dataset.yaml"]


# ---------------------------------------------------------------------------- metadata
@pytest.mark.parametrize("name", DATASET_NAMES)
def test_dataset_yaml_keys(metadata_dir, name):
    meta = yaml.safe_load((metadata_dir / name / "dataset.yaml").read_text())
    assert list(meta) == ["name", "camera", "mirror", "camera_height_m", "frames", "rate_hz", "images",
                          "groundtruth", "odometry", "odometry_exact", "odometry_noise", "floorplan"]
    assert meta["name"] == name
    assert meta["camera"] == {"width": 1024, "height": 1024, "center_px": [511.5, 511.5],
                              "focal_mm": 25.0, "pixel_pitch_mm": pytest.approx(0.00702051, abs=1e-8)}
    assert meta["mirror"] == "thesis-2008"
    assert meta["camera_height_m"] == CAMERA_HEIGHT_M.get(name, 1.0)
    assert meta["frames"] == EXPECTED_FRAMES[name]
    assert meta["rate_hz"] == 10
    assert meta["images"] == "images/%06d.png"
    assert meta["odometry_noise"] == {"model": "thesis", "seed": 1}
    for key in ("groundtruth", "odometry", "odometry_exact", "floorplan"):
        assert (metadata_dir / name / meta[key]).is_file()


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_groundtruth_reproduces_trajectory_table(metadata_dir, name):
    gt = poses(metadata_dir / name / "groundtruth.tum")
    pts = EXPECTED_POINTS[name]
    assert len(gt) == len(pts) == EXPECTED_FRAMES[name]
    assert times(metadata_dir / name / "groundtruth.tum") == pytest.approx([i / 10 for i in range(len(gt))])
    # Map frame = first pose: for a constant heading the table relative to point 1;
    # when turning, also rotated by the first heading (towards point 2).
    assert datasets.DATASETS[name].constant_heading == (name not in TURNING)
    yaw0 = 0.0
    if name in TURNING:
        yaw0 = math.atan2(pts[1][1] - pts[0][1], pts[1][0] - pts[0][0])
    c, s = math.cos(yaw0), math.sin(yaw0)
    for (x, y, yaw), (px, py) in zip(gt, pts):
        dx, dy = (px - pts[0][0]) / 1000.0, (py - pts[0][1]) / 1000.0
        assert x == pytest.approx(c * dx + s * dy, abs=1e-9)
        assert y == pytest.approx(-s * dx + c * dy, abs=1e-9)
        if name not in TURNING:
            assert abs(yaw) < 1e-12


@pytest.mark.parametrize("name, corners, min_facing", [("sim-room-turning", 4, 20), ("office-real", 3, 30),
                                                        ("building-2laps", 8, 300)])
def test_turning_headings_face_travel_and_turn_smoothly(metadata_dir, name, corners, min_facing):
    gt = poses(metadata_dir / name / "groundtruth.tum")
    yaw_steps = [abs(angle_diff(b[2], a[2])) for a, b in zip(gt[:-1], gt[1:])]
    # The sharpest turn (90 deg) is spread over several poses.
    assert max(yaw_steps) <= math.radians(90.0 / 4) + 1e-9
    turning = [i for i, d in enumerate(yaw_steps) if d > 1e-9]
    assert len(turning) >= 3 * corners   # corners x >= 3 steps
    # On the straight parts the robot faces its direction of travel.
    facing = 0
    for a, b in zip(gt[:-1], gt[1:]):
        travel = math.atan2(b[1] - a[1], b[0] - a[0])
        if abs(angle_diff(a[2], travel)) < 1e-9 and abs(angle_diff(b[2], travel)) < 1e-9:
            facing += 1
    assert facing >= min_facing


def test_office_loop_circles_the_pillar():
    """office-real: one counter-clockwise lap around the pillar back to the start, steps of
    0.25-0.30 m, first and last pose facing their step, left turns only (three corners of
    90 deg; the fourth is where the lap starts and ends)."""
    spec = datasets.DATASETS["office-real"]
    world = spec.world_poses()
    assert len(world) == 45
    assert world[0][:2] == world[-1][:2]
    lengths = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(world[:-1], world[1:])]
    assert min(lengths) >= 0.25 and max(lengths) <= 0.30
    assert sum(lengths) == pytest.approx(2 * (4.6 + 1.6), abs=1e-5)
    pillar = next(o for o in spec.room().objects if o.name == "pillar")
    cx, cy = pillar.centre
    bearings = [math.atan2(p[1] - cy, p[0] - cx) for p in world]
    winding = sum(angle_diff(b, a) for a, b in zip(bearings[:-1], bearings[1:]))
    assert winding == pytest.approx(2 * math.pi, abs=1e-9)
    for pose, (a, b) in ((world[0], (world[0], world[1])), (world[-1], (world[-2], world[-1]))):
        assert angle_diff(pose[2], math.atan2(b[1] - a[1], b[0] - a[0])) == pytest.approx(0.0, abs=1e-9)
    turns = [angle_diff(b[2], a[2]) for a, b in zip(world[:-1], world[1:])]
    assert min(turns) >= -1e-12
    assert sum(turns) == pytest.approx(math.radians(270.0), abs=1e-9)


def test_building_loop_two_laps_through_rooms():
    """building-2laps: two identical counter-clockwise laps of 48 m (>= 80 m in all) in
    0.25 m steps, back to the first pose; each lap runs the long corridor, the east corridor,
    both rooms through their three doors and the west corridor."""
    spec = datasets.DATASETS["building-2laps"]
    world = spec.world_poses()
    assert len(world) == 385
    # lap 2 repeats lap 1 (headings up to rounding: its images are lap 1's)
    for p, q in zip(world[:193], world[192:]):
        assert p[:2] == q[:2] and abs(angle_diff(p[2], q[2])) < 1e-12
    lengths = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(world[:-1], world[1:])]
    assert lengths == pytest.approx([0.25] * 384, abs=1e-9)
    assert sum(lengths) == pytest.approx(96.0, abs=1e-6) and sum(lengths) >= 80.0
    turns = [angle_diff(b[2], a[2]) for a, b in zip(world[:-1], world[1:])]
    assert min(turns) >= -1e-12 and sum(turns) == pytest.approx(4 * math.pi, abs=1e-9)
    lap = world[:193]
    # through the three doors (partition x: W|A 2.0-2.15, A|B 9.925-10.075, B|E 17.85-18.0),
    # openings y 6.3..7.7
    for x_door in (2.075, 10.0, 17.925):
        crossing = [(a, b) for a, b in zip(lap[:-1], lap[1:]) if min(a[0], b[0]) <= x_door <= max(a[0], b[0])
                    and 4.5 < a[1] < 12.0]
        assert crossing and all(6.3 + 0.45 <= a[1] <= 7.7 - 0.45 for a, _ in crossing)
    room = spec.room()
    in_room = {name: sum(1 for x, y, _ in lap if x0 < x < x1 and y > 4.5)
               for name, x0, x1 in (("A", 2.15, 9.925), ("B", 10.075, 17.85))}
    assert min(in_room.values()) >= 25
    assert max(x for x, _, _ in lap) - min(x for x, _, _ in lap) == pytest.approx(18.0)
    assert room.height == 3.0 and spec.camera_height_m == 1.0


def test_building_long_corridor_is_plain():
    """Along the middle of the long corridor every wall or object in sight within the stereo
    range (6 m) runs along the corridor: nothing there fixes the motion along it."""
    spec = datasets.DATASETS["building-2laps"]
    room = spec.room()
    segments = room.floorplan()

    def blocked(x0, y0, x1, y1):
        """Does the sight line from (x0, y0) to just before (x1, y1) cross a wall block?"""
        for t in np.linspace(0.0, 0.995, 60):
            x, y = x0 + t * (x1 - x0), y0 + t * (y1 - y0)
            if any(b.lo[0] < x < b.hi[0] and b.lo[1] < y < b.hi[1] for b in room.solids):
                return True
        return False

    middle = [p for p in spec.world_poses() if p[1] == 1.0 and 8.0 <= p[0] <= 12.0]
    assert len(middle) == 2 * 17
    seen = set()
    for x, y, yaw in middle:
        assert abs(yaw) < 1e-12
        for seg in segments:
            x1, y1, x2, y2 = seg
            for t in np.linspace(0.0, 1.0, 41):
                px, py = x1 + t * (x2 - x1), y1 + t * (y2 - y1)
                if math.hypot(px - x, py - y) < 6.0 and not blocked(x, y, px, py):
                    assert y1 == y2, (x, seg)
                    seen.add(seg)
    # in sight: only the corridor's two walls, the facade and the core's face, 16 m without a gap
    assert seen == {(0.0, 0.0, 20.0, 0.0), (18.0, 2.0, 2.0, 2.0)}


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_trajectory_clears_every_object(name):
    spec = datasets.DATASETS[name]
    room, world = spec.room(), spec.world_poses()
    for a, b in zip(world[:-1], world[1:]):
        for t in np.linspace(0.0, 1.0, 21):
            x, y = a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])
            dist, what = room.clearance(x, y)
            assert dist >= 0.45, f"({x:.3f}, {y:.3f}) is {dist:.3f} m from {what}"


# ---------------------------------------------------------------------------- odometry
@pytest.mark.parametrize("name", DATASET_NAMES)
def test_exact_odometry_is_groundtruth(metadata_dir, name):
    gt = poses(metadata_dir / name / "groundtruth.tum")
    exact = poses(metadata_dir / name / "odometry_exact.tum")
    assert len(exact) == len(gt)
    for p, q in zip(exact, gt):
        assert abs(p[0] - q[0]) < 1e-9 and abs(p[1] - q[1]) < 1e-9
        assert abs(angle_diff(p[2], q[2])) < 1e-9
    # composing the exact increments again gives the ground truth
    again = odometry.dead_reckon(steps(exact))
    for p, q in zip(again, gt):
        assert abs(p[0] - q[0]) < 1e-9 and abs(p[1] - q[1]) < 1e-9
        assert abs(angle_diff(p[2], q[2])) < 1e-9


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_noisy_odometry_respects_model_bounds(metadata_dir, name):
    gt = poses(metadata_dir / name / "groundtruth.tum")
    noisy = poses(metadata_dir / name / "odometry.tum")
    assert noisy[0] == (0.0, 0.0, 0.0)
    scales, yaw_errors = [], []
    for true, meas in zip(steps(gt), steps(noisy)):
        length, length_meas = math.hypot(true[0], true[1]), math.hypot(meas[0], meas[1])
        if length > 1e-9:
            scales.append(length_meas / length)
            # direction in the robot frame kept
            assert abs(angle_diff(math.atan2(meas[1], meas[0]), math.atan2(true[1], true[0]))) < 1e-6
        else:
            assert length_meas < 1e-9
        err = angle_diff(meas[2], true[2])
        bound = max(0.10 * abs(true[2]), math.radians(1.5))
        assert abs(err) <= bound + 1e-9
        yaw_errors.append(err)
    scales = np.array(scales)
    assert scales.min() >= 0.9 - 1e-9 and scales.max() <= 1.1 + 1e-9
    assert np.abs(scales - 1).max() > 0.01        # noise was applied
    assert np.abs(yaw_errors).max() > math.radians(0.3)


def test_noisy_odometry_reproducible_and_seeded(metadata_dir, tmp_path):
    name = "sim-room-37"
    datasets.build(name, tmp_path / "again", images=False, log=lambda *_: None)
    first = (metadata_dir / name / "odometry.tum").read_bytes()
    assert (tmp_path / "again" / "odometry.tum").read_bytes() == first
    gt = poses(metadata_dir / name / "groundtruth.tum")
    seeded = odometry.odometry(gt, 1)
    other = odometry.odometry(gt, 2)
    written = poses(metadata_dir / name / "odometry.tum")
    assert np.abs(np.array(written) - np.array(seeded)).max() < 1e-9
    assert max(abs(a[0] - b[0]) + abs(a[1] - b[1]) for a, b in zip(seeded, other)) > 1e-3
    exact = poses(metadata_dir / name / "odometry_exact.tum")
    assert max(math.hypot(a[0] - b[0], a[1] - b[1]) for a, b in zip(seeded, exact)) > 1e-2


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_thesis_odometry_txt_matches_tum(metadata_dir, name):
    path = metadata_dir / name / "odometry.txt"
    if name in TURNING:
        assert not path.exists()          # heading not constant: no thesis-format file
        return
    pairs = odometry.read_thesis_odometry(path)
    noisy = poses(metadata_dir / name / "odometry.tum")
    assert len(pairs) == len(noisy)
    assert pairs[0] == (0.0, 0.0)
    x = y = 0.0
    for (dist_mm, angle_deg), pose in zip(pairs, noisy):
        x += dist_mm / 1000.0 * math.cos(math.radians(angle_deg))
        y += dist_mm / 1000.0 * math.sin(math.radians(angle_deg))
        assert x == pytest.approx(pose[0], abs=1e-6) and y == pytest.approx(pose[1], abs=1e-6)


# ---------------------------------------------------------------------------- floor plan
def _floorplan(path):
    lines = path.read_text().splitlines()
    assert lines[0] == "x1,y1,x2,y2"
    return np.array([[float(v) for v in ln.split(",")] for ln in lines[1:]])


def test_floorplan_sim_room(metadata_dir):
    segs = _floorplan(metadata_dir / "sim-room-37" / "floorplan.csv")
    # map frame = pose 1 at room (3, 1.5): the walls x = -4, 4 and y = -2, 2 become
    # x = -7, 1 and y = -3.5, 0.5
    xs, ys = segs[:, [0, 2]], segs[:, [1, 3]]
    assert xs.min() == pytest.approx(-7.0) and xs.max() == pytest.approx(1.0)
    assert ys.min() == pytest.approx(-3.5) and ys.max() == pytest.approx(0.5)
    # 4 walls + 2 cabinets, table top, platform, board, 4 boxes (4 sides each)
    # + table column and sphere (24 sides each)
    assert len(segs) == 4 + 4 * 9 + 24 * 2
    lengths = np.hypot(segs[:, 2] - segs[:, 0], segs[:, 3] - segs[:, 1])
    assert np.isclose(lengths, 8.0).sum() == 2 and np.isclose(lengths, 4.0).sum() == 2


def test_floorplan_l_room(metadata_dir):
    segs = _floorplan(metadata_dir / "l-room-1lap" / "floorplan.csv")
    walls = segs[:6]
    assert np.ptp(walls[:, [0, 2]]) == pytest.approx(6.9)
    assert len(segs) == 6 + 3 * 5 * 4 + 2 * 4   # walls, three 4-legged tables, cabinet, crate


def _inset_walls(walls: np.ndarray, depth: float) -> np.ndarray:
    """The walls of an axis-aligned counter-clockwise polygon moved inwards by `depth`:
    each corner moves by `depth` along the inward normals of both walls meeting there
    (where the two moved walls, perpendicular, meet again)."""
    d = walls[:, 2:] - walls[:, :2]
    d /= np.hypot(d[:, 0], d[:, 1])[:, None]
    assert np.all(np.abs(d[:, 0] * np.roll(d, 1, axis=0)[:, 0] + d[:, 1] * np.roll(d, 1, axis=0)[:, 1]) < 1e-12)
    inward = np.stack([-d[:, 1], d[:, 0]], axis=1)          # left of a counter-clockwise wall
    corners = walls[:, :2] + depth * (inward + np.roll(inward, 1, axis=0))
    return np.hstack([corners, np.roll(corners, -1, axis=0)])


@pytest.mark.parametrize("name, n_walls", [("sim-room-37-real", 4), ("l-room-1lap-real", 6)])
def test_floorplan_realistic_twin_is_flat_plan_with_skirting(metadata_dir, name, n_walls):
    """Same objects as the flat twin; the walls are the skirting boards' faces, 12 mm inside."""
    twin = REALISTIC[name][0]
    real_lines = (metadata_dir / name / "floorplan.csv").read_text().splitlines()
    flat_lines = (metadata_dir / twin / "floorplan.csv").read_text().splitlines()
    assert len(real_lines) == len(flat_lines)
    assert real_lines[1 + n_walls:] == flat_lines[1 + n_walls:]
    segs, flat = _floorplan(metadata_dir / name / "floorplan.csv"), _floorplan(metadata_dir / twin / "floorplan.csv")
    assert segs[:n_walls] == pytest.approx(_inset_walls(flat[:n_walls], SKIRTING_DEPTH_M), abs=2e-9)
    # the same in the room frame, unrounded
    room, flat_room = datasets.DATASETS[name].room(), datasets.DATASETS[twin].room()
    assert room.floorplan()[n_walls:] == flat_room.floorplan()[n_walls:]
    expected = _inset_walls(np.array(flat_room.floorplan()[:n_walls]), SKIRTING_DEPTH_M)
    assert np.array(room.floorplan()[:n_walls]) == pytest.approx(expected, abs=1e-12)
    if name == "sim-room-37-real":
        xs, ys = segs[:4, [0, 2]], segs[:4, [1, 3]]
        assert xs.min() == pytest.approx(-7.0 + 0.012) and xs.max() == pytest.approx(1.0 - 0.012)
        assert ys.min() == pytest.approx(-3.5 + 0.012) and ys.max() == pytest.approx(0.5 - 0.012)


def test_floorplan_office(metadata_dir):
    segs = _floorplan(metadata_dir / "office-real" / "floorplan.csv")
    # map frame = pose 1 at room (1.2, 1.8), heading 0: the 7.0 x 5.2 m room's walls
    # x = 0, 7 and y = 0, 5.2, at the skirting faces 12 mm inside
    ox, oy, d = 1.2, 1.8, SKIRTING_DEPTH_M
    expected_walls = [(-ox + d, -oy + d, 7.0 - ox - d, -oy + d), (7.0 - ox - d, -oy + d, 7.0 - ox - d, 5.2 - oy - d),
                      (7.0 - ox - d, 5.2 - oy - d, -ox + d, 5.2 - oy - d), (-ox + d, 5.2 - oy - d, -ox + d, -oy + d)]
    assert segs[:4] == pytest.approx(np.array(expected_walls), abs=2e-9)
    # 4 walls + pillar (24) + desk top and 4 legs + sofa + bookshelf + low table top and
    # 4 legs (4 sides each) + bin (24)
    assert len(segs) == 4 + 24 + 4 * 12 + 24
    for circle, (cx, cy), r in ((segs[4:28], (3.5, 2.6), 0.2), (segs[-24:], (0.4, 0.4), 0.15)):
        assert np.hypot(circle[:, 0] - (cx - ox), circle[:, 1] - (cy - oy)) == pytest.approx(np.full(24, r), abs=2e-9)
        assert np.array_equal(circle[:, 2:], np.roll(circle[:, :2], -1, axis=0))     # closed 24-gon
    boxes = [(0.4, 3.9, 2.0, 4.7),                                                    # desk top
             *[(x, y, x + 0.05, y + 0.05) for x, y in ((0.45, 3.95), (1.9, 3.95), (1.9, 4.6), (0.45, 4.6))],
             (4.5, 0.3, 6.5, 1.2),                                                    # sofa
             (6.65, 2.0, 7.0, 3.2),                                                   # bookshelf
             (4.4, 4.0, 5.2, 4.6),                                                    # low table top
             *[(x, y, x + 0.05, y + 0.05) for x, y in ((4.45, 4.05), (5.1, 4.05), (5.1, 4.5), (4.45, 4.5))]]
    for k, (x0, y0, x1, y1) in enumerate(boxes):
        x0, y0, x1, y1 = x0 - ox, y0 - oy, x1 - ox, y1 - oy
        rect = [(x0, y0, x1, y0), (x1, y0, x1, y1), (x1, y1, x0, y1), (x0, y1, x0, y0)]
        assert segs[28 + 4 * k:32 + 4 * k] == pytest.approx(np.array(rect), abs=2e-9), f"box {k}"


def test_floorplan_building(metadata_dir):
    segs = _floorplan(metadata_dir / "building-2laps" / "floorplan.csv")
    # map frame = pose 1 at room (4, 1), heading east: the 20 x 12 m floor spans
    # x -4..16, y -1..11
    walls = segs[:28]
    assert walls[:, [0, 2]].min() == pytest.approx(-4.0) and walls[:, [0, 2]].max() == pytest.approx(16.0)
    assert walls[:, [1, 3]].min() == pytest.approx(-1.0) and walls[:, [1, 3]].max() == pytest.approx(11.0)
    # 28 wall segments, 22 boxes (four 4-legged tables and six others) and 2 circles
    assert len(segs) == 28 + 4 * (4 * 5 + 6) + 24 * 2
    # every wall segment has free floor on its left and a solid on its right (the core, a
    # partition, or the outer walls beyond the floor's outline)
    room = datasets.DATASETS["building-2laps"].room()
    for x1, y1, x2, y2 in room.walls():
        mx, my = 0.5 * (x1 + x2), 0.5 * (y1 + y2)
        nx, ny = -(y2 - y1), x2 - x1          # left of the segment: the free side
        n = math.hypot(nx, ny)
        fx, fy = mx + 0.01 * nx / n, my + 0.01 * ny / n
        assert 0.0 < fx < 20.0 and 0.0 < fy < 12.0
        assert not any(b.lo[0] < fx < b.hi[0] and b.lo[1] < fy < b.hi[1] for b in room.solids)
        sx, sy = mx - 0.01 * nx / n, my - 0.01 * ny / n
        assert not (0.0 < sx < 20.0 and 0.0 < sy < 12.0) or any(
            b.lo[0] < sx < b.hi[0] and b.lo[1] < sy < b.hi[1] for b in room.solids)
    # facades 2 x (20 + 12) less the three partition ends on the north one, the core's
    # south face (16), its west and east ends continued by the partitions (4 x 4.3, cut by
    # the doors), its north face in both rooms (2 x 7.775), the partitions' room faces
    # (4 x 6.1) and six door jambs
    length = sum(math.hypot(x2 - x1, y2 - y1) for x1, y1, x2, y2 in room.walls())
    assert length == pytest.approx(64.0 - 3 * 0.15 + 16.0 + 4 * 4.3 + 2 * 7.775 + 4 * 6.1 + 6 * 0.15)


def test_building_floor_skirting_lines_every_side_of_the_free_floor():
    # A Floor's skirting (the held-out building-real) runs along every side of the free floor
    # on its free side, and the plan follows the boards' faces: before, the boards were the
    # bounding boxes of the outer outline's inset edges paired with the first four wall
    # segments, 8 cm slabs over much of the floor.
    room = datasets.HELD_OUT["building-real"].room()
    bare = datasets.DATASETS["building-2laps"].room()
    depth, height = room.skirting.depth, room.skirting.height
    boards = [line for line in room.pov_body().splitlines() if line.strip().endswith("// skirting")]
    assert len(boards) == len(bare.walls()) == len(room.inner_faces())
    assert room.walls() == bare.walls()
    assert set(map(tuple, room.floorplan())) >= set(map(tuple, room.inner_faces()))
    for (x1, y1, x2, y2), (a1, b1, a2, b2) in zip(bare.walls(), room.inner_faces()):
        nx, ny = -(y2 - y1), x2 - x1          # left: the free side
        n = math.hypot(nx, ny)
        assert (a1, b1) == pytest.approx((x1 + depth * nx / n, y1 + depth * ny / n))
        assert (a2, b2) == pytest.approx((x2 + depth * nx / n, y2 + depth * ny / n))
    # every board is one side's length by the board's depth, as high as the board
    lengths = []
    for line in boards:
        lo, hi = [np.array([float(v) for v in part.split(">")[0].split(",")]) for part in line.split("<")[1:3]]
        size = np.sort(np.abs(hi[:2] - lo[:2]))
        assert size[0] == pytest.approx(depth * 1000.0)
        assert lo[2] == pytest.approx(0.0) and hi[2] == pytest.approx(height * 1000.0)
        lengths.append(size[1])
    assert sorted(lengths) == pytest.approx(
        sorted(1000.0 * math.hypot(x2 - x1, y2 - y1) for x1, y1, x2, y2 in bare.walls()))


def test_home_cables_lie_on_the_floor_outside_the_plan_and_cross_the_path():
    # The held-out living room: its cables are floor texture a few millimetres high (not in the
    # floor plan, which draws what a robot cannot drive over), one of them crosses the path,
    # and the path clears every object in the plan.
    spec = datasets.HELD_OUT["home"]
    room, world = spec.room(), spec.world_poses()
    sweeps = [line for line in room.pov_body().splitlines() if line.strip().startswith("sphere_sweep")]
    assert len(sweeps) == len(room.cables) == 3
    for cable, line in zip(room.cables, sweeps):
        assert line.rstrip().endswith(f"// {cable.name}")
        knots = [[float(v) for v in knot.split(",")] for knot in re.findall(r"<([^>]*)>", line)[:len(cable.points)]]
        assert np.allclose([k[:2] for k in knots], 1000.0 * np.array(cable.points))
        assert all(k[2] == pytest.approx(1000.0 * cable.radius) for k in knots)  # lying on the floor
    plan = {tuple(round(v, 6) for v in seg) for seg in room.floorplan()}
    for cable in room.cables:
        for (x1, y1), (x2, y2) in zip(cable.points, cable.points[1:]):
            assert (x1, y1, x2, y2) not in plan

    def crosses(p, q, a, b):
        def side(u, v, w):
            return (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0])
        return side(p, q, a) * side(p, q, b) < 0 and side(a, b, p) * side(a, b, q) < 0

    path = [(x, y) for x, y, _ in world]
    lead = room.cables[0].points
    assert any(crosses(p, q, a, b) for p, q in zip(path, path[1:]) for a, b in zip(lead, lead[1:]))
    for a, b in zip(world[:-1], world[1:]):
        for t in np.linspace(0.0, 1.0, 21):
            dist, what = room.clearance(a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]))
            assert dist >= 0.4, what
    assert spec.camera_height_m == 1.05 and spec.grey


def test_home_step_pit_is_cut_into_the_floor_and_drawn_in_the_plan():
    # The held-out sunken area: the floor is a plane with a box cut out (bottom and sides in
    # the floor's material), its edge is in the floor plan and the path stays clear of it.
    spec = datasets.HELD_OUT["home-step"]
    room, world = spec.room(), spec.world_poses()
    (pit,) = room.pits
    floor = next(line for line in room.pov_body().splitlines() if line.strip().endswith("pit(s)"))
    assert floor.startswith("difference { plane { z, 0 } box { <2400.0, 1800.0, -180.0>, <3900.0, 2700.0, 1000.0> }")
    assert room.floor_texture in floor
    plan = {tuple(round(v, 6) for v in seg) for seg in room.floorplan()}
    assert {tuple(round(v, 6) for v in seg) for seg in pit.outline()} <= plan
    assert room.clearance(3.0, 2.2) == (0.0, "sunken area")
    assert min(room.clearance(x, y)[0] for x, y, _ in world) >= 0.4
    assert not any(o.name.startswith("low table") for o in room.objects) and not room.rugs


def test_home_ramp_is_a_wedge_in_the_floor_material_down_the_pit():
    # The held-out ramp: the pit of home-step 0.12 m deep, and a prism swept across its width
    # whose top runs from the floor's level at its left edge to its bottom at the right edge.
    room = datasets.HELD_OUT["home-ramp"].room()
    (pit,) = room.pits
    assert (pit.depth, pit.ramp_m) == (0.12, 1.5)
    ramp = next(line for line in room.pov_body().splitlines() if line.strip().endswith(": ramp"))
    assert ramp.startswith("prism { linear_sweep linear_spline 1800.0, 2700.0, 4, <2400.0, 0.0>, <3900.0, -120.0>, "
                           "<2400.0, -120.0>, <2400.0, 0.0> ")
    assert room.floor_texture in ramp
    # Without a ramp the scene is as before (home-step's renders keep their key).
    assert ": ramp" not in datasets.HELD_OUT["home-step"].room().pov_body()


def test_home_stairs_are_nested_pits_each_a_step_deeper():
    room = datasets.HELD_OUT["home-stairs"].room()
    assert [round(pit.depth, 2) for pit in room.pits] == [0.18, 0.36, 0.54, 0.72]
    assert [round(pit.lo[0], 2) for pit in room.pits] == [2.4, 2.7, 3.0, 3.3]
    assert all(pit.hi == (3.9, 2.7) and pit.lo[1] == 1.8 for pit in room.pits)
    assert room.pov_body().count("box { <") >= 4


def test_frames_option_limits_metadata(tmp_path):
    out = tmp_path / "ds"
    subprocess.run(RENDER + ["l-room-2laps", "--out", str(out), "--frames", "7", "--no-images"],
                   check=True, capture_output=True, cwd=REPO)
    meta = yaml.safe_load((out / "dataset.yaml").read_text())
    assert meta["frames"] == 7
    for f in ("groundtruth.tum", "odometry.tum", "odometry_exact.tum"):
        assert len(poses(out / f)) == 7
    assert len(odometry.read_thesis_odometry(out / "odometry.txt")) == 7
    assert not (out / "images").exists()


def test_camera_height_option(tmp_path):
    """--camera-height renders the same room and path with the camera at another height:
    dataset.yaml says so, the poses are unchanged, a height off the range is refused."""
    out = tmp_path / "ds"
    subprocess.run(RENDER + ["office-real", "--out", str(out), "--frames", "3", "--no-images",
                             "--camera-height", "1.25"], check=True, capture_output=True, cwd=REPO)
    meta = yaml.safe_load((out / "dataset.yaml").read_text())
    assert meta["camera_height_m"] == 1.25
    same = tmp_path / "same"
    subprocess.run(RENDER + ["office-real", "--out", str(same), "--frames", "3", "--no-images"],
                   check=True, capture_output=True, cwd=REPO)
    assert yaml.safe_load((same / "dataset.yaml").read_text())["camera_height_m"] == 0.8
    assert (out / "groundtruth.tum").read_bytes() == (same / "groundtruth.tum").read_bytes()
    refused = subprocess.run(RENDER + ["office-real", "--out", str(tmp_path / "no"), "--no-images",
                                       "--camera-height", "0.1"], capture_output=True, text=True, cwd=REPO)
    assert refused.returncode != 0 and "--camera-height" in refused.stderr


@pytest.mark.parametrize("name", DATASET_NAMES)
def test_bundled_metadata_is_reproduced(metadata_dir, name):
    """The metadata of every bundled dataset (datasets/<name>) is what build() writes, byte for byte."""
    bundled = REPO / "datasets" / name
    if not (bundled / "dataset.yaml").is_file():
        pytest.skip(f"{name} is not bundled (no datasets/{name}/dataset.yaml)")
    for f in METADATA_FILES:
        built = metadata_dir / name / f
        assert built.is_file() == (bundled / f).is_file(), f
        if built.is_file():
            assert built.read_bytes() == (bundled / f).read_bytes(), f


# ---------------------------------------------------------------------------- grey PNGs
@pytest.mark.parametrize("shape", [(1024, 1024), (3, 5)])
def test_write_png_gray_round_trips(tmp_path, shape):
    img = np.random.default_rng(7).integers(0, 256, size=shape, dtype=np.uint8)
    write_png_gray(tmp_path / "grey.png", img)
    back = read_png(tmp_path / "grey.png")
    assert back.dtype == np.uint8 and back.shape == shape
    assert np.array_equal(back, img)


def test_to_gray_weights():
    rgb = np.array([[[255, 0, 0], [0, 255, 0], [0, 0, 255], [255, 255, 255], [0, 0, 0]]], np.uint8)
    grey = to_gray(rgb)
    assert grey.dtype == np.uint8 and grey.shape == (1, 5)
    assert grey.tolist() == [[76, 150, 29, 255, 0]]
    # an alpha channel is ignored, a grey image is kept
    rgba = np.concatenate([rgb, np.full((1, 5, 1), 7, np.uint8)], axis=2)
    assert np.array_equal(to_gray(rgba), grey)
    assert np.array_equal(to_gray(grey), grey)


# ---------------------------------------------------------------------------- rendering
@pytest.mark.parametrize("name", sorted(REALISTIC))
def test_realistic_room_scene_parts(name):
    """(Rendering one realistic frame is too slow for the suite: check the scene text.)"""
    spec = datasets.DATASETS[name]
    assert spec.grey
    room = spec.room()
    body = room.pov_body()
    assert room.floor_texture and REALISTIC[name][1] in room.floor_texture
    assert f"plane {{ z, 0 {room.floor_texture} }}  // floor" in body
    assert body.count("area_light") == len(room.area_lamps) >= 2
    assert body.count("projected_through") == 1 and "// sun through window" in body
    assert body.count("// skirting") == len(room.outline)
    assert "shadowless" not in body


@pytest.mark.parametrize("name", [n for n in DATASET_NAMES if n not in REALISTIC])
def test_flat_rooms_have_no_realistic_parts(name):
    spec = datasets.DATASETS[name]
    assert spec.grey == (name in GREY_FLAT)
    body = spec.room().pov_body()
    for part in ("area_light", "projected_through", "// skirting", "texture", "no_shadow"):
        assert part not in body


def test_flat_scene_keys_unchanged():
    # the keys the bundled flat datasets record (their images stay valid)
    assert datasets.render_key(rooms.sim_room()) == "f27652dab1e05c78"
    assert datasets.render_key(rooms.l_room()) == "df606803c84301d3"


def test_convention_check_matches_reference(tmp_path):
    png = tmp_path / "convention.png"
    convention.render_convention(png)
    img, ref = read_png(png), read_png(convention.DATA_DIR / "image.png")
    stats = convention.compare(img, ref)
    assert stats["mean_abs"] < 0.1
    assert stats["px_diff_gt_32"] < 100
    assert stats["red"]["mean_az_deg"] == pytest.approx(stats["red"]["ref_mean_az_deg"], abs=0.1)
    assert stats["blue"]["mean_az_deg"] == pytest.approx(90.0, abs=0.1)
    # the red cube (centre azimuth 18.4 deg) in both lobes, the blue one at 90 deg
    for colour, expected in (("red", 19.0), ("blue", 90.0)):
        az = convention.colour_azimuths_deg(img, colour)
        assert np.median(az) == pytest.approx(expected, abs=1.5)
    rgb = img.astype(int)
    vv, uu = np.nonzero((rgb[..., 0] > 120) & (rgb[..., 0] > 2 * rgb[..., 1]) & (rgb[..., 0] > 2 * rgb[..., 2]))
    radius = np.hypot(uu - 511.5, vv - 511.5)
    assert (radius < mirror.R_SPLIT_PX).sum() > 500 and (radius > mirror.R_SPLIT_PX).sum() > 500


def test_mirror_geometry_matches_model():
    """Every pixel's ray hits the floor where mirror.md's back-projection says."""
    result = geocheck.check(range_mm=20000.0)
    for lobe in ("inner", "outer"):
        assert result[lobe]["pixels"] > 150000
        assert result[lobe]["median_abs_px"] < 0.01
        assert result[lobe]["max_abs_px"] < 0.05
        assert result[lobe]["max_abs_az_deg"] < 0.01


def test_render_is_deterministic(tmp_path):
    outs = [tmp_path / "a", tmp_path / "b"]
    for out in outs:
        subprocess.run(RENDER + ["sim-room-37", "--out", str(out), "--frames", "2"],
                       check=True, capture_output=True, cwd=REPO)
    for i in (1, 2):
        a = (outs[0] / "images" / f"{i:06d}.png").read_bytes()
        b = (outs[1] / "images" / f"{i:06d}.png").read_bytes()
        assert a == b
    assert sorted(p.name for p in (outs[0] / "images").iterdir()) == ["000001.png", "000002.png"]
    img = read_png(outs[0] / "images" / "000001.png")
    assert img.shape == (1024, 1024, 3) and img.dtype == np.uint8
    # black centre and corners, mirror content in both annuli
    assert img[511, 511].max() == 0 and img[0, 0].max() == 0
    assert img[511, 511 + 150].max() > 0 and img[511, 511 + 400].max() > 0


def test_identical_poses_reuse_images(tmp_path):
    """l-room-2laps reuses l-room-1lap's images of the same poses (no re-render)."""
    one = tmp_path / "l-room-1lap"
    datasets.build("l-room-1lap", one, frames=3, images=False, log=lambda *_: None)
    (one / "images").mkdir()
    for i in (1, 2, 3):
        (one / "images" / f"{i:06d}.png").write_bytes(b"frame %d" % i)
    two = tmp_path / "l-room-2laps"
    stats = datasets.build("l-room-2laps", two, frames=3, log=lambda *_: None)
    assert stats["rendered"] == 0 and stats["reused"] == 3
    for i in (1, 2, 3):
        assert (two / "images" / f"{i:06d}.png").read_bytes() == b"frame %d" % i


def test_floor_wall_edges_match_mirror_model(metadata_dir, tmp_path):
    """A turned pose of sim-room-turning: the floor-wall boundary seen in both lobes
    lies where mirror.md projects the floor-plan walls (map frame, ground truth)."""
    name, frame = "sim-room-turning", 10
    spec = datasets.DATASETS[name]
    datasets.render_images(spec, tmp_path, [spec.world_poses()[frame - 1]], log=lambda *_: None)
    img = read_png(tmp_path / "images" / "000001.png")
    segments = np.loadtxt(metadata_dir / name / "floorplan.csv", delimiter=",", skiprows=1)
    pose = poses(metadata_dir / name / "groundtruth.tum")[frame - 1]
    errors = floor_wall_edge_errors(img, segments, 4, pose, 1000.0)
    for lobe in ("inner", "outer"):
        assert len(errors[lobe]) >= 60
        assert abs(np.median(errors[lobe])) < 0.1
        assert np.median(np.abs(errors[lobe])) < 0.2
        assert np.percentile(np.abs(errors[lobe]), 95) < 0.5
