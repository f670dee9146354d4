"""The field apparatus: coaxial coil pairs that make the paper's a1 and a2, and what else they make.

A circular loop of radius ``a`` at height ``z0`` on the Z axis, carrying ``I``, makes (Biot-Savart,
closed form in complete elliptic integrals; Jackson, Classical Electrodynamics, 3rd ed., sec. 5.5;
Simpson et al., NASA/TM-2001-210986)::

    B_rho = mu0 I z' / (2 pi alpha^2 beta rho) [(a^2 + rho^2 + z'^2) E(k^2) - alpha^2 K(k^2)]
    B_z   = mu0 I / (2 pi alpha^2 beta) [(a^2 - rho^2 - z'^2) E(k^2) + alpha^2 K(k^2)]

with ``z' = z - z0``, ``alpha^2 = a^2 + rho^2 + z'^2 - 2 a rho``, ``beta^2 = alpha^2 + 4 a rho``,
``k^2 = 1 - alpha^2 / beta^2``; on the axis ``B_z = mu0 I a^2 / (2 (a^2 + z'^2)^(3/2))``.

Inside the sphere through the loop the field is harmonic and axisymmetric, so it is the
project's Legendre series (:mod:`chargedesign.fields`, ``B = -grad Phi``,
``Phi = sum f_j R^j P_j(Z/R)``), read off the axis exactly: with ``D^2 = a^2 + z0^2``,
``u = z0 / D``, the generating function of the Gegenbauer polynomials gives

    B_z(z) = mu0 I a^2 / (2 D^3) sum_k C_k^(3/2)(u) (z / D)^k,   f_j = -b_(j-1) / j.

A Helmholtz pair (currents alike, separation = radius) makes ``a1`` with no degree-3 term; a
Maxwell gradient pair (currents opposed, separation sqrt(3) x radius) makes ``a2`` with no
degree-4 term. What remains (degree 5 of the first, 6 of the second, and beyond) is the
apparatus' harmonic error: terms the theorem does not have, which act on the magnets and
charges like any field. :func:`design_apparatus` sizes the coils so that this error over the
body region is a chosen fraction of the designed field.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.constants import MU_0
from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.field_bounds import field_magnitude_max
from chargedesign.physical.sources import value

#: Legendre degrees kept in a coil's series (the error terms beyond decay like (r / a)^j)
SERIES_DEGREE = 12
#: coil radii tried, in body-region radii (the smallest whose harmonic error is small enough)
COIL_RADII = (2.0, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0, 12.0, 15.0, 20.0, 30.0, 50.0)
#: the coils' harmonic error is kept below this share of the realised window's fraction (each
#: parasitic is held below the fraction on its own; half leaves a margin)
HARMONIC_SHARE = 0.5
#: resistivity of copper at 20 C, ohm m (sources table: coils.copper_resistivity)
COPPER_RESISTIVITY = value("coils.copper_resistivity")
#: current density of an air-cooled copper winding, A/m^2: 1-3 A/mm^2 without forced cooling
#: (Montgomery, Solenoid Magnet Design, Wiley 1969, ch. 1); 2 A/mm^2 used
#: (sources table: coils.air_cooled_current_density)
AIR_COOLED_CURRENT_DENSITY = value("coils.air_cooled_current_density")
#: cross-section of the wire the turns are counted in, m^2 (1 mm^2: AWG 17)
WIRE_SECTION = 1.0e-6


def loop_axis_field(z: Any, radius: float, z0: float, current: float) -> np.ndarray:
    """``B_z`` on the axis of a loop (T), the closed form; ``z`` in m, any shape."""
    z = np.asarray(z, dtype=float)
    return MU_0 * current * radius**2 / (2.0 * (radius**2 + (z - z0) ** 2) ** 1.5)


def loop_field(points: Any, radius: float, z0: float, current: float) -> np.ndarray:
    """Biot-Savart field of a circular loop coaxial with Z, at ``points`` (n, 3), T, (n, 3)."""
    from scipy.special import ellipe, ellipk

    pts = np.atleast_2d(np.asarray(points, dtype=float))
    x, y, zz = pts.T
    rho = np.hypot(x, y)
    zp = zz - z0
    r2 = radius**2 + rho**2 + zp**2
    alpha2 = r2 - 2.0 * radius * rho
    beta2 = r2 + 2.0 * radius * rho
    beta = np.sqrt(beta2)
    m = 1.0 - alpha2 / beta2
    big_k, big_e = ellipk(m), ellipe(m)
    c = MU_0 * current / math.pi
    bz = c / (2.0 * alpha2 * beta) * ((radius**2 - rho**2 - zp**2) * big_e + alpha2 * big_k)
    safe = np.where(rho > 0, rho, 1.0)
    b_rho = np.where(
        rho > 0, c * zp / (2.0 * alpha2 * beta * safe) * (r2 * big_e - alpha2 * big_k), 0.0
    )
    return np.column_stack([b_rho * x / safe, b_rho * y / safe, bz])


def loop_legendre(radius: float, z0: float, current: float, degree: int = SERIES_DEGREE):
    """The loop's field inside the sphere through it as Legendre coefficients ``(f_1..f_deg)``
    of ``Phi`` (``B = -grad Phi``), exact from the Gegenbauer expansion of the axis field."""
    from scipy.special import eval_gegenbauer

    dist = math.hypot(radius, z0)
    u = z0 / dist
    scale = MU_0 * current * radius**2 / (2.0 * dist**3)
    b = [scale * float(eval_gegenbauer(k, 1.5, u)) / dist**k for k in range(degree)]
    return tuple(-b[j - 1] / j for j in range(1, degree + 1))


@dataclass(frozen=True)
class CoilPair:
    """Two coaxial loops of ``turns`` turns at ``z = +- separation / 2``, currents alike
    (``helmholtz``) or opposed (``maxwell``); ``current`` is the current per turn of the
    upper coil, A (signed)."""

    kind: str
    radius: float
    separation: float
    turns: float
    current: float

    @property
    def signs(self) -> tuple[float, float]:
        return (1.0, 1.0) if self.kind == "helmholtz" else (1.0, -1.0)

    def legendre(self, degree: int = SERIES_DEGREE) -> tuple[float, ...]:
        total = np.zeros(degree)
        for sign, z0 in zip(self.signs, (self.separation / 2, -self.separation / 2), strict=True):
            total += loop_legendre(self.radius, z0, sign * self.turns * self.current, degree)
        return tuple(float(v) for v in total)

    def field(self, points: Any) -> np.ndarray:
        """Biot-Savart field of both coils at ``points`` (n, 3), T."""
        out = np.zeros((len(np.atleast_2d(points)), 3))
        for sign, z0 in zip(self.signs, (self.separation / 2, -self.separation / 2), strict=True):
            out += loop_field(points, self.radius, z0, sign * self.turns * self.current)
        return out

    @property
    def power_W(self) -> float:
        """Ohmic power of both coils' copper at the wire's current density, W."""
        length = 2.0 * 2.0 * math.pi * self.radius * self.turns
        return COPPER_RESISTIVITY * length * abs(self.current) ** 2 / WIRE_SECTION

    def to_dict(self) -> dict[str, Any]:
        return {
            "kind": self.kind,
            "radius_m": self.radius,
            "separation_m": self.separation,
            "turns": self.turns,
            "current_A": self.current,
            "ampere_turns": self.turns * self.current,
            "power_W": self.power_W,
        }


def _pair(kind: str, radius: float, target: float, index: int) -> CoilPair:
    """The pair of ``kind`` and ``radius`` whose Legendre coefficient ``index`` is ``target``,
    wound with :data:`WIRE_SECTION` wire at :data:`AIR_COOLED_CURRENT_DENSITY`."""
    separation = radius if kind == "helmholtz" else math.sqrt(3.0) * radius
    unit = CoilPair(kind, radius, separation, 1.0, 1.0).legendre(index + 1)[index]
    ampere_turns = target / unit
    current = math.copysign(AIR_COOLED_CURRENT_DENSITY * WIRE_SECTION, ampere_turns)
    return CoilPair(kind, radius, separation, abs(ampere_turns) / abs(current), current)


@dataclass
class Apparatus:
    """The coil pairs that make ``legendre[:2]`` (a1, 2 a2), and their harmonic error over the
    body region of radius ``region_radius``."""

    pairs: list[CoilPair]
    region_radius: float
    error_legendre: tuple[float, ...]
    #: largest |B_error| over the region over the largest designed |B| there
    harmonic_error: float
    wanted: float
    notes: list[str] = field(default_factory=list)

    @property
    def power_W(self) -> float:
        return float(sum(p.power_W for p in self.pairs))

    def to_dict(self) -> dict[str, Any]:
        return {
            "pairs": [p.to_dict() for p in self.pairs],
            "region_radius_m": self.region_radius,
            "harmonic_error": self.harmonic_error,
            "harmonic_error_wanted": self.wanted,
            "error_legendre": list(self.error_legendre),
            "power_W": self.power_W,
        }

    def __str__(self) -> str:
        lines = [
            f"{p.kind} pair: radius {fmt(p.radius)} m, {fmt(p.separation)} m apart, "
            f"{fmt(p.turns)} turns x {fmt(p.current)} A each, {fmt(p.power_W)} W"
            for p in self.pairs
        ]
        lines.append(
            f"harmonic error over the body region (r <= {fmt(self.region_radius)} m): "
            f"{fmt(self.harmonic_error)} of the designed field (wanted < "
            f"{fmt(self.wanted, PLAIN)})"
        )
        return "\n".join(lines)


def apparatus_at(
    a1: float, a2: float, coil_radius: float, region: float, wanted: float
) -> Apparatus:
    """The pairs of radius ``coil_radius`` that make ``a1`` (Helmholtz) and ``a2`` (Maxwell),
    and their harmonic error over the region (field by field)."""
    pairs = []
    if a1 != 0.0:
        pairs.append(_pair("helmholtz", coil_radius, a1, 0))
    if a2 != 0.0:
        pairs.append(_pair("maxwell", coil_radius, 2.0 * a2, 1))
    total = np.zeros(SERIES_DEGREE)
    for pair in pairs:
        total += np.asarray(pair.legendre())
    error = total.copy()
    error[:2] = 0.0  # the designed part, (a1, 2 a2) by construction of the ampere-turns
    designed = float(field_magnitude_max((a1, 2.0 * a2), np.array([region]))[0])
    spurious = float(field_magnitude_max(tuple(error), np.array([region]))[0])
    ratio = spurious / designed if designed > 0 else 0.0
    return Apparatus(pairs, region, tuple(float(v) for v in error), ratio, wanted)


def design_apparatus(a1: float, a2: float, region_radius: float, wanted: float) -> Apparatus:
    """The smallest coils (radius among :data:`COIL_RADII` x the region's) whose harmonic error
    over the body region is below ``wanted``; the largest tried when none is.

    Parameters
    ----------
    a1, a2 : float
        The paper's field, ``Phi = a1 Z + a2 (3 Z^2 - R^2)`` (T, T/m).
    region_radius : float
        Radius of the body region, m.
    wanted : float
        Largest harmonic error (|B_error| / |B_designed| over the region).
    """
    best = None
    for factor in COIL_RADII:
        best = apparatus_at(a1, a2, factor * region_radius, region_radius, wanted)
        if best.harmonic_error < wanted:
            return best
    assert best is not None
    best.notes.append(
        f"even coils {fmt(COIL_RADII[-1])} x the region's radius leave a harmonic error of "
        f"{fmt(best.harmonic_error)}"
    )
    return best
