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


def inset_outline(points: Sequence[tuple[float, float]], depth: float) -> list[tuple[float, float]]:
    """The axis-aligned, counter-clockwise polygon moved inwards by `depth` on every edge."""
    out = []
    n = len(points)
    for i in range(n):
        (xp, yp), (x, y), (xn, yn) = points[i - 1], points[i], points[(i + 1) % n]
        shift = [0.0, 0.0]
        for (ax, ay), (bx, by) in (((xp, yp), (x, y)), ((x, y), (xn, yn))):
            length = math.hypot(bx - ax, by - ay)
            # inward normal of a counter-clockwise edge: the edge direction turned left
            shift[0] += -(by - ay) / length * depth
            shift[1] += (bx - ax) / length * depth
        out.append((x + shift[0], y + shift[1]))
    return out


def rectangle_segments(lo: Sequence[float], hi: Sequence[float]) -> list[Segment]:
    """The plan outline of an axis-aligned rectangle from its (x, y) corners."""
    (x0, y0), (x1, y1) = lo[:2], hi[:2]
    return polygon_segments([(x0, y0), (x1, y0), (x1, y1), (x0, y1)])


def rectangle_distance(lo: Sequence[float], hi: Sequence[float], x: float, y: float) -> float:
    """Plan distance from (x, y) to an axis-aligned rectangle (0 inside it)."""
    dx = max(lo[0] - x, 0.0, x - hi[0])
    dy = max(lo[1] - y, 0.0, y - hi[1])
    return math.hypot(dx, dy)


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

    def pov(self, finish: str = MATT) -> str:
        return (f"box {{ {vec(*_mm(*self.lo))}, {vec(*_mm(*self.hi))} "
                f"pigment {{ {_rgb(self.colour)} }} {finish} }}  // {self.name}")

    def outline(self) -> list[Segment]:
        return rectangle_segments(self.lo[:2], self.hi[:2])

    def distance_xy(self, x: float, y: float) -> float:
        return rectangle_distance(self.lo[:2], self.hi[:2], x, y)


@dataclass
class Cylinder:
    name: str
    centre: tuple[float, float]
    radius: float
    z0: float
    z1: float
    colour: Colour

    def pov(self, finish: str = MATT) -> str:
        cx, cy = self.centre
        return (f"cylinder {{ {vec(*_mm(cx, cy, self.z0))}, {vec(*_mm(cx, cy, self.z1))}, "
                f"{num(self.radius * 1000)} pigment {{ {_rgb(self.colour)} }} {finish} }}  // {self.name}")

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

    def pov(self, finish: str = MATT) -> str:
        return (f"sphere {{ {vec(*_mm(*self.centre))}, {num(self.radius * 1000)} "
                f"pigment {{ {_rgb(self.colour)} }} {finish} }}  // {self.name}")

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
class AreaLamp:
    """A ceiling panel or pendant: a rectangular area light (soft shadows), sampled on a
    fixed grid (no jitter, so renders stay deterministic), with 1/d^2 falloff."""
    centre: tuple[float, float, float]
    size: tuple[float, float]   # extent along x and y (m)
    power: float
    samples: int = 5

    def pov(self) -> str:
        sx, sy = _mm(*self.size)
        return (f"light_source {{ {vec(*_mm(*self.centre))} color rgb {num(self.power)} "
                f"area_light {vec(sx, 0, 0)}, {vec(0, sy, 0)}, {self.samples}, {self.samples} adaptive 1 "
                f"fade_distance 2500 fade_power 2 }}")


@dataclass
class Sun:
    """Sunlight entering through a window (a Patch of the room): a parallel light from
    outside, restricted to the window opening, drawing a bright patch on the floor."""
    window: str            # name of the Patch it shines through
    azimuth_deg: float     # direction towards the sun, in the room frame
    elevation_deg: float
    power: float


@dataclass
class Rug:
    """A thin rug or mat lying on the floor: floor texture, not an obstacle (not in the
    floor plan)."""
    name: str
    lo: tuple[float, float]
    hi: tuple[float, float]
    thickness: float
    texture: str           # POV texture text, millimetres, room frame


@dataclass
class Pit:
    """A part of the floor lower than the rest (a sunken seating area, a step down, a stairwell
    without its railing), its bottom and sides in the floor's material: a drop the robot must
    not drive over, so the floor plan draws its edge."""
    name: str
    lo: tuple[float, float]
    hi: tuple[float, float]
    depth: float
    ramp_m: float = 0.0  # a ramp down from its lo-x edge, this long (0: none)

    def outline(self) -> list[Segment]:
        return rectangle_segments(self.lo, self.hi)

    def ramp_pov(self, texture: str) -> str:
        """The ramp's wedge, in the floor's material: from the floor's level at lo-x down to
        the pit's bottom ramp_m along +x, across the pit's width."""
        (x0, y0), (_, y1) = self.lo, self.hi
        top, low = _mm(x0, 0.0), _mm(x0 + self.ramp_m, -self.depth)
        corner = _mm(x0, -self.depth)
        points = ", ".join(f"<{num(a)}, {num(b)}>" for a, b in (top, low, corner, top))
        return (f"prism {{ linear_sweep linear_spline {num(y0 * 1000.0)}, {num(y1 * 1000.0)}, 4, {points} "
                f"{texture} }}  // {self.name}: ramp")

    def distance_xy(self, x: float, y: float) -> float:
        return rectangle_distance(self.lo, self.hi, x, y)


@dataclass
class Cable:
    """A cable lying loose on the floor along a polyline (x, y in m): a dark or light line
    a few millimetres high that a robot drives over; floor texture, not an obstacle (not in
    the floor plan)."""
    name: str
    points: list[tuple[float, float]]
    radius: float
    colour: Colour

    def pov(self, finish: str = MATT) -> str:
        r = num(self.radius * 1000)
        knots = ", ".join(f"{vec(*_mm(x, y, self.radius))}, {r}" for x, y in self.points)
        return (f"sphere_sweep {{ linear_spline {len(self.points)}, {knots} "
                f"pigment {{ {_rgb(self.colour)} }} {finish} }}  // {self.name}")


@dataclass
class Skirting:
    """Skirting boards along every wall: the floor contact moves to their face, which the
    floor plan follows."""
    height: float
    depth: float
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
    # Realistic rooms (all optional; the flat-shaded rooms leave them unset).
    floor_texture: str | None = None      # POV texture text replacing floor_colour
    finish: str = MATT
    area_lamps: list[AreaLamp] = field(default_factory=list)
    sun: Sun | None = None
    rugs: list[Rug] = field(default_factory=list)
    skirting: Skirting | None = None
    cables: list[Cable] = field(default_factory=list)
    pits: list[Pit] = field(default_factory=list)

    # ---------------------------------------------------------------- geometry
    def walls(self) -> list[Segment]:
        return polygon_segments(self.outline)

    def inner_faces(self) -> list[Segment]:
        """Where the walls meet the floor: the walls, or the skirting boards' faces."""
        if self.skirting is None:
            return self.walls()
        return polygon_segments(inset_outline(self.outline, self.skirting.depth))

    def floorplan(self) -> list[Segment]:
        segs = list(self.inner_faces())
        for obj in [*self.objects, *self.pits]:
            segs.extend(obj.outline())
        return segs

    def clearance(self, x: float, y: float) -> tuple[float, str]:
        """Smallest plan distance (m) from (x, y) to a wall or object, and its name."""
        best = (math.inf, "")
        for i, (x1, y1, x2, y2) in enumerate(self.inner_faces()):
            dx, dy = x2 - x1, y2 - y1
            t = max(0.0, min(1.0, ((x - x1) * dx + (y - y1) * dy) / (dx * dx + dy * dy)))
            d = math.hypot(x - x1 - t * dx, y - y1 - t * dy)
            best = min(best, (d, f"wall {i}"))
        for obj in [*self.objects, *self.pits]:
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
            # Realistic rooms: walls cast no shadow, so the sun reaches the room through a
            # window that is only painted on the wall (the light is restricted to it).
            shadow = " no_shadow" if self.sun is not None else ""
            out.append(f"box {{ {vec(*_mm(*lo))}, {vec(*_mm(*hi))} pigment {{ {pigment} }} "
                       f"{self.finish}{shadow} }}  // wall {i}")
        return out

    def _patch_box(self, patch: Patch, thickness: float) -> tuple[tuple, tuple]:
        x1, y1, x2, y2 = self.walls()[patch.wall]
        length = math.hypot(x2 - x1, y2 - y1)
        ux, uy = (x2 - x1) / length, (y2 - y1) / length
        nx, ny = uy, -ux
        pa = (x1 + ux * patch.s0, y1 + uy * patch.s0)
        pb = (x1 + ux * patch.s1 + nx * thickness, y1 + uy * patch.s1 + ny * thickness)
        return ((min(pa[0], pb[0]), min(pa[1], pb[1]), patch.z0),
                (max(pa[0], pb[0]), max(pa[1], pb[1]), patch.z1))

    def _sun_pov(self) -> str:
        sun = self.sun
        patch = next(p for p in self.patches if p.name == sun.window)
        lo, hi = self._patch_box(patch, WALL_THICKNESS)
        centre = [(a + b) / 2 for a, b in zip(lo, hi)]
        az, el = math.radians(sun.azimuth_deg), math.radians(sun.elevation_deg)
        towards = (math.cos(el) * math.cos(az), math.cos(el) * math.sin(az), math.sin(el))
        source = [c + 0.8 * t for c, t in zip(centre, towards)]
        return (f"light_source {{ {vec(*_mm(*source))} color rgb {num(sun.power)} parallel "
                f"point_at {vec(*_mm(*centre))} projected_through {{ box {{ {vec(*_mm(*lo))}, "
                f"{vec(*_mm(*hi))} }} }} }}  // sun through {sun.window}")

    def _skirting_pov(self) -> list[str]:
        # A board between each wall and its face (inner_faces(), in the same order as walls()).
        sk = self.skirting
        out = []
        for (x1, y1, x2, y2), (a1, b1, a2, b2) in zip(self.walls(), self.inner_faces()):
            lo = (min(x1, x2, a1, a2), min(y1, y2, b1, b2), 0.0)
            hi = (max(x1, x2, a1, a2), max(y1, y2, b1, b2), sk.height)
            out.append(f"box {{ {vec(*_mm(*lo))}, {vec(*_mm(*hi))} pigment {{ {_rgb(sk.colour)} }} "
                       f"{self.finish} }}  // skirting")
        return out

    def pov_body(self) -> str:
        """The room in world coordinates (mm), without the pose transform."""
        floor = self.floor_texture or f"pigment {{ {_rgb(self.floor_colour)} }} {self.finish}"
        ceiling_shadow = " no_shadow" if self.sun is not None else ""
        floor_solid = f"plane {{ z, 0 {floor} }}  // floor"
        if self.pits:  # the floor with the pits cut out: their bottoms and sides in its material
            cuts = " ".join(f"box {{ {vec(*_mm(*pit.lo, -pit.depth))}, {vec(*_mm(*pit.hi, 1.0))} }}"
                            for pit in self.pits)
            floor_solid = f"difference {{ plane {{ z, 0 }} {cuts} {floor} }}  // floor with {len(self.pits)} pit(s)"
            floor_solid += "".join("\n" + pit.ramp_pov(floor) for pit in self.pits if pit.ramp_m > 0.0)
        parts = [
            floor_solid,
            f"plane {{ -z, {num(-self.height * 1000)} pigment {{ {_rgb(self.ceiling_colour)} }} "
            f"{self.finish}{ceiling_shadow} }}  // ceiling",
        ]
        parts += self._wall_boxes()
        if self.skirting is not None:
            parts += self._skirting_pov()
        parts += [f"box {{ {vec(*_mm(*rug.lo, 0.0))}, {vec(*_mm(*rug.hi, rug.thickness))} {rug.texture} }}"
                  f"  // {rug.name}" for rug in self.rugs]
        parts += [cable.pov(self.finish) for cable in self.cables]
        parts += [obj.pov(self.finish) for obj in self.objects]
        parts += [f"light_source {{ {vec(*_mm(*pos))} color rgb {num(power)} shadowless }}"
                  for pos, power in self.lights]
        parts += [lamp.pov() for lamp in self.area_lamps]
        if self.sun is not None:
            parts.append(self._sun_pov())
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


def person_pov(x: float, y: float, heading: float, colour: Colour = (0.22, 0.24, 0.30)) -> str:
    """A standing or walking person at (x, y) in the room frame (m), facing `heading` (rad):
    two legs 0.85 m high 0.2 m apart, a torso to 1.45 m, a head; dark clothes."""
    lx, ly = -math.sin(heading) * 0.1, math.cos(heading) * 0.1  # half the stance, sideways
    legs = [Cylinder(f"leg {k}", (x + sign * lx, y + sign * ly), 0.06, 0.0, 0.85, colour)
            for k, sign in enumerate((-1.0, 1.0))]
    torso = Cylinder("torso", (x, y), 0.17, 0.85, 1.45, colour)
    head = f"sphere {{ {vec(*_mm(x, y, 1.6))}, 100 pigment {{ rgb <0.55, 0.42, 0.35> }} {MATT} }}  // head"
    return "\n  ".join([*(c.pov() for c in (*legs, torso)), head])


def level_tilt_transform(level_tilt_deg: tuple[float, float]) -> str:
    """POV transform taking the level camera frame into a rig turned off level by
    R = Ry(y) Rx(x) (mirror.Rig.level_tilt_deg): p_camera = R^T p_level, Ry(-y) first.
    POV's rotate applies the right-handed matrix to the coordinates as written."""
    x, y = level_tilt_deg
    if (x, y) == (0.0, 0.0):
        return ""
    return f" rotate {vec(0.0, -y, 0.0)} rotate {vec(-x, 0.0, 0.0)}"


def frame_scene(room: Room, pose: Pose, camera_height_m: float, camera: str, mirror: str,
                extra: str = "", level_tilt_deg: tuple[float, float] = (0.0, 0.0)) -> str:
    """One frame: the room (and `extra`, objects of this frame alone in room coordinates, mm)
    moved into the camera frame of the robot at `pose` (turned off level by `level_tilt_deg`)."""
    return (
        "#version 3.7;\n"
        "global_settings { assumed_gamma 1.0 ambient_light rgb 1 max_trace_level 5 }\n"
        f"// room {room.name}, robot pose x={pose[0]!r} m y={pose[1]!r} m yaw={pose[2]!r} rad\n"
        "union {\n  " + room.pov_body() + ("\n  " + extra if extra else "") + "\n"
        f"  {world_to_camera_matrix(pose, camera_height_m)}{level_tilt_transform(level_tilt_deg)}\n}}\n"
        + camera + mirror
    )


def _moved_left(segment: Segment, distance: float) -> Segment:
    """An axis-aligned segment moved `distance` to its left (the free side of a boundary)."""
    x1, y1, x2, y2 = segment
    length = math.hypot(x2 - x1, y2 - y1)
    nx, ny = -(y2 - y1) / length * distance, (x2 - x1) / length * distance
    return (x1 + nx, y1 + ny, x2 + nx, y2 + ny)


def free_space_boundary(interior: tuple[float, float, float, float], solids: Sequence[Box]) -> list[Segment]:
    """Where the free floor meets the solids, as maximal segments with the free side on their
    left (counter-clockwise around the free space, like a room outline).

    `interior` = (x0, y0, x1, y1), the inside of the outer walls; `solids` are the interior
    walls and blocks (axis-aligned boxes standing on the floor); outside the interior counts
    as solid.  The plan is cut into the cells of the grid through every box edge, each cell
    free or solid; cell sides between a free and a solid cell are joined along their line."""
    x0, y0, x1, y1 = interior
    xs = sorted({x0, x1, *(min(max(v, x0), x1) for b in solids for v in (b.lo[0], b.hi[0]))})
    ys = sorted({y0, y1, *(min(max(v, y0), y1) for b in solids for v in (b.lo[1], b.hi[1]))})

    def free(i: int, j: int) -> bool:
        if not (0 <= i < len(xs) - 1 and 0 <= j < len(ys) - 1):
            return False
        cx, cy = 0.5 * (xs[i] + xs[i + 1]), 0.5 * (ys[j] + ys[j + 1])
        return not any(b.lo[0] < cx < b.hi[0] and b.lo[1] < cy < b.hi[1] for b in solids)

    segments: list[Segment] = []
    # Horizontal sides (y = ys[j]) between cell rows j-1 and j; free above -> run towards +x.
    for j in range(len(ys)):
        run = None      # (start x, direction)
        for i in range(len(xs)):
            kind = None
            if i < len(xs) - 1:
                below, above = free(i, j - 1), free(i, j)
                kind = +1 if above and not below else (-1 if below and not above else None)
            if run is not None and (kind != run[1]):
                a, b = (run[0], xs[i]) if run[1] > 0 else (xs[i], run[0])
                segments.append((a, ys[j], b, ys[j]))
                run = None
            if kind is not None and run is None:
                run = (xs[i], kind)
    # Vertical sides (x = xs[i]) between cell columns i-1 and i; free on the left of the
    # direction: free to the west -> run towards +y, free to the east -> towards -y.
    for i in range(len(xs)):
        run = None
        for j in range(len(ys)):
            kind = None
            if j < len(ys) - 1:
                west, east = free(i - 1, j), free(i, j)
                kind = +1 if west and not east else (-1 if east and not west else None)
            if run is not None and (kind != run[1]):
                a, b = (run[0], ys[j]) if run[1] > 0 else (ys[j], run[0])
                segments.append((xs[i], a, xs[i], b))
                run = None
            if kind is not None and run is None:
                run = (ys[j], kind)
    return segments


@dataclass
class Floor(Room):
    """A building floor: the outer walls around `outline` (an axis-aligned rectangle, the
    inside of the outer walls) plus interior walls and solid blocks (`solids`, boxes from
    below the floor to above the ceiling, each with its own colour).  The walls of the floor
    plan are where the free floor meets them (free_space_boundary); doors are gaps between
    wall boxes.  Box faces only ever touch solid neighbours, so no two visible surfaces are
    coincident."""
    solids: list[Box] = field(default_factory=list)

    def _interior(self) -> tuple[float, float, float, float]:
        xs = [p[0] for p in self.outline]
        ys = [p[1] for p in self.outline]
        if len(self.outline) != 4 or len(set(xs)) != 2 or len(set(ys)) != 2:
            raise ValueError("a Floor's outline is the rectangle inside its outer walls")
        return min(xs), min(ys), max(xs), max(ys)

    def walls(self) -> list[Segment]:
        return free_space_boundary(self._interior(), self.solids)

    def inner_faces(self) -> list[Segment]:
        """Where the walls meet the floor: the walls, or the skirting boards' faces."""
        if self.skirting is None:
            return self.walls()
        return [_moved_left(segment, self.skirting.depth) for segment in self.walls()]

    def _wall_boxes(self) -> list[str]:
        t = WALL_THICKNESS
        x0, y0, x1, y1 = self._interior()
        outer = [((x0 - t, y0 - t), (x1 + t, y0)), ((x1, y0), (x1 + t, y1 + t)),
                 ((x0 - t, y1), (x1, y1 + t)), ((x0 - t, y0), (x0, y1))]
        out = []
        for i, ((ax, ay), (bx, by)) in enumerate(outer):
            colour = self.wall_colours[i % len(self.wall_colours)]
            out.append(Box(f"outer wall {i}", (ax, ay, -t), (bx, by, self.height + t), colour).pov(self.finish))
        for box in self.solids:
            tall = Box(box.name, (box.lo[0], box.lo[1], -t), (box.hi[0], box.hi[1], self.height + t), box.colour)
            out.append(tall.pov(self.finish))
        return out
