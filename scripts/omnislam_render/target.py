"""A printed chessboard seen by the rig, for the target calibration (issue 12): boards held
round the robot and laid on the floor, in known poses, rendered through a rig with known
misalignments so the fit's result can be checked against the truth.

Scene units are millimetres in the camera frame (pov.py): the board is placed by its pose
T_camera_board directly. Its inner corner (0, 0) is the board frame's origin, x along its
corners' rows, the printed face at z = 0 (the squares stand 0.3 mm proud of a white sheet).
"""
from __future__ import annotations

import math
import random
from dataclasses import dataclass

from . import mirror as M
from . import pov
from .scene import level_tilt_transform

CAMERA_HEIGHT_MM = 1000.0


@dataclass(frozen=True)
class Board:
    squares_x: int = 8
    squares_y: int = 6
    square_mm: float = 45.0
    margin_mm: float = 20.0


@dataclass(frozen=True)
class View:
    rotation: tuple[tuple[float, float, float], ...]  # rows of R in T_camera_board
    translation_mm: tuple[float, float, float]
    on_floor: bool


def _rot_z(a: float) -> list[list[float]]:
    c, s = math.cos(a), math.sin(a)
    return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]


def _columns(x, y, z) -> tuple[tuple[float, float, float], ...]:
    return tuple((x[i], y[i], z[i]) for i in range(3))


def _cross(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def _place(rotation, centre_mm, board: Board) -> tuple[float, float, float]:
    """The translation that puts the board's middle corner at centre_mm."""
    half = ((board.squares_x - 2) * board.square_mm / 2.0, (board.squares_y - 2) * board.square_mm / 2.0, 0.0)
    return tuple(centre_mm[i] - sum(rotation[i][k] * half[k] for k in range(3)) for i in range(3))


def held_view(board: Board, azimuth: float, rng: random.Random) -> View:
    """Held about 0.8 m from the axis and 0.3-0.7 m below the camera, facing the axis and
    leaning back to face the mirror, turned a little about its normal."""
    rng_range = 800.0 + 150.0 * rng.uniform(-1, 1)
    height = -500.0 + 200.0 * rng.uniform(-1, 1)
    lean = math.radians(35.0 + 15.0 * rng.uniform(-1, 1))
    roll = math.radians(20.0 * rng.uniform(-1, 1))
    radial = (math.cos(azimuth), math.sin(azimuth), 0.0)
    tangential = (-math.sin(azimuth), math.cos(azimuth), 0.0)
    z = (radial[0] * math.cos(lean), radial[1] * math.cos(lean), -math.sin(lean))
    # x: the tangent turned by roll about z (Rodrigues; the tangent is perpendicular to z).
    zx = _cross(z, tangential)
    x = tuple(tangential[i] * math.cos(roll) + zx[i] * math.sin(roll) for i in range(3))
    rotation = _columns(x, _cross(z, x), z)
    centre = (rng_range * radial[0], rng_range * radial[1], height)
    return View(rotation, _place(rotation, centre, board), False)


def floor_view(board: Board, azimuth: float, rng: random.Random) -> View:
    """Lying on the floor (printed face up) 0.8-1.2 m from the axis, turned any way."""
    rng_range = 1000.0 + 200.0 * rng.uniform(-1, 1)
    rotation = tuple(tuple(row) for row in _rot_z(math.pi * rng.uniform(-1, 1)))
    centre = (rng_range * math.cos(azimuth), rng_range * math.sin(azimuth), -CAMERA_HEIGHT_MM)
    return View(rotation, _place(rotation, centre, board), True)


def views(board: Board, held: int, on_floor: int, seed: int) -> list[View]:
    rng = random.Random(seed)
    out = [held_view(board, 2 * math.pi * (i + 0.3) / held, rng) for i in range(held)]
    out += [floor_view(board, 2 * math.pi * (i + 0.7) / on_floor, rng) for i in range(on_floor)]
    return out


def board_pov(board: Board, view: View) -> str:
    s = board.square_mm
    x0, y0 = -s, -s
    x1, y1 = (board.squares_x - 1) * s, (board.squares_y - 1) * s
    m = board.margin_mm
    r, t = view.rotation, view.translation_mm
    entries = [r[j][i] for i in range(3) for j in range(3)] + list(t)
    # checker: unit cubes alternate; scaled to the squares and shifted half a square in z so
    # the printed face (z = 0) lies inside one layer.
    return (
        "union {\n"
        f"  box {{ {pov.vec(x0 - m, y0 - m, -0.2)}, {pov.vec(x1 + m, y1 + m, 0.2)}\n"
        "        pigment { rgb 0.92 } finish { ambient 1 diffuse 0 } }\n"
        f"  box {{ {pov.vec(x0, y0, -0.3)}, {pov.vec(x1, y1, 0.3)}\n"
        "        pigment { checker rgb 0.92, rgb 0.06 scale " + pov.num(s) +
        f" translate {pov.vec(0, 0, s / 2)} }} finish {{ ambient 1 diffuse 0 }} }}\n"
        "  matrix <" + ", ".join(pov.num(v) for v in entries) + ">\n}\n"
    )


def scene(board: Board, view: View, rig: M.Rig) -> str:
    """A plain grey room lit evenly (bright enough for the rim method's steps), the board,
    the camera and mirror of `rig`. The room and the board are placed in the level frame
    (the floor at z = -camera height), turned into the camera's when the rig is off level
    (rig.level_tilt_deg)."""
    world = (
        f"plane {{ z, {pov.num(-CAMERA_HEIGHT_MM)} pigment {{ rgb 0.45 }} finish {{ ambient 1 diffuse 0 }} }}\n"
        "sphere { <0,0,0>, 20000 pigment { rgb 0.6 } finish { ambient 1 diffuse 0 } }\n"
        + board_pov(board, view))
    if rig.level_tilt_deg != (0.0, 0.0):
        world = "union {\n" + world + level_tilt_transform(rig.level_tilt_deg) + "\n}\n"
    return (
        "#version 3.7;\n"
        "global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }\n"
        + world + pov.camera_block(rig) + pov.mirror_block(rig)
    )
