"""The rooms: the thesis's simulated room (thesis.md sec. 2) and an L-shaped room
built around the real-room poses of table 3.3.  The thesis gives no object positions
or L-room outline; these layouts are ours (see the docstrings), chosen so that every
trajectory keeps >= 0.45 m from every wall and object (checked by the tests)."""
from __future__ import annotations

import math

from .scene import Box, Cylinder, Floor, Patch, Room, Sphere

# Plain, distinct colours (linear RGB).  The floor is dark so that every floor
# contact (the nearest horizontal edges) has strong contrast.
FLOOR = (0.16, 0.15, 0.14)
CEILING = (0.90, 0.90, 0.88)
WALLS = [(0.80, 0.78, 0.70), (0.70, 0.78, 0.85), (0.82, 0.74, 0.74), (0.74, 0.82, 0.72)]
CABINET = (0.55, 0.33, 0.15)
CABINET_2 = (0.20, 0.35, 0.60)
TABLE_TOP = (0.75, 0.60, 0.35)
TABLE_FOOT = (0.45, 0.45, 0.50)
PLATFORM = (0.50, 0.50, 0.20)
BOARD = (0.05, 0.30, 0.12)
SPHERE = (0.85, 0.20, 0.15)
BOXES = [(0.90, 0.65, 0.10), (0.25, 0.65, 0.70), (0.70, 0.30, 0.65), (0.55, 0.75, 0.25)]
DOOR = (0.40, 0.22, 0.10)
WINDOW = (0.45, 0.65, 0.95)


def _small_box(name: str, cx: float, cy: float, colour) -> Box:
    return Box(name, (cx - 0.2, cy - 0.2, 0.0), (cx + 0.2, cy + 0.2, 0.25), colour)


def sim_room() -> Room:
    """Thesis simulated room, room-centred: x in [-4, 4] m, y in [-2, 2] m, 3 m high.

    The table 3.1/3.2 path runs (3, 1.5) -> (3, -0.5) -> (1, -0.5) -> (0, 0) ->
    (-1, 0.5) -> (-3, 0.5) -> (-3, 1.5); the objects sit in the free space around it:
      cabinet 1   2 x 0.5 x 1.5  against the top wall, x -2.4..-0.4, y 1.5..2.0
      cabinet 2   2 x 0.5 x 1.5  against the bottom wall, x 1.0..3.0, y -2.0..-1.5
      table       top 1.0 x 0.8 (0.05 thick, 0.70..0.75 m high) centred (1.0, 1.3),
                  cylindrical column r 0.08
      platform    2.5 x 1.8 x 0.2, x -3.7..-1.2, y -1.8..0.0
      board       2.5 x 1.0, 0.05 deep, on the left wall (x -4.0..-3.95),
                  y -1.25..1.25, z 1.0..2.0
      sphere      r 0.25 on the floor at (2.0, 1.1)
      four boxes  0.4 x 0.4 x 0.25 centred 1 m from the room centre at azimuths
                  23.43, 103.43, 203.43, 283.43 deg (point-symmetric pairs, mirror-
                  symmetric about the normal of the diagonal leg, which passes
                  between them)
      door        0.9 x 2.0 painted on the top wall, x 2.0..2.9
      window      1.5 x 1.1 painted on the bottom wall, x -1.5..0.0, z 1.0..2.1
    """
    outline = [(-4.0, -2.0), (4.0, -2.0), (4.0, 2.0), (-4.0, 2.0)]  # walls: 0 bottom, 1 right, 2 top, 3 left
    boxes = []
    for k, az_deg in enumerate((23.43, 103.43, 203.43, 283.43)):
        a = math.radians(az_deg)
        boxes.append(_small_box(f"box {k + 1}", round(math.cos(a), 4), round(math.sin(a), 4), BOXES[k]))
    objects = [
        Box("cabinet 1", (-2.4, 1.5, 0.0), (-0.4, 2.0, 1.5), CABINET),
        Box("cabinet 2", (1.0, -2.0, 0.0), (3.0, -1.5, 1.5), CABINET_2),
        Box("table top", (0.5, 0.9, 0.70), (1.5, 1.7, 0.75), TABLE_TOP),
        Cylinder("table column", (1.0, 1.3), 0.08, 0.0, 0.70, TABLE_FOOT),
        Box("platform", (-3.7, -1.8, 0.0), (-1.2, 0.0, 0.2), PLATFORM),
        Box("board", (-4.0, -1.25, 1.0), (-3.95, 1.25, 2.0), BOARD),
        Sphere("sphere", (2.0, 1.1, 0.25), 0.25, SPHERE),
        *boxes,
    ]
    patches = [
        # wall 2 runs from (4, 2) to (-4, 2): s = 4 - x
        Patch("door", 2, 4.0 - 2.9, 4.0 - 2.0, 0.0, 2.0, DOOR),
        # wall 0 runs from (-4, -2) to (4, -2): s = x + 4
        Patch("window", 0, -1.5 + 4.0, 0.0 + 4.0, 1.0, 2.1, WINDOW),
    ]
    lights = [((0.0, 0.0, 2.5), 0.6), ((2.0, -1.0, 2.8), 0.4)]
    return Room("sim-room", outline, WALLS, FLOOR, CEILING, 3.0, objects, patches, lights)


def _table(name: str, x0: float, y0: float, x1: float, y1: float) -> list[Box]:
    """Four-legged table: top 0.72..0.75 m, legs 0.05 x 0.05 inset 0.05."""
    top = Box(f"{name} top", (x0, y0, 0.72), (x1, y1, 0.75), TABLE_TOP)
    legs = []
    for k, (lx, ly) in enumerate(((x0 + 0.05, y0 + 0.05), (x1 - 0.10, y0 + 0.05),
                                  (x1 - 0.10, y1 - 0.10), (x0 + 0.05, y1 - 0.10))):
        legs.append(Box(f"{name} leg {k + 1}", (lx, ly, 0.0), (lx + 0.05, ly + 0.05, 0.72), TABLE_FOOT))
    return [top, *legs]


def l_room() -> Room:
    """L-shaped room around the table 3.3 loop, in the frame of pose 1 (the table's
    x and y used as they are, so the plan is fig. 3.6 mirrored left-right).

    The loop runs (0,0) -> (4.8,0) -> (4.8,2.1) -> (2.35,2.1) -> (2.35,3.9) -> (0,3.9)
    -> (0,0).  Walls 0.9..1.05 m outside it: x -1.05..5.85 (6.9 m long),
    y -0.9..3.0 in the long arm and x -1.05..3.25, y up to 4.8 in the short arm.
    Inside the loop: three four-legged tables (x 0.6..2.2 / y 0.6..1.4,
    x 2.9..4.1 / y 0.6..1.4, x 0.6..1.4 / y 2.2..3.4); outside it: a cabinet against the
    end wall (x 5.35..5.85, y -0.5..1.5) and a low crate (x -1.05..-0.55, y 1.2..2.0)."""
    outline = [(-1.05, -0.9), (5.85, -0.9), (5.85, 3.0), (3.25, 3.0), (3.25, 4.8), (-1.05, 4.8)]
    objects = [
        *_table("table 1", 0.6, 0.6, 2.2, 1.4),
        *_table("table 2", 2.9, 0.6, 4.1, 1.4),
        *_table("table 3", 0.6, 2.2, 1.4, 3.4),
        Box("cabinet", (5.35, -0.5, 0.0), (5.85, 1.5, 1.5), CABINET),
        Box("crate", (-1.05, 1.2, 0.0), (-0.55, 2.0, 0.45), BOXES[1]),
    ]
    patches = [
        Patch("door", 4, 0.3, 1.2, 0.0, 2.0, DOOR),           # wall 4: (3.25, 4.8) -> (-1.05, 4.8)
        Patch("window", 0, 1.5, 4.0, 1.0, 2.1, WINDOW),       # wall 0: (-1.05, -0.9) -> (5.85, -0.9)
    ]
    lights = [((1.5, 1.5, 2.6), 0.6), ((4.0, 1.0, 2.8), 0.4)]
    walls = [WALLS[0], WALLS[1], WALLS[2], WALLS[3], WALLS[1], WALLS[2]]
    return Room("l-room", outline, walls, FLOOR, CEILING, 3.0, objects, patches, lights)


# Building floor: walls in a few light tones, all of them far brighter than the floor.
CORE = (0.78, 0.76, 0.72)
PARTITION = (0.72, 0.78, 0.84)
SHELF = (0.35, 0.30, 0.25)
PILLAR = (0.85, 0.85, 0.80)


def _wall(name: str, x0: float, y0: float, x1: float, y1: float, colour=PARTITION) -> Box:
    """A wall or block standing on the floor (Floor raises it through the ceiling)."""
    return Box(name, (x0, y0, 0.0), (x1, y1, 3.0), colour)


def building_floor() -> Floor:
    """A 20 x 12 m office floor (inside the outer walls: x 0..20, y 0..12), 3 m high.

      long corridor L   y 0..2 along the south facade, x 0..20, 2 m wide; its north side is
                        the core's plain face, 16 m long (x 2..18) without a door or niche
      cross corridors   W at x 0..2 and E at x 18..20, 2 m wide, from L to the north facade
      core              x 2..18, y 2..4.5: stairs, lifts and shafts, a solid block
      room A (lab)      x 2.15..9.925, y 4.5..12, behind a 0.15 m partition to W
      room B (office)   x 10.075..17.85, y 4.5..12, 0.15 m partitions to A and E
      doors             1.4 m openings at y 6.3..7.7 in the three partitions W|A, A|B, B|E,
                        in line, so a path along y = 7 crosses both rooms
    Furniture keeps >= 0.5 m from the line y = 7 through the rooms: in A two four-legged
    benches, a tall cabinet on the north wall, a low cabinet on the core and a crate; in B
    two desks, a round table on a column, a bookshelf and a pillar; a cabinet closes the
    dead end of E.  W and L hold nothing."""
    door_lo, door_hi = 6.3, 7.7
    solids = [
        _wall("core", 2.0, 2.0, 18.0, 4.5, CORE),
        _wall("partition W|A south", 2.0, 4.5, 2.15, door_lo, CORE),
        _wall("partition W|A north", 2.0, door_hi, 2.15, 12.0, CORE),
        _wall("partition A|B south", 9.925, 4.5, 10.075, door_lo),
        _wall("partition A|B north", 9.925, door_hi, 10.075, 12.0),
        _wall("partition B|E south", 17.85, 4.5, 18.0, door_lo, CORE),
        _wall("partition B|E north", 17.85, door_hi, 18.0, 12.0, CORE),
    ]
    objects = [
        # room A (lab)
        *_table("bench 1", 3.0, 9.6, 6.0, 10.4),
        *_table("bench 2", 6.6, 9.6, 9.2, 10.4),
        Box("lab cabinet", (4.0, 11.5, 0.0), (6.0, 12.0, 1.8), CABINET),
        Box("low cabinet", (6.5, 4.5, 0.0), (8.5, 5.0, 1.0), CABINET_2),
        Box("crate", (3.0, 5.2, 0.0), (3.6, 5.8, 0.45), BOXES[0]),
        # room B (office)
        *_table("desk 1", 11.0, 9.0, 12.6, 9.8),
        *_table("desk 2", 14.0, 9.0, 15.6, 9.8),
        Box("round table top", (12.6, 5.2, 0.70), (13.4, 6.0, 0.75), TABLE_TOP),
        Cylinder("round table column", (13.0, 5.6), 0.08, 0.0, 0.70, TABLE_FOOT),
        Box("bookshelf", (17.45, 9.5, 0.0), (17.85, 11.5, 2.0), SHELF),
        Cylinder("pillar", (16.0, 5.4), 0.2, 0.0, 3.0, PILLAR),
        # dead end of the east corridor
        Box("corridor cabinet", (18.4, 11.5, 0.0), (19.6, 12.0, 1.2), CABINET_2),
    ]
    # Shadowless point lights over the corridors and rooms (no falloff: they set the shading
    # of each face orientation, like the two lights of the small rooms).
    lights = [((x, y, 2.6), 0.14) for x, y in ((4.0, 1.0), (10.0, 1.0), (16.0, 1.0), (1.0, 8.0),
                                                (19.0, 8.0), (6.0, 8.0), (14.0, 8.0))]
    outline = [(0.0, 0.0), (20.0, 0.0), (20.0, 12.0), (0.0, 12.0)]  # outer walls: 0 south, 1 east, 2 north, 3 west
    walls = [WALLS[0], WALLS[1], WALLS[0], WALLS[1]]
    return Floor("building", outline, walls, FLOOR, CEILING, 3.0, objects, [], lights, solids=solids)
