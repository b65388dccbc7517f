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
