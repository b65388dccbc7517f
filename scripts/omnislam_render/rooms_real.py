"""Realistic rooms: real floor materials, skirting boards, area lamps with soft shadows and
sunlight through a window (issue "real floors, real light, real sensors").

The geometry of sim-room and l-room is unchanged (same walls, objects and poses as the
flat-shaded datasets), only their look; office is a room of its own, seen from a camera
0.8 m above the floor.  Materials are POV-Ray textures in millimetres in the room frame,
so they move with the room.  Sensor effects (noise, blur, vignetting, JPEG, exposure,
dust) are not rendered: `omnislam degrade` / `replay --degrade` add them, seeded.
"""
from __future__ import annotations

from .rooms import (BOXES, CABINET, CEILING, DOOR, TABLE_FOOT, TABLE_TOP, WALLS, WINDOW, building_floor, l_room,
                    sim_room)
from .scene import AreaLamp, Box, Cable, Cylinder, Patch, Pit, Room, Rug, Skirting, Sphere, Sun

# Indirect light is approximated by a low ambient term; the lamps do the rest.
FINISH = "finish { ambient 0.12 diffuse 0.8 }"
GLOSSY = "finish { ambient 0.12 diffuse 0.75 specular 0.15 roughness 0.04 }"
SKIRTING_HEIGHT = 0.08
SKIRTING_DEPTH = 0.012


def _rgb(c) -> str:
    return f"rgb <{c[0]}, {c[1]}, {c[2]}>"


def ceramic_tiles(size_mm: float = 400.0, joint_mm: float = 6.0) -> str:
    """Square ceramic tiles with light grout joints; each tile a slightly different shade
    (POV `cells`, one random value per tile), a little gloss."""
    joint = (f"function {{ max(select(mod(x + 400000, {size_mm}) - {joint_mm}, 1, 0), "
             f"select(mod(y + 400000, {size_mm}) - {joint_mm}, 1, 0)) }}")
    tile = (f"pigment {{ cells color_map {{ [0 rgb <0.36, 0.33, 0.29>] [1 rgb <0.46, 0.42, 0.37>] }} "
            f"scale {size_mm} translate <0, 0, {size_mm / 2}> }} {GLOSSY}")
    grout = f"pigment {{ rgb <0.74, 0.72, 0.68> }} {FINISH}"
    return f"texture {{ {joint} texture_map {{ [0.5 {tile}] [0.5 {grout}] }} }}"


def wood_planks(length_mm: float = 1200.0, width_mm: float = 150.0) -> str:
    """Staggered wooden planks along x with dark joints and grain along each plank."""
    grain = ("pigment { wood turbulence 0.08 color_map { [0 rgb <0.40, 0.26, 0.14>] "
             "[0.5 rgb <0.52, 0.35, 0.19>] [1 rgb <0.40, 0.26, 0.14>] } scale 9 rotate y*90 }")
    return (f"texture {{ brick texture {{ pigment {{ rgb <0.12, 0.08, 0.05> }} {FINISH} }} "
            f"texture {{ {grain} {GLOSSY} }} brick_size <{length_mm}, {width_mm}, 1000> mortar 3 "
            f"translate <0, 0, 500> }}")


def pale_oak(length_mm: float = 1400.0, width_mm: float = 180.0) -> str:
    """Pale oak laminate with light joints: a floor nearly as light as white walls and skirting,
    so a wall's base is a faint line."""
    grain = ("pigment { wood turbulence 0.06 color_map { [0 rgb <0.66, 0.57, 0.44>] "
             "[0.5 rgb <0.75, 0.66, 0.52>] [1 rgb <0.66, 0.57, 0.44>] } scale 11 rotate y*90 }")
    return (f"texture {{ brick texture {{ pigment {{ rgb <0.55, 0.47, 0.36> }} {FINISH} }} "
            f"texture {{ {grain} {FINISH} }} brick_size <{length_mm}, {width_mm}, 1000> mortar 2 "
            f"translate <0, 0, 500> }}")


def patterned_carpet(cell_mm: float = 120.0) -> str:
    """Office carpet: a three-tone hexagon pattern."""
    hexagons = (f"pigment {{ hexagon rgb <0.30, 0.34, 0.44>, rgb <0.40, 0.44, 0.56>, rgb <0.24, 0.27, 0.34> "
                f"scale {cell_mm} rotate x*90 }}")
    return f"texture {{ {hexagons} {FINISH} }}"


def checker_marble(size_mm: float = 300.0) -> str:
    """Black and white marble squares, polished: the strongest texture a floor has (every
    square's edge a high-contrast line, and a dark skirting hides the base of a wall wherever a
    black square meets it)."""
    squares = (f"pigment {{ checker rgb <0.10, 0.10, 0.11>, rgb <0.86, 0.85, 0.82> scale {size_mm} "
               f"translate <0, 0, {size_mm / 2}> }}")
    return f"texture {{ {squares} {GLOSSY} }}"


def polished_vinyl(tile_mm: float = 600.0) -> str:
    """Polished vinyl tiles, as in corridors and shops: a light mottled grey with faint joints,
    waxed so that it reflects the room like glass does (Fresnel's law for an index of 1.5:
    4% looking straight down, ~20% at the 20-25 degrees below the horizon of a wall's base
    3 m away, ~40% at 10 degrees). The floor's own pattern is weak; what it shows beyond the
    wall's base is the wall, mirrored."""
    mottle = ("pigment { granite color_map { [0 rgb <0.50, 0.51, 0.50>] [1 rgb <0.60, 0.60, 0.58>] } "
              "scale 400 }")
    polish = ("finish { ambient 0.10 diffuse 0.7 specular 0.3 roughness 0.005 "
              "reflection { 0.0, 1.0 fresnel on } conserve_energy }")
    joint = (f"function {{ max(select(mod(x + 600000, {tile_mm}) - 2, 1, 0), "
             f"select(mod(y + 600000, {tile_mm}) - 2, 1, 0)) }}")
    tile = f"{mottle} {polish}"
    seam = f"pigment {{ rgb <0.42, 0.42, 0.41> }} {polish}"
    return f"texture {{ {joint} texture_map {{ [0.5 {tile}] [0.5 {seam}] }} }} interior {{ ior 1.5 }}"


def rug_texture(x0: float, y0: float, x1: float, y1: float, border_m: float = 0.12) -> str:
    """A rug with a plain border around a field of diamonds."""
    lo, hi = (x0 * 1000, y0 * 1000), (x1 * 1000, y1 * 1000)
    inside = (f"function {{ select(min(x - {lo[0]}, {hi[0]} - x, y - {lo[1]}, {hi[1]} - y) - "
              f"{border_m * 1000}, 1, 0) }}")
    field = ("pigment { checker rgb <0.62, 0.18, 0.14>, rgb <0.80, 0.66, 0.42> scale 110 rotate z*45 "
             "translate <0, 0, 55> }")
    border = "pigment { rgb <0.20, 0.16, 0.30> }"
    return f"texture {{ {inside} texture_map {{ [0.5 {field} {FINISH}] [0.5 {border} {FINISH}] }} }}"


def _realistic(room: Room, floor: str, lamps: list[AreaLamp], sun: Sun | None, skirting_colour,
               rugs: list[Rug] = ()) -> Room:
    room.name += "-real"
    room.floor_texture = floor
    room.finish = FINISH
    room.lights = []
    room.area_lamps = lamps
    room.sun = sun
    room.rugs = list(rugs)
    room.skirting = Skirting(SKIRTING_HEIGHT, SKIRTING_DEPTH, skirting_colour)
    return room


def sim_room_real() -> Room:
    """sim-room with ceramic tiles, two square ceiling panels and the afternoon sun through
    the window of the bottom wall, drawing a patch across the middle of the path."""
    lamps = [AreaLamp((-2.0, 0.0, 2.95), (0.6, 0.6), 0.55), AreaLamp((1.5, 0.0, 2.95), (0.6, 0.6), 0.55)]
    sun = Sun("window", azimuth_deg=-110.0, elevation_deg=35.0, power=1.4)
    return _realistic(sim_room(), ceramic_tiles(), lamps, sun, (0.92, 0.92, 0.90))


def l_room_real() -> Room:
    """l-room with oak planks, a rug in the long arm's free corner, three pendant lamps (soft
    shadows of the tables on the floor) and morning sun through the long wall's window."""
    lamps = [AreaLamp((1.4, 1.0, 2.4), (0.3, 0.3), 0.40), AreaLamp((3.5, 1.0, 2.4), (0.3, 0.3), 0.40),
             AreaLamp((1.0, 3.2, 2.4), (0.3, 0.3), 0.35)]
    sun = Sun("window", azimuth_deg=-65.0, elevation_deg=40.0, power=1.3)
    rug = Rug("rug", (2.6, 1.7), (4.4, 2.8), 0.008, rug_texture(2.6, 1.7, 4.4, 2.8))
    return _realistic(l_room(), wood_planks(), lamps, sun, (0.30, 0.22, 0.15), [rug])


def checker_room() -> Room:
    """A held-out scene (not bundled: for checking what is not tuned to the bundled ones):
    sim-room's walls and objects with a black and white marble floor, a dark skirting, one
    ceiling panel off centre and a low sun through the window."""
    lamps = [AreaLamp((-1.2, 0.8, 2.95), (0.8, 0.4), 0.6)]
    sun = Sun("window", azimuth_deg=-80.0, elevation_deg=20.0, power=1.6)
    room = _realistic(sim_room(), checker_marble(), lamps, sun, (0.15, 0.12, 0.10))
    room.name = "checker-room"
    return room


def polished_room() -> Room:
    """A held-out scene (not bundled): sim-room's walls and objects on a polished vinyl floor
    that mirrors them (a dark skirting, the window and the lamps seen again below the floor
    line), two ceiling panels and the sun low through the window."""
    lamps = [AreaLamp((-1.5, -0.5, 2.95), (0.6, 0.6), 0.5), AreaLamp((1.5, 0.5, 2.95), (0.6, 0.6), 0.5)]
    sun = Sun("window", azimuth_deg=-100.0, elevation_deg=25.0, power=1.3)
    room = _realistic(sim_room(), polished_vinyl(), lamps, sun, (0.18, 0.18, 0.20))
    room.name = "polished-room"
    return room


def polished_building() -> Room:
    """A held-out scene (not bundled): the building floor on polished vinyl that mirrors its
    walls (long corridors: grazing angles, where Fresnel's reflection is strongest), a dark
    skirting and ceiling panels over the corridors and rooms."""
    floor = building_floor()
    lamps = [AreaLamp((x, y, 2.9), (1.2, 0.3), 0.30) for (x, y, _), _ in floor.lights]
    room = _realistic(floor, polished_vinyl(), lamps, None, (0.18, 0.18, 0.20))
    room.name = "polished-building"
    return room


def building_real() -> Room:
    """A held-out scene (not bundled): the building floor with narrow light oak planks, a light
    skirting and ceiling panels (soft shadows) over the corridors and rooms."""
    floor = building_floor()
    lamps = [AreaLamp((x, y, 2.9), (1.2, 0.3), 0.30) for (x, y, _), _ in floor.lights]  # where its lights are
    room = _realistic(floor, wood_planks(900.0, 120.0), lamps, None, (0.85, 0.85, 0.82))
    room.name = "building-real"
    return room


def _chair(name: str, x: float, y: float, back_towards_y: float) -> list:
    """A dining chair centred at (x, y): a 0.42 m seat 0.45 m up on four legs 25 mm square, and
    a backrest on the side whose y sign is `back_towards_y`."""
    h, leg, seat_h = 0.21, 0.025, 0.45
    x0, y0, x1, y1 = x - h, y - h, x + h, y + h
    legs = [Box(f"{name} leg {k + 1}", (lx, ly, 0.0), (lx + leg, ly + leg, seat_h - 0.03), TABLE_FOOT)
            for k, (lx, ly) in enumerate(((x0, y0), (x1 - leg, y0), (x1 - leg, y1 - leg), (x0, y1 - leg)))]
    by0 = y1 - 0.03 if back_towards_y > 0 else y0
    back = Box(f"{name} back", (x0, by0, seat_h), (x1, by0 + 0.03, 0.90), (0.30, 0.22, 0.16))
    return [Box(f"{name} seat", (x0, y0, seat_h - 0.03), (x1, y1, seat_h), (0.30, 0.22, 0.16)), *legs, back]


def home_room() -> Room:
    """A held-out scene (not bundled): a living room 6.4 x 4.6 m, 2.6 m high, with white walls
    and white skirting on a pale oak floor (a wall's base a faint line), two chairs on thin legs
    at a desk, a floor lamp on a thin pole, a sofa, a low table on a rug, a TV on a stand, a
    plant, and cables lying loose on the floor: an extension lead from the right wall across
    the robot's path to the low table (black), a white charger cable by the desk, the lamp's
    cable to the bottom wall (black)."""
    outline = [(0.0, 0.0), (6.4, 0.0), (6.4, 4.6), (0.0, 4.6)]  # walls: 0 bottom, 1 right, 2 top, 3 left
    white = (0.86, 0.85, 0.82)
    objects = [
        Box("sofa", (2.0, 0.0, 0.0), (4.2, 0.6, 0.8), (0.45, 0.47, 0.52)),
        *_legged_table("low table", 2.4, 1.9, 3.8, 2.6, 0.42),
        *_legged_table("desk", 2.0, 4.0, 3.8, 4.6, 0.74),
        *_chair("chair 1", 2.5, 3.85 + 0.2, -1.0),
        *_chair("chair 2", 3.3, 3.85 + 0.2, -1.0),
        Cylinder("lamp base", (0.45, 0.45), 0.14, 0.0, 0.025, (0.15, 0.15, 0.15)),
        Cylinder("lamp pole", (0.45, 0.45), 0.012, 0.025, 1.45, (0.15, 0.15, 0.15)),
        Cylinder("lamp shade", (0.45, 0.45), 0.2, 1.45, 1.7, (0.92, 0.88, 0.78)),
        Box("bookshelf", (0.0, 2.0, 0.0), (0.35, 3.2, 1.9), CABINET),
        Box("tv stand", (6.0, 1.6, 0.0), (6.4, 2.9, 0.5), (0.20, 0.20, 0.22)),
        Box("tv", (6.3, 1.7, 0.55), (6.35, 2.8, 1.2), (0.05, 0.05, 0.06)),
        Cylinder("plant pot", (5.9, 0.45), 0.18, 0.0, 0.4, (0.70, 0.40, 0.25)),
        Sphere("plant", (5.9, 0.45, 0.72), 0.3, (0.20, 0.40, 0.18)),
    ]
    patches = [
        Patch("window", 1, 0.3, 1.4, 0.9, 2.2, WINDOW),       # wall 1: (6.4, 0) -> (6.4, 4.6)
        Patch("door", 3, 0.2, 1.1, 0.0, 2.0, DOOR),           # wall 3: (0, 4.6) -> (0, 0)
    ]
    lamps = [AreaLamp((x, 2.3, 2.55), (0.6, 0.6), 0.45) for x in (1.8, 4.6)]
    sun = Sun("window", azimuth_deg=20.0, elevation_deg=30.0, power=1.3)
    room = Room("home", outline, [white] * 4, (0.7, 0.6, 0.5), CEILING, 2.6, objects, patches)
    rug = Rug("rug", (2.1, 1.6), (4.1, 2.9), 0.008, rug_texture(2.1, 1.6, 4.1, 2.9))
    room = _realistic(room, pale_oak(), lamps, sun, (0.90, 0.90, 0.88), [rug])
    room.name = "home"
    room.cables = [
        Cable("extension lead", [(6.38, 3.8), (6.0, 3.75), (5.6, 3.62), (5.1, 3.35), (4.6, 3.0), (4.1, 2.75),
                                 (3.8, 2.62)], 0.004, (0.05, 0.05, 0.05)),
        Cable("charger cable", [(1.85, 4.55), (1.7, 4.2), (1.75, 3.9), (2.05, 3.75), (2.3, 3.78)], 0.0025,
              (0.88, 0.88, 0.86)),
        Cable("lamp cable", [(0.55, 0.5), (0.95, 0.62), (1.35, 0.58), (1.7, 0.35), (1.8, 0.02)], 0.003,
              (0.05, 0.05, 0.05)),
    ]
    return room


def home_step_room() -> Room:
    """A held-out scene (not bundled): the living room with a sunken seating area instead of
    its low table and rug, 1.5 x 0.9 m and 0.18 m deep (one step down, no railing), in pale oak
    like the rest of the floor; the robot passes its edges 0.7 m away. A drop, not a wall: the
    floor beyond its edge goes on, lower."""
    room = home_room()
    room.name = "home-step"
    room.objects = [o for o in room.objects if not o.name.startswith("low table")]
    room.rugs = []
    room.cables = [c for c in room.cables if c.name != "extension lead"]
    room.pits = [Pit("sunken area", (2.4, 1.8), (3.9, 2.7), 0.18)]
    return room


def home_deep_room() -> Room:
    """A held-out scene (not bundled): the sunken area of `home_step_room` 0.55 m deep (three
    steps' worth, as a loading bay's or a stairwell's edge without its railing): its lower floor
    lies several pixels below the floor's row in the outer lobe, not one."""
    room = home_step_room()
    room.name = "home-deep"
    room.pits = [Pit("sunken area", (2.4, 1.8), (3.9, 2.7), 0.55)]
    return room


def home_ramp_room() -> Room:
    """A held-out scene (not bundled): the sunken area of `home_step_room` 0.12 m deep with a
    ramp down into it over its whole length (1.5 m at 8%, an accessible ramp's slope) from its
    left edge: the ramp's surface is where a robot may drive, its sides and far end are steps
    down, up to 0.12 m deep."""
    room = home_step_room()
    room.name = "home-ramp"
    room.pits = [Pit("sunken area", (2.4, 1.8), (3.9, 2.7), 0.12, ramp_m=1.5)]
    return room


def home_stairs_room() -> Room:
    """A held-out scene (not bundled): in place of the sunken area of `home_step_room`, stairs
    down without a railing: four steps of 0.18 m along +x from its left edge, treads 0.3 m,
    0.72 m deep at the bottom landing (nested pits, each cut deeper than the one before)."""
    room = home_step_room()
    room.name = "home-stairs"
    room.pits = [Pit(f"stairs, step {k + 1}", (2.4 + 0.3 * k, 1.8), (3.9, 2.7), 0.18 * (k + 1)) for k in range(4)]
    return room


def _legged_table(name: str, x0: float, y0: float, x1: float, y1: float, height: float) -> list:
    top = Box(f"{name} top", (x0, y0, height - 0.03), (x1, y1, height), TABLE_TOP)
    legs = [Box(f"{name} leg {k + 1}", (lx, ly, 0.0), (lx + 0.05, ly + 0.05, height - 0.03), TABLE_FOOT)
            for k, (lx, ly) in enumerate(((x0 + 0.05, y0 + 0.05), (x1 - 0.10, y0 + 0.05),
                                          (x1 - 0.10, y1 - 0.10), (x0 + 0.05, y1 - 0.10)))]
    return [top, *legs]


def office_real() -> Room:
    """An open office, 7.0 x 5.2 m, 2.8 m high: carpet, a round pillar in the middle, a desk,
    a sofa, a bookshelf, a low table and a bin; fluorescent panels and low winter sun through
    a wide window.  The path (datasets.py) loops around the pillar."""
    outline = [(0.0, 0.0), (7.0, 0.0), (7.0, 5.2), (0.0, 5.2)]  # walls: 0 bottom, 1 right, 2 top, 3 left
    objects = [
        Cylinder("pillar", (3.5, 2.6), 0.2, 0.0, 2.8, (0.85, 0.85, 0.82)),
        *_legged_table("desk", 0.4, 3.9, 2.0, 4.7, 0.74),
        Box("sofa", (4.5, 0.3, 0.0), (6.5, 1.2, 0.8), (0.35, 0.38, 0.30)),
        Box("bookshelf", (6.65, 2.0, 0.0), (7.0, 3.2, 1.8), CABINET),
        *_legged_table("low table", 4.4, 4.0, 5.2, 4.6, 0.45),
        Cylinder("bin", (0.4, 0.4), 0.15, 0.0, 0.4, BOXES[2]),
    ]
    patches = [
        Patch("window", 0, 2.5, 4.5, 0.9, 2.0, WINDOW),       # wall 0: (0, 0) -> (7, 0)
        Patch("door", 2, 0.6, 1.5, 0.0, 2.0, DOOR),           # wall 2: (7, 5.2) -> (0, 5.2)
    ]
    lamps = [AreaLamp((x, y, 2.75), (1.2, 0.3), 0.30) for x in (1.8, 5.2) for y in (1.6, 3.6)]
    sun = Sun("window", azimuth_deg=-100.0, elevation_deg=25.0, power=1.2)
    room = Room("office", outline, [WALLS[0], WALLS[3], WALLS[0], WALLS[3]], (0.2, 0.2, 0.2), CEILING, 2.8,
                objects, patches)
    return _realistic(room, patterned_carpet(), lamps, sun, (0.92, 0.92, 0.90))
