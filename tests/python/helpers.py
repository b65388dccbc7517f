"""Small readers, image helpers and the omnislamd harness used by the tests."""
from __future__ import annotations

import contextlib
import csv
import math
import os
import subprocess
from pathlib import Path

import numpy as np

from omnislam_render.geometry import between, read_tum

TRAJECTORIES = Path(__file__).resolve().parents[2] / "scripts" / "omnislam_render" / "data" / "trajectories.csv"


def dds_domain(offset: int) -> int:
    """A DDS domain id of this test process (100-199): each DDS test file its own offset, so
    that tests running at once do not hear each other."""
    return 100 + (os.getpid() * 2 + offset) % 100


@contextlib.contextmanager
def omnislamd(work: Path, config_yaml: str):
    """omnislamd (OMNISLAMD_BIN) on `config_yaml`, written to WORK/omnislamd.yaml, its journal
    to WORK/omnislamd.log; killed on leaving if it is still running."""
    config = work / "omnislamd.yaml"
    config.write_text(config_yaml)
    with (work / "omnislamd.log").open("w") as log:
        service = subprocess.Popen([os.environ["OMNISLAMD_BIN"], "--config", str(config)], stdout=log,
                                   stderr=subprocess.STDOUT)
        try:
            yield service
        finally:
            if service.poll() is None:
                service.kill()
                service.wait()


def table_mm(table: str) -> list[tuple[float, float]]:
    rows = []
    with open(TRAJECTORIES) as fh:
        for row in csv.reader(ln for ln in fh if not ln.startswith("#")):
            if row and row[0] == table:
                rows.append((int(row[1]), float(row[2]), float(row[3])))
    return [(x, y) for _, x, y in sorted(rows)]


def poses(path: Path):
    return [p for _, p in read_tum(path)]


def times(path: Path):
    return [t for t, _ in read_tum(path)]


def steps(traj):
    return [between(a, b) for a, b in zip(traj[:-1], traj[1:])]


def angle_diff(a: float, b: float) -> float:
    return math.atan2(math.sin(a - b), math.cos(a - b))


def first_hits(segments: np.ndarray, x0: float, y0: float, directions: np.ndarray):
    """For plan rays from (x0, y0) along unit `directions` (N, 2): distance to and
    index of the first floor-plan segment hit (inf, -1 when none)."""
    p1, p2 = segments[:, :2], segments[:, 2:]
    e = p2 - p1                                        # (S, 2)
    d = directions[:, None, :]                         # (N, 1, 2)
    w = p1[None, :, :] - np.array([x0, y0])            # (1, S, 2)
    det = -d[..., 0] * e[None, :, 1] + d[..., 1] * e[None, :, 0]
    with np.errstate(divide="ignore", invalid="ignore"):
        t = (-w[..., 0] * e[None, :, 1] + w[..., 1] * e[None, :, 0]) / det
        s = (d[..., 0] * w[..., 1] - d[..., 1] * w[..., 0]) / det
    ok = (np.abs(det) > 1e-12) & (t > 0) & (s >= -1e-9) & (s <= 1 + 1e-9)
    t = np.where(ok, t, np.inf)
    idx = np.argmin(t, axis=1)
    dist = t[np.arange(len(t)), idx]
    return dist, np.where(np.isfinite(dist), idx, -1)


def floor_wall_edge_errors(img: np.ndarray, segments: np.ndarray, n_walls: int, pose, camera_height_mm: float):
    """Image-radius error (px) of the floor-wall boundary, per lobe, measured along
    azimuths whose first plan hit (and that of +-1.5 deg) is a wall.  The edge is the
    half-level crossing of the (linearised) brightness along the radial line."""
    from omnislam_render import mirror as M

    gray = ((img[..., :3].astype(float) / 255.0) ** 2.2).mean(axis=2)
    x0, y0, yaw = pose
    az = np.radians(np.arange(0.5, 360.0, 1.0))
    hits = [first_hits(segments, x0, y0, np.stack([np.cos(az + yaw + o), np.sin(az + yaw + o)], axis=1))
            for o in (0.0, math.radians(-1.5), math.radians(1.5))]
    errors = {"inner": [], "outer": []}
    for i, a in enumerate(az):
        k = hits[0][1][i]
        if not (0 <= k < n_walls and hits[1][1][i] == k and hits[2][1][i] == k):
            continue
        for lobe, lo, hi in ((M.INNER, M.R_CENTRAL_PX, M.R_SPLIT_PX), (M.OUTER, M.R_SPLIT_PX, M.R_RIM_PX)):
            pred = M.rho_px(lobe, hits[0][0][i] * 1000.0, -camera_height_mm)
            if not lo + 8 < pred < hi - 8:
                continue
            radii = np.arange(pred - 4, pred + 4, 0.02)
            u, v = M.CENTER_PX + radii * math.cos(a), M.CENTER_PX + radii * math.sin(a)
            u0, v0 = np.floor(u).astype(int), np.floor(v).astype(int)
            fu, fv = u - u0, v - v0
            prof = (gray[v0, u0] * (1 - fu) * (1 - fv) + gray[v0, u0 + 1] * fu * (1 - fv)
                    + gray[v0 + 1, u0] * (1 - fu) * fv + gray[v0 + 1, u0 + 1] * fu * fv)
            near, far = prof[:20].mean(), prof[-20:].mean()
            if abs(far - near) < 0.05:
                continue
            cross = np.nonzero(np.diff(np.sign(prof - (near + far) / 2)))[0]
            if len(cross) != 1:
                continue
            j = cross[0]
            r = radii[j] + ((near + far) / 2 - prof[j]) / (prof[j + 1] - prof[j]) * 0.02
            errors[lobe.name].append(r - pred)
    return {k: np.array(v) for k, v in errors.items()}


def shifted(image, du, dv):
    """The image moved by (du, dv) px, bilinear, black where nothing was (the whole rig's
    picture moves when the mirror's axis is off the camera's)."""
    iu, iv = int(np.floor(du)), int(np.floor(dv))
    fu, fv = du - iu, dv - iv

    def take(oy, ox):  # out[y, x] = image[y - oy, x - ox], zero outside
        out = np.zeros_like(image, dtype=float)
        h, w = image.shape
        ys, xs = slice(max(0, oy), min(h, h + oy)), slice(max(0, ox), min(w, w + ox))
        yi, xi = slice(max(0, -oy), min(h, h - oy)), slice(max(0, -ox), min(w, w - ox))
        out[ys, xs] = image[yi, xi]
        return out

    out = ((1 - fu) * (1 - fv) * take(iv, iu) + fu * (1 - fv) * take(iv, iu + 1)
           + (1 - fu) * fv * take(iv + 1, iu) + fu * fv * take(iv + 1, iu + 1))
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


def covariance_consistency(run_dir: Path, dataset_dir: Path) -> tuple[float, float]:
    """(mean NEES of (x, y, yaw), share of positions inside their own 95% ellipse) of a run's
    published poses (trajectory_online.tum) and covariance.csv against the dataset's ground
    truth, matched by time stamp; frames with a singular covariance (the first) are left out.
    Computed here from the files, independently of `omnislam evaluate`."""
    truth = {round(t, 6): p for t, p in read_tum(Path(dataset_dir) / "groundtruth.tum")}
    published = {round(t, 6): p for t, p in read_tum(Path(run_dir) / "trajectory_online.tum")}
    nees, inside = [], 0
    with open(Path(run_dir) / "covariance.csv") as fh:
        for row in csv.DictReader(fh):
            t = round(float(row["t"]), 6)
            if t not in truth or t not in published:
                continue
            xx, xy, yy = float(row["xx_m2"]), float(row["xy_m2"]), float(row["yy_m2"])
            xa, ya, aa = float(row["xyaw_m_rad"]), float(row["yyaw_m_rad"]), float(row["yawyaw_rad2"])
            cov = np.array([[xx, xy, xa], [xy, yy, ya], [xa, ya, aa]])
            if np.linalg.det(cov) <= 0.0:
                continue
            e = np.array(published[t]) - np.array(truth[t])
            e[2] = angle_diff(published[t][2], truth[t][2])
            nees.append(float(e @ np.linalg.solve(cov, e)))
            inside += float(e[:2] @ np.linalg.solve(cov[:2, :2], e[:2])) <= 5.991  # chi2(2) 95%
    assert nees, f"no frame of {run_dir} has a covariance to check"
    return float(np.mean(nees)), inside / len(nees)
