"""Small readers used by the dataset tests."""
from __future__ import annotations

import csv
import math
from pathlib import Path

from omnislam_render.geometry import between, read_tum

TRAJECTORIES = Path(__file__).resolve().parents[2] / "scripts" / "omnislam_render" / "data" / "trajectories.csv"


def table_mm(table: str) -> list[tuple[float, float]]:
    rows = []
    with open(TRAJECTORIES) as fh:
        for row in csv.reader(ln for ln in fh if not ln.startswith("#")):
            if row and row[0] == table:
                rows.append((int(row[1]), float(row[2]), float(row[3])))
    return [(x, y) for _, x, y in sorted(rows)]


def poses(path: Path):
    return [p for _, p in read_tum(path)]


def times(path: Path):
    return [t for t, _ in read_tum(path)]


def steps(traj):
    return [between(a, b) for a, b in zip(traj[:-1], traj[1:])]


def angle_diff(a: float, b: float) -> float:
    return math.atan2(math.sin(a - b), math.cos(a - b))
