"""Planar poses (x, y, yaw) and the TUM trajectory format."""
from __future__ import annotations

import math
from pathlib import Path
from typing import Iterable, Sequence

Pose = tuple[float, float, float]  # x, y (metres), yaw (radians)


def wrap(angle: float) -> float:
    """Angle wrapped to (-pi, pi]."""
    wrapped = math.atan2(math.sin(angle), math.cos(angle))
    return math.pi if wrapped == -math.pi else wrapped


def compose(a: Pose, b: Pose) -> Pose:
    """a * b: pose b expressed in a's frame, returned in a's parent frame."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], wrap(a[2] + b[2]))


def inverse(a: Pose) -> Pose:
    c, s = math.cos(a[2]), math.sin(a[2])
    return (-(c * a[0] + s * a[1]), s * a[0] - c * a[1], wrap(-a[2]))


def between(a: Pose, b: Pose) -> Pose:
    """Increment a^-1 * b: pose b in the frame of pose a."""
    return compose(inverse(a), b)


def _clean(value: float, digits: int) -> str:
    """Fixed-point text without a negative zero."""
    return f"{round(value, digits) + 0.0:.{digits}f}"


def write_tum(path: Path, poses: Sequence[Pose], rate_hz: float, header: str) -> None:
    """TUM lines "t x y z qx qy qz qw" (metres; z = 0, base_link on the floor)."""
    lines = [f"# {ln}" for ln in header.splitlines()]
    lines.append("# t x y z qx qy qz qw")
    for i, (x, y, yaw) in enumerate(poses):
        t = i / rate_hz
        qz, qw = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
        lines.append(f"{t:.6f} {_clean(x, 12)} {_clean(y, 12)} 0.0 0.0 0.0 {_clean(qz, 15)} {_clean(qw, 15)}")
    Path(path).write_text("\n".join(lines) + "\n")


def read_tum(path: Path) -> list[tuple[float, Pose]]:
    """[(t, (x, y, yaw))] of a planar TUM file."""
    out = []
    for line in Path(path).read_text().splitlines():
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        t, x, y, _z, _qx, _qy, qz, qw = (float(v) for v in line.split())
        out.append((t, (x, y, 2.0 * math.atan2(qz, qw))))
    return out


def relative_to_first(poses: Iterable[Pose]) -> list[Pose]:
    poses = list(poses)
    first_inv = inverse(poses[0])
    return [compose(first_inv, p) for p in poses]
