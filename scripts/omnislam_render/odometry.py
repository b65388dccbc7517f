"""Odometry from ground truth: exact increments and the noise model "thesis".

Noise model "thesis" (architecture.md, dataset format), per step i-1 -> i with the
true increment (dx, dy, dyaw) in the robot frame of pose i-1:
  * translation scaled by (1 + U(-0.10, 0.10)), its direction in the robot frame kept;
  * yaw error = the larger in magnitude of U(-0.10, 0.10) * dyaw and U(-1.5, 1.5) deg.
The noisy increments are composed (dead reckoning) from the first pose (= odom origin).
Random draws: numpy.random.default_rng(seed); per step, in this order, one uniform
for the translation scale, one for the relative yaw error, one for the absolute yaw
error (three draws per step even when a term is unused), so a given seed always gives
the same trajectory.
"""
from __future__ import annotations

import math
from pathlib import Path
from typing import Sequence

import numpy as np

from .geometry import Pose, between, compose

TRANSLATION_FRACTION = 0.10
YAW_FRACTION = 0.10
YAW_ABS_RAD = math.radians(1.5)


def increments(poses: Sequence[Pose]) -> list[Pose]:
    return [between(a, b) for a, b in zip(poses[:-1], poses[1:])]


def dead_reckon(steps: Sequence[Pose]) -> list[Pose]:
    out: list[Pose] = [(0.0, 0.0, 0.0)]
    for step in steps:
        out.append(compose(out[-1], step))
    return out


def noisy_increments(steps: Sequence[Pose], seed: int) -> list[Pose]:
    rng = np.random.default_rng(seed)
    noisy = []
    for dx, dy, dyaw in steps:
        draws = rng.uniform(-1.0, 1.0, size=3)
        scale = 1.0 + TRANSLATION_FRACTION * draws[0]
        err_rel = YAW_FRACTION * draws[1] * dyaw
        err_abs = YAW_ABS_RAD * draws[2]
        err = err_rel if abs(err_rel) > abs(err_abs) else err_abs
        noisy.append((dx * scale, dy * scale, dyaw + err))
    return noisy


def odometry(groundtruth: Sequence[Pose], seed: int | None) -> list[Pose]:
    """Odometry trajectory (odom frame = map at frame 1); exact when seed is None.
    `groundtruth` must start at the identity (map frame = first pose)."""
    steps = increments(groundtruth)
    if seed is not None:
        steps = noisy_increments(steps, seed)
    return dead_reckon(steps)


def write_thesis_odometry(path: Path, odom: Sequence[Pose]) -> None:
    """odometry.txt: frame count, then per frame "distance_mm angle_deg" of the
    translation since the previous frame, angle in the map (odom) frame from +x
    towards +y; the first frame's line is "0.0 0.0"."""
    lines = [str(len(odom)), "0.0 0.0"]
    for a, b in zip(odom[:-1], odom[1:]):
        dx, dy = (b[0] - a[0]) * 1000.0, (b[1] - a[1]) * 1000.0
        dist = math.hypot(dx, dy)
        angle = math.degrees(math.atan2(dy, dx)) if dist > 0.0 else 0.0
        lines.append(f"{dist:.9f} {angle:.12f}")
    Path(path).write_text("\n".join(lines) + "\n")


def read_thesis_odometry(path: Path) -> list[tuple[float, float]]:
    rows = Path(path).read_text().split("\n")
    count = int(rows[0])
    pairs = [tuple(float(v) for v in r.split()) for r in rows[1:1 + count]]
    if len(pairs) != count:
        raise ValueError(f"{path}: expected {count} lines")
    return pairs
