"""Render the convention-check scene (architecture.md, reference/convention-check)
with this renderer's camera and mirror, and compare it with the reference image."""
from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from . import mirror as M
from . import pov
from .pngio import read_png

# The reference image was rendered with POV-Ray's default adaptive antialiasing.
REFERENCE_ANTIALIAS = "+A0.3 +AM1"

DATA_DIR = Path(__file__).resolve().parents[2] / "tests" / "python" / "data" / "convention-check"


def scene_text(excerpt: Path = DATA_DIR / "scene-excerpt.pov.txt") -> str:
    lines = [ln for ln in excerpt.read_text().splitlines() if not ln.lstrip().startswith("camera")]
    return "\n".join(lines) + "\n" + pov.camera_block() + pov.mirror_block()


def render_convention(png_file: Path, antialias: str | None = REFERENCE_ANTIALIAS, threads: int = 2) -> float:
    with tempfile.TemporaryDirectory(prefix="omnislam-conv-") as tmp:
        pov_file = Path(tmp) / "convention.pov"
        pov_file.write_text(scene_text())
        return pov.render(pov_file, Path(png_file), antialias=antialias, threads=threads)


def colour_azimuths_deg(img: np.ndarray, colour: str) -> np.ndarray:
    """Image angles atan2(v - cy, u - cx) in degrees of the saturated red or blue pixels."""
    rgb = img[..., :3].astype(int)
    r, g, b = rgb[..., 0], rgb[..., 1], rgb[..., 2]
    if colour == "red":
        mask = (r > 120) & (r > 2 * g) & (r > 2 * b)
    else:
        mask = (b > 120) & (b > 2 * r) & (b > g + 60)
    v, u = np.nonzero(mask)
    return np.degrees(np.arctan2(v - M.CENTER_PX, u - M.CENTER_PX))


def compare(img: np.ndarray, ref: np.ndarray) -> dict:
    diff = np.abs(img[..., :3].astype(int) - ref[..., :3].astype(int)).max(axis=2)
    out = {
        "mean_abs": float(np.abs(img[..., :3].astype(float) - ref[..., :3]).mean()),
        "max_abs": int(diff.max()),
        "px_diff_gt_8": int((diff > 8).sum()),
        "px_diff_gt_32": int((diff > 32).sum()),
        "px_diff_gt_64": int((diff > 64).sum()),
    }
    for colour in ("red", "blue"):
        az = colour_azimuths_deg(img, colour)
        az_ref = colour_azimuths_deg(ref, colour)
        out[colour] = {"pixels": int(az.size), "ref_pixels": int(az_ref.size),
                       "mean_az_deg": float(az.mean()), "ref_mean_az_deg": float(az_ref.mean())}
    return out


def check(png_file: Path, ref_file: Path = DATA_DIR / "image.png") -> dict:
    return compare(read_png(png_file), read_png(ref_file))
