"""Geometric check of the rendered camera + mirror against mirror.md.

A floor plane (z = -1000 mm, i.e. the floor under a camera 1 m high) carries a
16-bit grey ramp of its distance from the axis (and, in a second render, of its
azimuth).  Each pixel's rendered value is compared with the back-projection of
mirror.md sec. 5 for the pixel centre; the radial error is converted to image
pixels through the local derivative dr/dR.  This measures the whole chain (camera
vectors, pixel-centre convention, lobe surfaces, clipping, reflection) per pixel.
"""
from __future__ import annotations

import math
import subprocess
import tempfile
from pathlib import Path

import numpy as np

from . import mirror as M
from . import pov
from .pngio import read_ppm

FLOOR_Z_MM = -1000.0


def _scene(function: str) -> str:
    return ("#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 5 }\n"
            f"plane {{ z, {FLOOR_Z_MM} pigment {{ function {{ {function} }} "
            "color_map { [0 rgb 0][1 rgb 1] } } finish { ambient 1 diffuse 0 } }\n"
            + pov.camera_block() + pov.mirror_block())


def _render16(function: str, size: int, tmp: Path, tag: str) -> np.ndarray:
    pov_file, ppm = tmp / f"{tag}.pov", tmp / f"{tag}.ppm"
    pov_file.write_text(_scene(function))
    subprocess.run([pov.povray_binary(), f"+I{pov_file}", f"+O{ppm}", f"+W{size}", f"+H{size}",
                    "+FP16", "File_Gamma=1.0", "-D", "-V", "+WT2", "-A"],
                   check=True, capture_output=True)
    return read_ppm(ppm)[..., 0].astype(float) / 65535.0


def floor_radius(lobe: M.Lobe, radius_px: np.ndarray, floor_z_mm: float = FLOOR_Z_MM) -> np.ndarray:
    """Distance from the axis (mm) where the ray of image radius radius_px meets the floor."""
    gamma = np.arctan(radius_px * M.PIXEL_MM / M.FOCAL_MM)
    beta = lobe.beta
    theta = 2.0 * np.arctan(np.tan((gamma - beta) / 2.0) / lobe.k) - beta
    return lobe.r_focus + (lobe.z_focus - floor_z_mm) * np.tan(theta)


def check(range_mm: float = 40000.0) -> dict:
    """Per-lobe radial error in pixels (median, max) and azimuth error (deg, max).
    The 16-bit ramp over range_mm limits the resolution to range_mm / 65535."""
    size = M.IMAGE_PX
    with tempfile.TemporaryDirectory(prefix="omnislam-geo-") as tmp:
        got_r = _render16(f"sqrt(x*x+y*y)/{range_mm!r}", size, Path(tmp), "r") * range_mm
        got_az = (_render16("atan2(y,x)/(2*pi)+0.5", size, Path(tmp), "az") - 0.5) * 2 * math.pi
    v, u = np.mgrid[0:size, 0:size].astype(float)
    radius = np.hypot(u - M.CENTER_PX, v - M.CENTER_PX)
    expected_az = np.arctan2(v - M.CENTER_PX, u - M.CENTER_PX)
    out = {}
    # Pixels whose centre lies at least half a pixel inside the lobe's annulus.
    for lobe, lo, hi in ((M.INNER, M.R_CENTRAL_PX + 0.5, M.R_SPLIT_PX - 0.5),
                         (M.OUTER, M.R_SPLIT_PX + 0.5, M.R_RIM_PX - 0.5)):
        sel = (radius > lo) & (radius < hi)
        expected = floor_radius(lobe, radius[sel])
        ok = np.isfinite(expected) & (expected > 0) & (expected < 0.999 * range_mm)
        h = 1e-3
        drdR = (floor_radius(lobe, radius[sel] + h) - floor_radius(lobe, radius[sel] - h)) / (2 * h)
        err_px = ((got_r[sel] - expected) / drdR)[ok]
        err_az = np.angle(np.exp(1j * (got_az[sel] - expected_az[sel])))[ok]
        out[lobe.name] = {"pixels": int(ok.sum()),
                          "median_abs_px": float(np.median(np.abs(err_px))),
                          "max_abs_px": float(np.abs(err_px).max()),
                          "mean_px": float(err_px.mean()),
                          "max_abs_az_deg": float(np.degrees(np.abs(err_az)).max())}
    return out


def rig_check(rig: M.Rig, size: int = 128, range_mm: float = 20000.0,
              trace_rigs: tuple[M.Rig, ...] | None = None) -> list[dict]:
    """The renderer against mirror.trace for an assembled rig (issue 12): a floor plane
    carries 16-bit ramps of x and y; at each pixel whose centre is 3 px inside a lobe's
    designed annulus, the rendered floor point is compared with the traced ray's floor
    point, the error converted to image pixels through the local floor-per-pixel Jacobian.
    Renders at size x size (each pixel covers 1024/size design pixels at their centre).
    One result per rig of `trace_rigs` (default: the rendered rig alone)."""
    def scene(function: str) -> str:
        return ("#version 3.7;\nglobal_settings { assumed_gamma 1.0 max_trace_level 5 }\n"
                f"plane {{ z, {FLOOR_Z_MM} pigment {{ function {{ {function} }} "
                "color_map { [0 rgb 0][1 rgb 1] } } finish { ambient 1 diffuse 0 } }\n"
                + pov.camera_block(rig) + pov.mirror_block(rig))

    images = {}
    with tempfile.TemporaryDirectory(prefix="omnislam-rig-") as tmp:
        for axis in ("x", "y"):
            pov_file, ppm = Path(tmp) / f"{axis}.pov", Path(tmp) / f"{axis}.ppm"
            pov_file.write_text(scene(f"{axis}/{2 * range_mm!r}+0.5"))
            subprocess.run([pov.povray_binary(), f"+I{pov_file}", f"+O{ppm}", f"+W{size}", f"+H{size}",
                            "+FP16", "File_Gamma=1.0", "-D", "-V", "+WT2", "-A"],
                           check=True, capture_output=True)
            images[axis] = (read_ppm(ppm)[..., 0].astype(float) / 65535.0 - 0.5) * 2 * range_mm
    return [_compare_floor(images, trace_rig, size, range_mm) for trace_rig in (trace_rigs or (rig,))]


def _compare_floor(images: dict, rig: M.Rig, size: int, range_mm: float) -> dict:
    scale = M.IMAGE_PX / size
    out = {}
    for lobe, lo, hi in ((M.INNER, M.R_CENTRAL_PX + 3, M.R_SPLIT_PX - 3),
                         (M.OUTER, M.R_SPLIT_PX + 3, M.R_RIM_PX - 3)):
        errors = []
        for row in range(size):
            for col in range(size):
                u, v = (col + 0.5) * scale - 0.5, (row + 0.5) * scale - 0.5
                radius = math.hypot(u - M.CENTER_PX, v - M.CENTER_PX)
                if not lo < radius < hi:
                    continue
                rays = [M.trace(lobe, u + du, v + dv, rig) for du, dv in ((0.0, 0.0), (0.5, 0.0), (0.0, 0.5))]
                if any(r is None or r[1][2] >= 0 for r in rays):
                    continue
                floor = []
                for origin, direction in rays:
                    t = (FLOOR_Z_MM - origin[2]) / direction[2]
                    floor.append((origin[0] + t * direction[0], origin[1] + t * direction[1]))
                if math.hypot(*floor[0]) > 0.9 * range_mm:
                    continue
                # The floor error in image pixels: solve J delta = error, J = d floor / d pixel.
                j = [[(floor[1][0] - floor[0][0]) / 0.5, (floor[2][0] - floor[0][0]) / 0.5],
                     [(floor[1][1] - floor[0][1]) / 0.5, (floor[2][1] - floor[0][1]) / 0.5]]
                det = j[0][0] * j[1][1] - j[0][1] * j[1][0]
                ex, ey = images["x"][row, col] - floor[0][0], images["y"][row, col] - floor[0][1]
                errors.append(math.hypot(j[1][1] * ex - j[0][1] * ey, -j[1][0] * ex + j[0][0] * ey) / abs(det))
        errors.sort()
        out[lobe.name] = {"pixels": len(errors), "median_px": errors[len(errors) // 2],
                          "p95_px": errors[int(0.95 * len(errors))]}
    return out
