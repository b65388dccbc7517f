"""Room scenes from a few primitives: POV-Ray text and the ground-truth floor plan.

Coordinates are in metres in the room (world) frame, z up, floor at z = 0; the POV
text is in millimetres.  Each frame places the room in the camera frame (pinhole at
the origin, camera_height_m above the floor) by the inverse robot pose, so only the
room moves between frames.
"""
from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from typing import Sequence

from .geometry import Pose
from .pov import num, vec

Colour = tuple[float, float, float]
Segment = tuple[float, float, float, float]

CIRCLE_SIDES = 24
WALL_THICKNESS = 0.10
MATT = "finish { ambient 0.35 diffuse 0.65 }"


def _mm(*xs: float) -> list[float]:
    return [x * 1000.0 for x in xs]


def _rgb(c: Colour) -> str:
    return f"rgb {vec(*c)}"


def polygon_segments(points: Sequence[tuple[float, float]]) -> list[Segment]:
    return [(*points[i], *points[(i + 1) % len(points)]) for i in range(len(points))]


def circle_segments(cx: float, cy: float, r: float, sides: int = CIRCLE_SIDES) -> list[Segment]:
    """Polygon with `sides` vertices on the circle (a cylinder's plan outline)."""
    pts = [(cx + r * math.cos(2 * math.pi * i / sides), cy + r * math.sin(2 * math.pi * i / sides))
           for i in range(sides)]
    return polygon_segments(pts)


@dataclass
class Box:
    name: str
    lo: tuple[float, float, float]
    hi: tuple[float, float, float]
    colour: Colour

    def pov(self) -> str:
        return (f"box {{ {vec(*_mm(*self.lo))}, {vec(*_mm(*self.hi))} "
                f"pigment {{ {_rgb(self.colour)} }} {MATT} }}  // {self.name}")

    def outline(self) -> list[Segment]:
        (x0, y0, _), (x1, y1, _) = self.lo, self.hi
        return polygon_segments([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])

    def distance_xy(self, x: float, y: float) -> float:
        dx = max(self.lo[0] - x, 0.0, x - self.hi[0])
        dy = max(self.lo[1] - y, 0.0, y - self.hi[1])
        return math.hypot(dx, dy)


@dataclass
class Cylinder:
    name: str
    centre: tuple[float, float]
    radius: float
    z0: float
    z1: float
    colour: Colour

    def pov(self) -> str:
        cx, cy = self.centre
        return (f"cylinder {{ {vec(*_mm(cx, cy, self.z0))}, {vec(*_mm(cx, cy, self.z1))}, "
                f"{num(self.radius * 1000)} pigment {{ {_rgb(self.colour)} }} {MATT} }}  // {self.name}")

    def outline(self) -> list[Segment]:
        return circle_segments(*self.centre, self.radius)

    def distance_xy(self, x: float, y: float) -> float:
        return max(math.hypot(x - self.centre[0], y - self.centre[1]) - self.radius, 0.0)


@dataclass
class Sphere:
    name: str
    centre: tuple[float, float, float]
    radius: float
    colour: Colour

    def pov(self) -> str:
        return (f"sphere {{ {vec(*_mm(*self.centre))}, {num(self.radius * 1000)} "
                f"pigment {{ {_rgb(self.colour)} }} {MATT} }}  // {self.name}")

    def outline(self) -> list[Segment]:
        return circle_segments(self.centre[0], self.centre[1], self.radius)

    def distance_xy(self, x: float, y: float) -> float:
        return max(math.hypot(x - self.centre[0], y - self.centre[1]) - self.radius, 0.0)


@dataclass
class Patch:
    """A coloured rectangle flush with a wall (door, window): painted, so the wall
    face, its floor contact and the floor plan are unchanged."""
    name: str
    wall: int            # index of the wall (edge i of the room polygon)
    s0: float            # extent along the wall from its first vertex (m)
    s1: float
    z0: float
    z1: float
    colour: Colour


@dataclass
class Room:
    name: str
    outline: list[tuple[float, float]]      # interior polygon, counter-clockwise, axis-aligned
    wall_colours: list[Colour]
    floor_colour: Colour
    ceiling_colour: Colour
    height: float
    objects: list = field(default_factory=list)
    patches: list[Patch] = field(default_factory=list)
    lights: list[tuple[tuple[float, float, float], float]] = field(default_factory=list)

    # ---------------------------------------------------------------- geometry
    def walls(self) -> list[Segment]:
        return polygon_segments(self.outline)

    def floorplan(self) -> list[Segment]:
        segs = list(self.walls())
        for obj in self.objects:
            segs.extend(obj.outline())
        return segs

    def clearance(self, x: float, y: float) -> tuple[float, str]:
        """Smallest plan distance (m) from (x, y) to a wall or object, and its name."""
        best = (math.inf, "")
        for i, (x1, y1, x2, y2) in enumerate(self.walls()):
            dx, dy = x2 - x1, y2 - y1
            t = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / (dx * dx + dy * dy)))
            d = math.hypot(x - x1 - t * dx, y - y1 - t * dy)
            best = min(best, (d, f"wall {i}"))
        for obj in self.objects:
            best = min(best, (obj.distance_xy(x, y), obj.name))
        return best

    # ---------------------------------------------------------------- POV text
    def _wall_boxes(self) -> list[str]:
        out = []
        t = WALL_THICKNESS
        for i, (x1, y1, x2, y2) in enumerate(self.walls()):
            if x1 != x2 and y1 != y2:
                raise ValueError("only axis-aligned walls are supported")
            dx, dy = (x2 - x1), (y2 - y1)
            length = math.hypot(dx, dy)
            ux, uy = dx / length, dy / length
            nx, ny = uy, -ux          # outward normal of a counter-clockwise polygon
            ax, ay = x1 - ux * t, y1 - uy * t
            bx, by = x2 + ux * t + nx * t, y2 + uy * t + ny * t
            lo = (min(ax, bx), min(ay, by), -t)
            hi = (max(ax, bx), max(ay, by), self.height + t)
            pigment = _rgb(self.wall_colours[i % len(self.wall_colours)])
            for p in (p for p in self.patches if p.wall == i):
                # the patch region, thicker than the wall, expressed as an object pattern
                pa = (x1 + ux * p.s0 - nx * t, y1 + uy * p.s0 - ny * t)
                pb = (x1 + ux * p.s1 + nx * 2 * t, y1 + uy * p.s1 + ny * 2 * t)
                plo = (min(pa[0], pb[0]), min(pa[1], pb[1]), p.z0)
                phi = (max(pa[0], pb[0]), max(pa[1], pb[1]), p.z1)
                pigment = (f"object {{ box {{ {vec(*_mm(*plo))}, {vec(*_mm(*phi))} }} "
                           f"pigment {{ {pigment} }} pigment {{ {_rgb(p.colour)} }} }}")
            out.append(f"box {{ {vec(*_mm(*lo))}, {vec(*_mm(*hi))} pigment {{ {pigment} }} "
                       f"{MATT} }}  // wall {i}")
        return out

    def pov_body(self) -> str:
        """The room in world coordinates (mm), without the pose transform."""
        parts = [
            f"plane {{ z, 0 pigment {{ {_rgb(self.floor_colour)} }} {MATT} }}  // floor",
            f"plane {{ -z, {num(-self.height * 1000)} pigment {{ {_rgb(self.ceiling_colour)} }} {MATT} }}  // ceiling",
        ]
        parts += self._wall_boxes()
        parts += [obj.pov() for obj in self.objects]
        parts += [f"light_source {{ {vec(*_mm(*pos))} color rgb {num(power)} shadowless }}"
                  for pos, power in self.lights]
        return "\n  ".join(parts)

    def scene_hash(self) -> str:
        return hashlib.sha256(self.pov_body().encode()).hexdigest()[:16]


def world_to_camera_matrix(pose: Pose, camera_height_m: float) -> str:
    """POV `matrix` taking world (room) coordinates in mm to the camera frame of the
    robot at `pose` (x, y in m, yaw in rad): p_cam = R(yaw)^T (p - t) - h z.
    POV applies matrix <m00,m01,m02, m10,...,m32> to a row vector: x' = x m00 + y m10 + z m20 + m30."""
    x, y, yaw = pose
    c, s = math.cos(yaw), math.sin(yaw)
    tx, ty = x * 1000.0, y * 1000.0
    m = [c, -s, 0.0,
         s, c, 0.0,
         0.0, 0.0, 1.0,
         -(c * tx + s * ty), s * tx - c * ty, -camera_height_m * 1000.0]
    return "matrix " + vec(*m)


def frame_scene(room: Room, pose: Pose, camera_height_m: float, camera: str, mirror: str) -> str:
    return (
        "#version 3.7;\n"
        "global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }\n"
        f"// room {room.name}, robot pose x={pose[0]!r} m y={pose[1]!r} m yaw={pose[2]!r} rad\n"
        "union {\n  " + room.pov_body() + "\n"
        f"  {world_to_camera_matrix(pose, camera_height_m)}\n}}\n"
        + camera + mirror
    )
