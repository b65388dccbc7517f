"""Dataset definitions and writing (architecture.md, "Dataset format")."""
from __future__ import annotations

import csv
import hashlib
import math
import os
import re
import shutil
import tempfile
import time
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Callable, Sequence

from . import mirror as M
from . import odometry as odo
from . import pov
from .geometry import Pose, compose, inverse, relative_to_first, write_tum, read_tum
from .rooms import building_floor, l_room, sim_room
from .rooms_real import (building_real, checker_room, home_deep_room, home_ramp_room, home_room, home_stairs_room,
                         home_step_room, l_room_real, office_real, polished_building, polished_room, sim_room_real)
from .scene import Room, frame_scene, person_pov

TRAJECTORIES_CSV = Path(__file__).resolve().parent / "data" / "trajectories.csv"
RATE_HZ = 10
CAMERA_HEIGHT_M = 1.0
NOISE_SEED = 1
ANTIALIAS = "+A0.1 +AM1 +R3"   # adaptive 3x3 supersampling of contrasted pixels, no jitter
RENDERER_VERSION = "2"          # part of the render key: bump when the image output changes


def table_points(table: str) -> list[tuple[float, float]]:
    """(x, y) in metres of the poses of one table of trajectories.csv, in order."""
    rows = []
    with open(TRAJECTORIES_CSV) as fh:
        for row in csv.reader(ln for ln in fh if not ln.startswith("#")):
            if row and row[0] == table:
                rows.append((int(row[1]), float(row[2]) / 1000.0, float(row[3]) / 1000.0))
    rows.sort()
    return [(x, y) for _, x, y in rows]


def facing_travel(points: Sequence[tuple[float, float]], spread: int = 3) -> list[Pose]:
    """Poses that face the direction of travel; each heading change is spread over
    `spread` poses centred on the corner (linear in yaw, shortest turn)."""
    n = len(points)
    step_dir = [math.atan2(points[i + 1][1] - points[i][1], points[i + 1][0] - points[i][0])
                for i in range(n - 1)]
    heading = [step_dir[min(i, n - 2)] for i in range(n)]
    # unwrap so that each change is the shortest turn
    for i in range(1, n):
        heading[i] = heading[i - 1] + math.atan2(math.sin(heading[i] - heading[i - 1]),
                                                 math.cos(heading[i] - heading[i - 1]))
    smooth = list(heading)
    for k in range(1, n - 1):
        delta = heading[k] - heading[k - 1]
        if abs(delta) < 1e-12:
            continue
        half = spread // 2
        for j in range(-half, spread - half):
            idx = k + j
            if 0 <= idx < n:
                smooth[idx] = heading[k - 1] + delta * (j + half + 1) / (spread + 1)
    return [(x, y, math.atan2(math.sin(h), math.cos(h))) for (x, y), h in zip(points, smooth)]


@dataclass
class DatasetSpec:
    name: str
    room: Callable[[], Room]
    world_poses: Callable[[], list[Pose]]   # robot poses in the room frame
    constant_heading: bool
    description: str
    camera_height_m: float = CAMERA_HEIGHT_M
    grey: bool = False      # store 8-bit grey PNGs (a third of the size; the front-end reads grey)
    # People in the room, frame by frame: (frame index from 1, the robot's world poses) ->
    # each person's (x, y, heading) in the room frame. Not in the floor plan (they move).
    people: Callable[[int, Sequence[Pose]], list[Pose]] | None = None

    def placements(self, world: Sequence[Pose]) -> list[list[Pose]]:
        return [self.people(i, world) if self.people else [] for i in range(1, len(world) + 1)]


def _still(points) -> list[Pose]:
    return [(x, y, 0.0) for x, y in points]


def _l_laps(laps: int) -> list[Pose]:
    pts = table_points("3.3")
    return _still(pts * laps + pts[:1])


def _rectangle_loop(corners: Sequence[tuple[float, float]], steps: Sequence[int]) -> list[tuple[float, float]]:
    """Points along a closed polygon, leg i cut into steps[i] equal steps, back to the start."""
    pts = []
    for i, n in enumerate(steps):
        (x0, y0), (x1, y1) = corners[i], corners[(i + 1) % len(corners)]
        pts += [(round(x0 + (x1 - x0) * k / n, 6), round(y0 + (y1 - y0) * k / n, 6)) for k in range(n)]
    return pts + [corners[0]]


def home_loop() -> list[Pose]:
    """One lap around the living room's low table (rooms_real.home_room), counter-clockwise,
    facing the direction of travel: 50 steps of 0.25-0.26 m (12.6 m), over the extension lead
    where it crosses the path."""
    corners = [(1.2, 1.1), (5.2, 1.1), (5.2, 3.4), (1.2, 3.4)]
    return facing_travel(_rectangle_loop(corners, [16, 9, 16, 9]))


def office_loop() -> list[Pose]:
    """One lap around the office pillar, counter-clockwise, facing the direction of travel:
    44 steps of 0.27-0.29 m (12.4 m)."""
    corners = [(1.2, 1.8), (5.8, 1.8), (5.8, 3.4), (1.2, 3.4)]
    return facing_travel(_rectangle_loop(corners, [16, 6, 16, 6]))


BUILDING_STEP_M = 0.25


def building_loop(laps: int = 2, step: float = BUILDING_STEP_M) -> list[Pose]:
    """Laps of one counter-clockwise loop on the building floor (rooms.building_floor), facing
    the direction of travel: from (4, 1) east along the long corridor L to (19, 1), north up
    the east corridor to (19, 7), west through room B, room A and their three doors to (1, 7),
    south down the west corridor to (1, 1) and east back to (4, 1).  48 m a lap, cut into
    steps of `step` metres (each leg a whole number of steps); the laps are joined and the
    last pose is the first one again."""
    corners = [(4.0, 1.0), (19.0, 1.0), (19.0, 7.0), (1.0, 7.0), (1.0, 1.0)]
    legs = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(corners, corners[1:] + corners[:1])]
    lap = _rectangle_loop(corners, [round(length / step) for length in legs])
    return facing_travel(lap[:-1] * laps + lap[:1])


DATASETS: dict[str, DatasetSpec] = {
    "sim-room-10": DatasetSpec("sim-room-10", sim_room, lambda: _still(table_points("3.1")), True,
                               "thesis simulated room, table 3.1 poses, constant heading"),
    "sim-room-37": DatasetSpec("sim-room-37", sim_room, lambda: _still(table_points("3.2")), True,
                               "thesis simulated room, table 3.2 poses, constant heading"),
    "sim-room-turning": DatasetSpec("sim-room-turning", sim_room,
                                    lambda: facing_travel(table_points("3.2")), False,
                                    "table 3.2 path, robot facing its direction of travel"),
    "l-room-1lap": DatasetSpec("l-room-1lap", l_room, lambda: _l_laps(1), True,
                               "L-shaped room, table 3.3 poses, one lap back to pose 1"),
    "l-room-2laps": DatasetSpec("l-room-2laps", l_room, lambda: _l_laps(2), True,
                                "L-shaped room, table 3.3 poses, two laps back to pose 1"),
    # Realistic looks (rooms_real.py): textured floors, skirting, soft shadows, sunlight.
    "sim-room-37-real": DatasetSpec("sim-room-37-real", sim_room_real, lambda: _still(table_points("3.2")), True,
                                    "sim-room-37 with ceramic tiles, area lamps and sunlight", grey=True),
    "l-room-1lap-real": DatasetSpec("l-room-1lap-real", l_room_real, lambda: _l_laps(1), True,
                                    "l-room-1lap with wood planks, a rug, pendant lamps and sunlight",
                                    grey=True),
    "office-real": DatasetSpec("office-real", office_real, office_loop, False,
                               "office with carpet, pillar loop facing travel, camera 0.8 m up",
                               camera_height_m=0.8, grey=True),
    # A flat-shaded building floor (grey PNGs to keep its ~400 frames small).
    "building-2laps": DatasetSpec("building-2laps", building_floor, building_loop, False,
                                  "building floor 20 x 12 m: corridors and two rooms, 2 laps of 48 m",
                                  grey=True),
}


def _people_in_sim_room(frame: int, world: Sequence[Pose]) -> list[Pose]:
    """Three people in sim-room (its path, table 3.2): one following the robot five frames
    (1.25 m) behind on its path from frame 6, one pacing back and forth in front of the
    cabinet by the bottom wall (0.3 m a frame), one standing by the left cabinet until frame
    20 and then gone (left the room)."""
    out: list[Pose] = []
    if frame >= 6:
        (x0, y0, _), (x1, y1, _) = world[frame - 6], world[frame - 5]
        out.append((x0, y0, math.atan2(y1 - y0, x1 - x0)))
    lo, hi, step = -1.0, 0.8, 0.3
    travel = ((frame - 1) * step) % (2.0 * (hi - lo))
    forward = travel <= hi - lo
    out.append((lo + travel if forward else hi - (travel - (hi - lo)), -1.45, 0.0 if forward else math.pi))
    if frame <= 20:
        out.append((-2.0, 1.1, -math.pi / 2))
    return out


# Held-out scenes: rendered on demand (`scripts/render-dataset NAME --out DIR`), never bundled
# nor used to choose a parameter; they check that what works on the bundled datasets is not
# tuned to them (README, "Scenes not bundled").
HELD_OUT: dict[str, DatasetSpec] = {
    "checker-room": DatasetSpec("checker-room", checker_room, lambda: facing_travel(table_points("3.2")), False,
                                "held out: sim-room path facing travel, black and white marble, camera 1.15 m",
                                camera_height_m=1.15, grey=True),
    "building-real": DatasetSpec("building-real", building_real, building_loop, False,
                                 "held out: building-2laps with oak planks and ceiling panels, camera 0.9 m",
                                 camera_height_m=0.9, grey=True),
    "people-room": DatasetSpec("people-room", sim_room_real, lambda: _still(table_points("3.2")), True,
                               "held out: sim-room-37-real with three people, one following the robot",
                               grey=True, people=_people_in_sim_room),
    "polished-building": DatasetSpec("polished-building", polished_building, building_loop, False,
                                     "held out: building-2laps on polished vinyl mirroring its corridors",
                                     grey=True),
    "home": DatasetSpec("home", home_room, home_loop, False,
                        "held out: living room, white walls on pale oak, chairs, a floor lamp, cables on the floor, "
                        "camera 1.05 m", camera_height_m=1.05, grey=True),
    "home-step": DatasetSpec("home-step", home_step_room, home_loop, False,
                             "held out: the living room with a sunken area one step (0.18 m) down, camera 1.05 m",
                             camera_height_m=1.05, grey=True),
    "home-deep": DatasetSpec("home-deep", home_deep_room, home_loop, False,
                             "held out: the living room with a sunken area 0.55 m deep, camera 1.05 m",
                             camera_height_m=1.05, grey=True),
    "home-ramp": DatasetSpec("home-ramp", home_ramp_room, home_loop, False,
                             "held out: the living room with a ramp down into a sunken area 0.12 m deep, camera 1.05 m",
                             camera_height_m=1.05, grey=True),
    "home-stairs": DatasetSpec("home-stairs", home_stairs_room, home_loop, False,
                               "held out: the living room with stairs down (4 x 0.18 m) in place of its sunken area, "
                               "camera 1.05 m", camera_height_m=1.05, grey=True),
    "polished-room": DatasetSpec("polished-room", polished_room, lambda: facing_travel(table_points("3.2")), False,
                                 "held out: sim-room path facing travel, polished vinyl mirroring the walls",
                                 grey=True),
}


def spec_of(name: str) -> DatasetSpec:
    """A bundled dataset's or a held-out scene's definition (KeyError if neither)."""
    return DATASETS[name] if name in DATASETS else HELD_OUT[name]


def render_key(room: Room, camera_height_m: float = CAMERA_HEIGHT_M, grey: bool = False,
               rig: M.Rig = M.Rig(), people: Sequence[Sequence[Pose]] = ()) -> str:
    parts = [RENDERER_VERSION, room.pov_body(), pov.camera_block(rig), pov.mirror_block(rig), ANTIALIAS,
             repr(camera_height_m)]
    if rig.level_tilt_deg != (0.0, 0.0):
        parts.append(f"level tilt {rig.level_tilt_deg!r}")
    if any(people):
        parts.append(repr([[tuple(round(v, 6) for v in p) for p in frame] for frame in people]))
    text = "|".join(parts + (["grey"] if grey else []))
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _fmt(x: float) -> str:
    return repr(float(x))


def dataset_yaml(spec: DatasetSpec, frames: int, origin: Pose, key: str, rig: M.Rig = M.Rig()) -> str:
    return (
        f"# omnislam dataset rendered by scripts/render-dataset (POV-Ray): {spec.description}\n"
        f"# renderer: room {spec.room().name}, render key {key}, "
        f"map origin in room frame: x={_fmt(origin[0])} y={_fmt(origin[1])} yaw={_fmt(origin[2])}\n"
        f"name: {spec.name}\n"
        f"camera: {{width: {M.IMAGE_PX}, height: {M.IMAGE_PX}, center_px: [{rig.center_px[0]}, {rig.center_px[1]}], "
        f"focal_mm: {M.FOCAL_MM}, pixel_pitch_mm: {_fmt(M.PIXEL_MM)}{rig.yaml_fields()}}}\n"
        + (f"# support rod: azimuth {rig.rod_azimuth_deg!r} deg, {rig.rod_diameter_mm!r} mm thick, its axis "
           f"{pov.ROD_AXIS_RADIUS_MM!r} mm from the mirror's axis\n" if rig.rod_azimuth_deg is not None else "") +
        "mirror: thesis-2008          # mirror.md, derived constants\n"
        f"camera_height_m: {spec.camera_height_m}         # height of the camera pinhole F0 above the floor\n"
        f"frames: {frames}\n"
        f"rate_hz: {RATE_HZ}\n"
        "images: images/%06d.png\n"
        "groundtruth: groundtruth.tum\n"
        "odometry: odometry.tum\n"
        "odometry_exact: odometry_exact.tum\n"
        f"odometry_noise: {{model: thesis, seed: {NOISE_SEED}}}\n"
        "floorplan: floorplan.csv\n"
    )


def write_floorplan(path: Path, room: Room, origin: Pose) -> None:
    to_map = inverse(origin)
    lines = ["x1,y1,x2,y2"]
    for x1, y1, x2, y2 in room.floorplan():
        a = compose(to_map, (x1, y1, 0.0))
        b = compose(to_map, (x2, y2, 0.0))
        lines.append(f"{a[0]:.9f},{a[1]:.9f},{b[0]:.9f},{b[1]:.9f}")
    path.write_text("\n".join(lines) + "\n")


def write_metadata(spec: DatasetSpec, out: Path, frames: int | None = None, rig: M.Rig = M.Rig()) -> list[Pose]:
    """Everything but the images; returns the world poses of the frames written."""
    world = spec.world_poses()
    if frames is not None:
        world = world[:frames]
    room = spec.room()
    out.mkdir(parents=True, exist_ok=True)
    origin = world[0]
    gt = relative_to_first(world)
    write_tum(out / "groundtruth.tum", gt, RATE_HZ,
              f"{spec.name} ground truth: base_link in map (map = pose of frame 1)")
    write_tum(out / "odometry_exact.tum", odo.odometry(gt, None), RATE_HZ,
              f"{spec.name} exact odometry (ground-truth increments composed)")
    noisy = odo.odometry(gt, NOISE_SEED)
    write_tum(out / "odometry.tum", noisy, RATE_HZ,
              f"{spec.name} odometry, noise model thesis, seed {NOISE_SEED}")
    if spec.constant_heading:
        odo.write_thesis_odometry(out / "odometry.txt", noisy)
    elif (out / "odometry.txt").exists():
        (out / "odometry.txt").unlink()
    write_floorplan(out / "floorplan.csv", room, origin)
    key = render_key(room, spec.camera_height_m, spec.grey, rig, spec.placements(world))
    (out / "dataset.yaml").write_text(dataset_yaml(spec, len(world), origin, key, rig))
    return world


def _pose_key(p: Pose) -> tuple:
    return tuple(round(v, 9) for v in p)


def _reusable_images(out: Path, key: str) -> dict[tuple, Path]:
    """Images of sibling datasets rendered with the same render key, by world pose."""
    found: dict[tuple, Path] = {}
    parent = out.resolve().parent
    if not parent.is_dir():
        return found
    for yaml_file in sorted(parent.glob("*/dataset.yaml")):
        other = yaml_file.parent
        if other.resolve() == out.resolve():
            continue
        m = re.search(r"render key (\w+), map origin in room frame: x=(\S+) y=(\S+) yaw=(\S+)",
                      yaml_file.read_text())
        if not m or m.group(1) != key:
            continue
        origin = (float(m.group(2)), float(m.group(3)), float(m.group(4)))
        try:
            gt = read_tum(other / "groundtruth.tum")
        except (OSError, ValueError):
            continue
        for i, (_, pose) in enumerate(gt, start=1):
            img = other / "images" / f"{i:06d}.png"
            if img.is_file():
                found.setdefault(_pose_key(compose(origin, pose)), img)
    return found


def _link_or_copy(src: Path, dst: Path) -> None:
    tmp = dst.with_suffix(".tmp.png")
    if tmp.exists():
        tmp.unlink()
    try:
        os.link(src, tmp)
    except OSError:
        shutil.copyfile(src, tmp)
    os.replace(tmp, dst)


def render_images(spec: DatasetSpec, out: Path, world: Sequence[Pose], threads: int = 2,
                  log=print, rig: M.Rig = M.Rig()) -> dict:
    room = spec.room()
    people = spec.placements(world)
    key = render_key(room, spec.camera_height_m, spec.grey, rig, people)
    images = out / "images"
    images.mkdir(parents=True, exist_ok=True)
    for stale in images.glob("*.png"):
        if not re.fullmatch(r"\d{6}", stale.stem) or int(stale.stem) > len(world):
            stale.unlink()
    # A frame with people is its own: the same pose elsewhere in the run shows them elsewhere.
    own_frames = any(people)
    reuse = {} if own_frames else _reusable_images(out, key)
    done: dict[tuple, Path] = {}
    camera, mirror = pov.camera_block(rig), pov.mirror_block(rig)
    times, reused = [], 0
    with tempfile.TemporaryDirectory(prefix=f"omnislam-{spec.name}-") as tmp:
        for i, pose in enumerate(world, start=1):
            dst = images / f"{i:06d}.png"
            pk = _pose_key(pose)
            src = None if own_frames else done.get(pk) or reuse.get(pk)
            if src is not None:
                _link_or_copy(src, dst)
                reused += 1
            else:
                pov_file = Path(tmp) / f"{i:06d}.pov"
                extra = "\n  ".join(person_pov(*p) for p in people[i - 1])
                pov_file.write_text(frame_scene(room, pose, spec.camera_height_m, camera, mirror, extra,
                                                rig.level_tilt_deg))
                png_tmp = Path(tmp) / f"{i:06d}.png"
                times.append(pov.render(pov_file, png_tmp, threads=threads, antialias=ANTIALIAS,
                                        grey=spec.grey))
                shutil.move(str(png_tmp), dst)
                log(f"{spec.name}: frame {i}/{len(world)} rendered in {times[-1]:.2f} s")
            done.setdefault(pk, dst)
    return {"rendered": len(times), "reused": reused,
            "seconds_per_frame": (sum(times) / len(times)) if times else 0.0}


def build(name: str, out: Path, frames: int | None = None, images: bool = True,
          threads: int = 2, log=print, rig: M.Rig = M.Rig(), camera_height_m: float | None = None) -> dict:
    """Renders dataset `name` into `out`; `rig` is the assembled rig the images are taken
    with (default: the design), written into dataset.yaml so a replay uses the true rig;
    `camera_height_m` puts the camera at another height (default: the dataset's own)."""
    spec = spec_of(name)
    if camera_height_m is not None and camera_height_m != spec.camera_height_m:
        spec = replace(spec, camera_height_m=camera_height_m,
                       description=f"{spec.description}, camera {camera_height_m:g} m up")
    t0 = time.monotonic()
    world = write_metadata(spec, out, frames, rig)
    stats = {"frames": len(world)}
    if images:
        stats.update(render_images(spec, out, world, threads=threads, log=log, rig=rig))
    stats["seconds"] = time.monotonic() - t0
    return stats
