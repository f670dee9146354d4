"""The whole inertia of a written body, recomputed on its own from design.json's parts.

Written apart from the designer's formulas (:mod:`chargedesign.physical.holder`), from what
design.json holds: the point terms of every mass (summed in double-double), each part's own
inertia about its centre for its shape, and the holder's record:

- a ballast sphere of mass m and density rho: ``(2/5) m a^2``, ``a = (3 m / (4 pi rho))^(1/3)``;
- a magnet of volume v (a sphere of its material) whose mass m exceeds ``rho_m v``: the excess
  is a concentric shell of the (first) ballast material out to the sphere of the total volume;
- a carrier of outer radius a and wall t (solid without one): a shell of its mass;
- the holder: ``(2/5) M_sphere R^2`` about O less, for each bore (a sphere of holder material
  at the part's centre), its point term and its own ``(2/5) m_bore a^2``.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from chargedesign.checker.double_double import DoubleDouble


def inertia_accurate(positions: np.ndarray, masses: np.ndarray) -> tuple[np.ndarray, float]:
    """``sum m (|r|^2 1 - r r^T)`` summed in double-double, and ``sum m |r|^2`` (kg m^2)."""
    r = [positions[:, i] for i in range(3)]
    out = np.zeros((3, 3))
    for i in range(3):
        for j in range(i, 3):
            if i == j:
                a, b = r[(i + 1) % 3], r[(i + 2) % 3]
                entry = (DoubleDouble(masses) * a) * a + (DoubleDouble(masses) * b) * b
            else:
                entry = -((DoubleDouble(masses) * r[i]) * r[j])
            out[i, j] = out[j, i] = float(entry.total(-1).to_float())
    gross = float(np.abs(masses) @ np.einsum("ij,ij->i", positions, positions))
    return out, gross


def _shell(mass: np.ndarray, outer: np.ndarray, inner: np.ndarray) -> np.ndarray:
    """``(2/5) m (a^5 - b^5) / (a^3 - b^3)``: the own inertia of shells of mass m."""
    a5, b5, a3, b3 = outer**5, inner**5, outer**3, inner**3
    with np.errstate(invalid="ignore", divide="ignore"):
        out = 0.4 * mass * np.where(a3 > b3, (a5 - b5) / np.where(a3 > b3, a3 - b3, 1.0), 0.0)
    return out


def _radius(volume: np.ndarray) -> np.ndarray:
    return np.cbrt(3.0 * np.asarray(volume, dtype=float) / (4.0 * math.pi))


def own_inertia(design: Any) -> float:
    """The sum of every part's own (isotropic) moment of inertia about its centre, kg m^2."""
    materials = design.materials or {}
    total = 0.0
    ballast = materials.get("ballast")
    ballasts = ballast if isinstance(ballast, list) else ([ballast] if ballast else [])
    if len(design.charge_values):
        outer = np.asarray(design.carrier_radii(), dtype=float)
        wall = (materials.get("carrier") or {}).get("shell_thickness_m")
        inner = np.maximum(outer - wall, 0.0) if wall is not None else np.zeros_like(outer)
        total += float(np.sum(_shell(design.carrier_masses(), outer, inner)))
    if len(design.dipole_moments):
        rho_m = float(materials["magnet"]["density_kg_per_m3"])
        volume = np.asarray(design.magnet_volumes(), dtype=float)
        mass = np.asarray(design.magnet_masses(), dtype=float)
        core = _radius(volume)
        total += float(np.sum(0.4 * rho_m * volume * core**2))
        extra = np.maximum(mass - rho_m * volume, 0.0)
        if ballasts and np.any(extra > 0):
            rho_b = float(ballasts[0]["density_kg_per_m3"])
            outer = _radius(volume + extra / rho_b)
            total += float(np.sum(_shell(extra, outer, core)))
    if len(design.mass_values):
        names = design.mass_materials
        by_name = {b["name"]: float(b["density_kg_per_m3"]) for b in ballasts}
        if names is None:
            density = np.full(len(design.mass_values), float(ballasts[0]["density_kg_per_m3"]))
        else:
            density = np.array([by_name[str(n)] for n in names])
        mass = np.asarray(design.mass_values, dtype=float)
        total += float(np.sum(0.4 * mass * _radius(mass / density) ** 2))
    return total


def holder_inertia(holder: dict[str, Any] | None) -> tuple[np.ndarray, float]:
    """The holder's inertia about O from its record (zero without one), and its gross size."""
    if not holder:
        return np.zeros((3, 3)), 0.0
    rho = float(holder["density_kg_per_m3"])
    radius = float(holder["radius_m"])
    sphere = 0.4 * rho * 4.0 / 3.0 * math.pi * radius**5
    bores = holder.get("bores") or []
    c = np.array([b["position"] for b in bores], dtype=float).reshape(-1, 3)
    a = np.array([b["radius_m"] for b in bores], dtype=float)
    m = rho * 4.0 / 3.0 * math.pi * a**3
    points = float(np.sum(m * np.sum(c**2, axis=1))) * np.eye(3) - (c * m[:, None]).T @ c
    own = float(np.sum(0.4 * m * a**2))
    return sphere * np.eye(3) - points - own * np.eye(3), sphere


def whole_inertia_check(design: Any, elements: Any) -> tuple[np.ndarray, float, dict[str, Any]]:
    """The body's whole inertia about O (kg m^2), its gross size, and how it compares with
    design.json's ``inertia.total_kg_m2`` (``{}`` when the file records none)."""
    points, gross = inertia_accurate(elements.mass_positions, elements.mass_values)
    physical = design.medium is not None
    own = own_inertia(design) if physical else 0.0
    held, held_gross = holder_inertia(getattr(design, "holder", None))
    total = points + own * np.eye(3) + held
    compared: dict[str, Any] = {}
    record = getattr(design, "inertia", None)
    if isinstance(record, dict) and record.get("total_kg_m2") is not None:
        written = np.asarray(record["total_kg_m2"], dtype=float)
        scale = max(float(np.abs(written).max()), 1e-300)
        compared = {
            "recorded_vs_recomputed": float(np.abs(written - total).max()) / scale,
            "parts_own_kg_m2": own,
            "holder": bool(getattr(design, "holder", None)),
        }
    return total, gross + 3.0 * own + 3.0 * held_gross, compared
