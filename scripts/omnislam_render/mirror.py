"""Double-lobed hyperbolic mirror of mirror.md (thesis 2008), in millimetres.

All constants are derived in double precision from table 1.1 exactly as
mirror.md sec. 1 prescribes.  This module gives
  * the lobe parameters and the camera constants,
  * the forward projection of mirror.md sec. 4 (used by tests and checks),
  * the mirror point hit by the camera ray of a given image radius (sec. 2),
  * the implicit surfaces as polynomials in (x, y, w) with w = z - z_ref,
    ready to be written as POV-Ray `polynomial` objects.
"""
from __future__ import annotations

import math
from dataclasses import dataclass

FOCAL_MM = 25.0
RHO_MAX_MM = 3.5945
IMAGE_PX = 1024
PIXEL_MM = RHO_MAX_MM / 512.0
CENTER_PX = (IMAGE_PX - 1) / 2.0  # 511.5: pixel centres at integers

# Image radii (px) that bound the lobes in the image (mirror.md sec. 0).
R_CENTRAL_PX = 62.0
R_SPLIT_PX = 287.0
R_RIM_PX = 512.0


@dataclass(frozen=True)
class Lobe:
    name: str
    r_focus: float
    z_focus: float
    a: float

    @property
    def c(self) -> float:
        return math.hypot(self.r_focus, self.z_focus) / 2.0

    @property
    def b(self) -> float:
        return math.sqrt(self.c ** 2 - self.a ** 2)

    @property
    def k(self) -> float:
        return (self.c - self.a) / (self.c + self.a)

    @property
    def beta(self) -> float:
        return math.atan2(self.r_focus, self.z_focus)

    # --- forward projection (mirror.md sec. 4) --------------------------
    def rho_of_point(self, r_p: float, z_p: float) -> float:
        """Image radius (mm) of the world point (r_p, z_p) (z relative to F0)."""
        theta = math.atan2(r_p - self.r_focus, self.z_focus - z_p)
        beta = self.beta
        gamma = beta + 2.0 * math.atan(self.k * math.tan((theta + beta) / 2.0))
        return FOCAL_MM * math.tan(gamma)

    # --- camera ray -> mirror point (mirror.md sec. 2) -------------------
    def mirror_point(self, rho_mm: float) -> tuple[float, float]:
        """(r, z) of the lobe point seen at image radius rho_mm."""
        gamma = math.atan2(rho_mm, FOCAL_MM)
        d0 = self.b ** 2 / (self.c * math.cos(gamma - self.beta) - self.a)
        return d0 * math.sin(gamma), d0 * math.cos(gamma)

    # --- implicit profile --------------------------------------------------
    def profile_value(self, r: float, z: float) -> float:
        """((z_E - c)/a)^2 - (r_E/b)^2 - 1: zero on both branches of the profile."""
        s, co = math.sin(self.beta), math.cos(self.beta)
        r_e = r * co - z * s
        z_e = r * s + z * co
        return ((z_e - self.c) / self.a) ** 2 - (r_e / self.b) ** 2 - 1.0

    def profile_coefficients(self, z_ref: float) -> dict[str, float]:
        """Coefficients of the profile Q(r, w) = A r^2 + B r w + C w^2 + D r + E w + F,
        w = z - z_ref, equal to profile_value (so Q = 0 on the lobe)."""
        s, co = math.sin(self.beta), math.cos(self.beta)
        a2, b2 = self.a ** 2, self.b ** 2
        g = co * z_ref - self.c       # z_E - c = s r + co w + g
        h = -s * z_ref                # r_E     = co r - s w + h
        return {
            "A": s * s / a2 - co * co / b2,
            "B": 2.0 * s * co / a2 + 2.0 * s * co / b2,
            "C": co * co / a2 - s * s / b2,
            "D": 2.0 * s * g / a2 - 2.0 * co * h / b2,
            "E": 2.0 * co * g / a2 + 2.0 * s * h / b2,
            "F": g * g / a2 - h * h / b2 - 1.0,
        }


INNER = Lobe("inner", 0.0, 270.3, 123.794)
OUTER = Lobe("outer", 25.756, 420.3, 193.610)


def rho_px(lobe: Lobe, r_p: float, z_p: float) -> float:
    """Image radius in pixels of a world point (mm, z relative to the pinhole)."""
    return lobe.rho_of_point(r_p, z_p) / PIXEL_MM


# --- polynomials in (x, y, w) -------------------------------------------------
Poly = dict  # {(i, j, k): coefficient} for x^i y^j w^k


def _add(p: Poly, q: Poly, sign: float = 1.0) -> Poly:
    out = dict(p)
    for key, val in q.items():
        out[key] = out.get(key, 0.0) + sign * val
    return out


def _mul(p: Poly, q: Poly) -> Poly:
    out: Poly = {}
    for (i1, j1, k1), v1 in p.items():
        for (i2, j2, k2), v2 in q.items():
            key = (i1 + i2, j1 + j2, k1 + k2)
            out[key] = out.get(key, 0.0) + v1 * v2
    return out


def surface_polynomial(lobe: Lobe, z_ref: float, scale: float = 1.0) -> Poly:
    """Implicit surface of the lobe revolved about the camera axis, local coordinates
    (x, y, w = z - z_ref).  With beta = 0 this is the quadric Q(sqrt(x^2+y^2), w) = 0.
    With beta != 0 the odd powers of r are removed by squaring:
        Q = P(rho2, w) + r L(w) = 0   ->   P^2 - rho2 L^2 = 0   (quartic),
    which also holds on the profile mirrored in r; callers must clip to the lobe.
    `scale` multiplies Q (to keep the coefficients near 1)."""
    q = {k: v * scale for k, v in lobe.profile_coefficients(z_ref).items()}
    rho2 = {(2, 0, 0): 1.0, (0, 2, 0): 1.0}
    even = _add({(0, 0, 2): q["C"], (0, 0, 1): q["E"], (0, 0, 0): q["F"]},
                {k: q["A"] * v for k, v in rho2.items()})
    odd = {(0, 0, 1): q["B"], (0, 0, 0): q["D"]}
    if q["B"] == 0.0 and q["D"] == 0.0:
        return {k: v for k, v in even.items() if v != 0.0}
    quartic = _add(_mul(even, even), _mul(rho2, _mul(odd, odd)), -1.0)
    return {k: v for k, v in quartic.items() if v != 0.0}


def eval_poly(p: Poly, x: float, y: float, w: float) -> float:
    return sum(v * x ** i * y ** j * w ** k for (i, j, k), v in p.items())


# --- a real rig: the camera and mirror as assembled (issue 12) ----------------
@dataclass(frozen=True)
class Rig:
    """Misalignments of an assembled rig, with the meaning of the C++ RigConfig
    (modules/mirror/include/omnislam/mirror/mirror_config.hpp) and the same config keys:
    the mirror (both lobes, rigid) is placed in the camera frame by
        p_camera = R (p_design - pivot) + pivot + (offset_x, offset_y, dz),
        R = Ry(tilt_y) Rx(tilt_x),  pivot = (0, 0, z of the inner focus),
    the true focal length is focal_scale * FOCAL_MM and the optical axis is at center_px.
    level_tilt_deg turns the whole rig (camera and mirror) about the pinhole away from
    level, about the camera x then y axis (right-handed, R = Ry(y) Rx(x)): the world seen
    from the camera is turned by R^T (config key level_tilt_deg). The defaults are the design."""
    focal_scale: float = 1.0
    mirror_dz_mm: float = 0.0
    tilt_deg: tuple[float, float] = (0.0, 0.0)
    offset_mm: tuple[float, float] = (0.0, 0.0)
    center_px: tuple[float, float] = (CENTER_PX, CENTER_PX)
    level_tilt_deg: tuple[float, float] = (0.0, 0.0)
    # A support rod holding the mirror (the thesis's rig had one, "haste de suporte"): a
    # vertical cylinder beside the mirror's rim at this robot-frame azimuth (deg), seen by
    # both lobes, never by the camera directly. Not part of the camera model: no config key.
    rod_azimuth_deg: float | None = None
    rod_diameter_mm: float = 10.0

    def nominal(self) -> bool:
        return self == Rig()

    def mirror_moved(self) -> bool:
        return (self.mirror_dz_mm, self.tilt_deg, self.offset_mm) != (0.0, (0.0, 0.0), (0.0, 0.0))

    @property
    def pivot(self) -> tuple[float, float, float]:
        return (0.0, 0.0, INNER.z_focus)

    def rotation(self) -> list[list[float]]:
        """R = Ry(tilt_y) Rx(tilt_x), rows."""
        ax, ay = (math.radians(a) for a in self.tilt_deg)
        cx, sx, cy, sy = math.cos(ax), math.sin(ax), math.cos(ay), math.sin(ay)
        rx = [[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]]
        ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]]
        return [[sum(ry[i][k] * rx[k][j] for k in range(3)) for j in range(3)] for i in range(3)]

    def translation(self) -> tuple[float, float, float]:
        """t in p_camera = R p_design + t."""
        r, p = self.rotation(), self.pivot
        shift = (self.offset_mm[0], self.offset_mm[1], self.mirror_dz_mm)
        return tuple(p[i] + shift[i] - sum(r[i][k] * p[k] for k in range(3)) for i in range(3))

    def to_camera(self, p: tuple[float, float, float]) -> tuple[float, float, float]:
        r, t = self.rotation(), self.translation()
        return tuple(sum(r[i][k] * p[k] for k in range(3)) + t[i] for i in range(3))

    def to_design(self, p: tuple[float, float, float]) -> tuple[float, float, float]:
        r, t = self.rotation(), self.translation()
        q = [p[i] - t[i] for i in range(3)]
        return tuple(sum(r[k][i] * q[k] for k in range(3)) for i in range(3))

    def yaml_fields(self) -> str:
        """The camera keys of this rig for dataset.yaml / a config (empty when nominal)."""
        out = ""
        if self.focal_scale != 1.0:
            out += f", focal_scale: {self.focal_scale!r}"
        if self.mirror_dz_mm != 0.0:
            out += f", mirror_dz_mm: {self.mirror_dz_mm!r}"
        if self.tilt_deg != (0.0, 0.0):
            out += f", mirror_tilt_deg: [{self.tilt_deg[0]!r}, {self.tilt_deg[1]!r}]"
        if self.offset_mm != (0.0, 0.0):
            out += f", mirror_offset_mm: [{self.offset_mm[0]!r}, {self.offset_mm[1]!r}]"
        if self.level_tilt_deg != (0.0, 0.0):
            out += f", level_tilt_deg: [{self.level_tilt_deg[0]!r}, {self.level_tilt_deg[1]!r}]"
        return out


def trace(lobe: Lobe, u_px: float, v_px: float, rig: Rig = Rig()):
    """The world ray of image pixel (u, v) through `lobe` of `rig`, traced explicitly
    (camera ray, the lobe's implicit profile in the mirror's pose, law of reflection):
    ((origin), (unit direction)) in camera-frame mm, or None when the ray misses.
    Bisection on the profile between the lobe's vertex side and its rim side, so it
    shares no iteration with the C++ model's Newton steps."""
    d_cam = ((u_px - rig.center_px[0]) * PIXEL_MM, (v_px - rig.center_px[1]) * PIXEL_MM,
             FOCAL_MM * rig.focal_scale)
    n = math.sqrt(sum(c * c for c in d_cam))
    d_cam = tuple(c / n for c in d_cam)
    o = rig.to_design((0.0, 0.0, 0.0))
    far = rig.to_design(d_cam)
    d = tuple(far[i] - o[i] for i in range(3))

    def g(t: float) -> float:
        p = [o[i] + t * d[i] for i in range(3)]
        return lobe.profile_value(math.hypot(p[0], p[1]), p[2])

    # From the pinhole the camera ray crosses the hyperboloid's near sheet (g turns < 0 at
    # about c - a) and then the mirror sheet (g > 0 again) once before 2.2 c.
    lo, hi = lobe.c, 2.2 * lobe.c
    if g(lo) * g(hi) > 0.0:
        return None
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if g(lo) * g(mid) <= 0.0:
            hi = mid
        else:
            lo = mid
    t = 0.5 * (lo + hi)
    p = [o[i] + t * d[i] for i in range(3)]
    # Normal: numerical gradient of the profile revolved about the mirror axis.
    h = 1e-6

    def f(q):
        return lobe.profile_value(math.hypot(q[0], q[1]), q[2])
    grad = []
    for i in range(3):
        qp, qm = list(p), list(p)
        qp[i] += h
        qm[i] -= h
        grad.append((f(qp) - f(qm)) / (2 * h))
    gn = math.sqrt(sum(c * c for c in grad))
    nrm = [c / gn for c in grad]
    dot = sum(d[i] * nrm[i] for i in range(3))
    refl = [d[i] - 2.0 * dot * nrm[i] for i in range(3)]
    origin = rig.to_camera(tuple(p))
    zero = rig.to_camera((0.0, 0.0, 0.0))
    tip = rig.to_camera(tuple(refl))
    direction = tuple(tip[i] - zero[i] for i in range(3))
    return origin, direction
