"""POV-Ray scene text for the thesis camera and mirror, and the povray call.

Scene units are millimetres with the camera pinhole F0 at the origin and z up
(mirror.md sec. 0).  POV-Ray's axes are left-handed, but only the camera
vectors decide how the scene lands on the image: `right +x` and `up -y` put
image u along +x and image v along +y (architecture.md image convention),
checked against the convention-check reference render.
"""
from __future__ import annotations

import math
import shutil
import subprocess
import time
from pathlib import Path

from . import mirror as M
from .pngio import read_ppm, strip_timestamps, to_gray, write_png_gray

# Height band (around each lobe) used with the annulus to clip the implicit
# surfaces: wide enough to hold the lobe, narrow enough to exclude the other
# branch of the hyperboloid (z < 15) and, for the outer lobe, the profile
# mirrored in r that squaring brings in (z > 450 in the annulus).
_BAND_MARGIN_MM = 4.0


def num(x: float) -> str:
    """Full double precision, POV-Ray syntax."""
    return repr(float(x))


def vec(*xs: float) -> str:
    return "<" + ", ".join(num(x) for x in xs) + ">"


def camera_block(rig: M.Rig = M.Rig()) -> str:
    half = M.RHO_MAX_MM * M.IMAGE_PX / 1024.0  # half the sensor width: 512 px
    width = 2.0 * half
    # POV-Ray's ray for image point (sx, sy) in [-1/2, 1/2] is direction + sx right + sy up,
    # so pixel u sees direction + (u - 511.5) pitch x: moving `direction` off the image
    # centre puts the optical axis at rig.center_px, and its length is the focal length.
    du = (M.CENTER_PX - rig.center_px[0]) * M.PIXEL_MM
    dv = (M.CENTER_PX - rig.center_px[1]) * M.PIXEL_MM
    return (
        "// Pinhole F0 at the origin looking up (+z); image u -> +x, v -> +y.\n"
        f"camera {{ perspective location <0,0,0> direction {vec(du, dv, M.FOCAL_MM * rig.focal_scale)}\n"
        f"         right {vec(width, 0, 0)} up {vec(0, -width, 0)} }}\n"
    )


def rig_transform(rig: M.Rig) -> str:
    """The mirror's pose as a POV-Ray matrix (p' = p M with p a row vector: the rows of M
    are the images of the axes, i.e. the columns of R, then the translation)."""
    r, t = rig.rotation(), rig.translation()
    entries = [r[j][i] for i in range(3) for j in range(3)] + list(t)
    return "matrix <" + ", ".join(num(x) for x in entries) + ">"


def _polynomial(poly: dict) -> str:
    order = max(i + j + k for (i, j, k) in poly)
    terms = ",\n    ".join(
        f"xyz({i},{j},{k}):{num(v)}" for (i, j, k), v in sorted(poly.items(), reverse=True))
    # POV-Ray's direct quartic solver; `sturm` gave the same pixels (checked with
    # geocheck and the convention check) at twice the cost.
    return f"polynomial {{ {order},\n    {terms}\n  }}"


def _lobe_block(lobe: M.Lobe, r_in_px: float, r_out_px: float) -> str:
    r_in, z_in = lobe.mirror_point(r_in_px * M.PIXEL_MM)
    r_out, z_out = lobe.mirror_point(r_out_px * M.PIXEL_MM)
    z_lo = min(z_in, z_out) - _BAND_MARGIN_MM
    z_hi = max(z_in, z_out) + _BAND_MARGIN_MM
    z_ref = 0.5 * (z_lo + z_hi)
    poly = M.surface_polynomial(lobe, z_ref, scale=lobe.b ** 2)
    w_lo, w_hi = z_lo - z_ref, z_hi - z_ref
    return (
        f"// {lobe.name} lobe: a={num(lobe.a)} c={num(lobe.c)} b={num(lobe.b)}"
        f" focus=({num(lobe.r_focus)}, {num(lobe.z_focus)}) beta={num(lobe.beta)} rad\n"
        f"// annulus r {num(r_in)}..{num(r_out)} mm (image radius {r_in_px}..{r_out_px} px)\n"
        "object {\n  " + _polynomial(poly) + "\n"
        "  clipped_by { intersection {\n"
        f"    cylinder {{ {vec(0, 0, w_lo)}, {vec(0, 0, w_hi)}, {num(r_out)} }}\n"
        f"    cylinder {{ {vec(0, 0, w_lo - 1)}, {vec(0, 0, w_hi + 1)}, {num(r_in)} inverse }}\n"
        "  } }\n"
        f"  bounded_by {{ box {{ {vec(-r_out - 1, -r_out - 1, w_lo - 1)}, {vec(r_out + 1, r_out + 1, w_hi + 1)} }} }}\n"
        "  texture { Mirror_Finish }\n"
        "  no_shadow\n"
        f"  translate {vec(0, 0, z_ref)}\n"
        "}\n"
    )


def mirror_block(rig: M.Rig = M.Rig()) -> str:
    body = (
        _lobe_block(M.INNER, M.R_CENTRAL_PX, M.R_SPLIT_PX)
        + _lobe_block(M.OUTER, M.R_SPLIT_PX, M.R_RIM_PX)
        + "// Black cap above the mirror: camera rays that miss both lobes end here.\n"
        "disc { <0,0,440>, -z, 400 pigment { rgb 0 } finish { ambient 0 diffuse 0 } no_shadow }\n"
    )
    body += rod_block(rig)
    if rig.mirror_moved():
        # The lobes are cut (clipped) in the mirror's own frame, so the whole part moves.
        body = ("// The mirror as mounted: tilted and shifted (issue 12, mirror.Rig).\n"
                "union {\n" + body + f"  {rig_transform(rig)}\n}}\n")
    return (
        "// Double-lobed mirror (mirror.md), perfect reflector, exact implicit surfaces.\n"
        "#declare Mirror_Finish = texture { pigment { rgb 0 }\n"
        "  finish { ambient 0 diffuse 0 specular 0 phong 0 reflection { 1 } } }\n"
        + body
    )


# Where the support rod stands: its axis 15 mm outside the mirror's rim (60 mm), from the
# robot's top plate below the camera to the cap above the mirror; dull grey metal.
ROD_AXIS_RADIUS_MM = 75.0
ROD_Z_MM = (-150.0, 440.0)


def rod_block(rig: M.Rig) -> str:
    """The rig's support rod (rig.rod_azimuth_deg), fixed to the camera: it does not move
    with the room, so every frame shows it at the same place."""
    if rig.rod_azimuth_deg is None:
        return ""
    a = math.radians(rig.rod_azimuth_deg)
    x, y = ROD_AXIS_RADIUS_MM * math.cos(a), ROD_AXIS_RADIUS_MM * math.sin(a)
    return (f"// Support rod at azimuth {num(rig.rod_azimuth_deg)} deg, {num(rig.rod_diameter_mm)} mm thick.\n"
            f"cylinder {{ {vec(x, y, ROD_Z_MM[0])}, {vec(x, y, ROD_Z_MM[1])}, {num(rig.rod_diameter_mm / 2)}\n"
            "  pigment { rgb <0.45, 0.45, 0.47> } finish { ambient 0.1 diffuse 0.6 specular 0.4 roughness 0.02 } }\n")


def povray_binary(wait_s: float = 600.0) -> str:
    """Path of povray; waits for it while `scripts/setup` may still be installing it."""
    deadline = time.monotonic() + wait_s
    while True:
        found = shutil.which("povray")
        if found:
            return found
        if time.monotonic() > deadline:
            raise FileNotFoundError("povray not found (run scripts/setup)")
        time.sleep(5)


def render(pov_file: Path, png_file: Path, width: int = M.IMAGE_PX, height: int = M.IMAGE_PX,
           threads: int = 2, antialias: str | None = "+A0.1 +AM2 +R2", grey: bool = False) -> float:
    """Render deterministically (no jitter) to an 8-bit PNG (RGB, or grey luma); returns
    wall seconds."""
    out_file = Path(png_file).with_suffix(".ppm") if grey else png_file
    args = [povray_binary(), f"+I{pov_file}", f"+O{out_file}", f"+W{width}", f"+H{height}",
            "+FP8" if grey else "+FN8", "-D", "-V", f"+WT{threads}", "-J"]
    args += antialias.split() if antialias else ["-A"]
    start = time.monotonic()
    proc = subprocess.run(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    if proc.returncode != 0 or not Path(out_file).exists():
        raise RuntimeError(f"povray failed on {pov_file}:\n{proc.stderr[-3000:]}")
    if grey:
        write_png_gray(png_file, to_gray(read_ppm(out_file)))
        Path(out_file).unlink()
    else:
        strip_timestamps(png_file)
    return time.monotonic() - start
