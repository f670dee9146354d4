"""The holder and the whole inertia: every part as the sphere it is, held in a sphere about O.

A designed body is carriers (hollow or solid spheres), magnets (spheres of their material's
volume, with any attached ballast as a concentric shell of the first ballast material) and
ballast (spheres of their material). Each is a concentric layered sphere, so its own inertia
about its centre is isotropic: ``(8 pi / 15) sum_layers rho (r_out^5 - r_in^5)`` (``2/5 m a^2``
for a solid sphere). The holder is a sphere of one material about O with a bore (a sphere) at
each part's centre, of the part's outer radius. Its inertia is the full sphere's, isotropic,
less each bore's: the bore removes a sphere of holder material at the part's centre, whose
point term ``rho_h v (|c|^2 1 - c c^T)`` is not isotropic: the bores carry the contrast.

The designer (:mod:`chargedesign.designer.masses`) meets the inertia conditions with all of it
(:func:`monomial_moments` gives any mass row's value for the layered spheres and the holder);
design.json records ``inertia`` (:func:`whole_inertia`) and ``holder`` (:meth:`Holder.record`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.physical.materials import (
    BALLAST_DENSITY,
    CONDUCTIVITY,
    SUSCEPTIBILITY,
    Material,
    ballast_groups,
    ballast_materials,
    sphere_radius,
)
from chargedesign.validation import parse_moment_key

#: the wall the holder keeps outside its outermost bore, m: about the thinnest wall a machined
#: plastic or glass part keeps around a bore without breaking through (a workshop convention,
#: not a sourced figure: unchecked)
WALL_M = 1.0e-3
#: the holder's radius is rounded up to this step, m (a machinist's dimension; it also keeps
#: the radius fixed while the parts' sizes converge)
RADIUS_STEP_M = 1.0e-4

#: holder materials beyond the ballast materials: (density kg/m^3, volume susceptibility,
#: conductivity S/m, source). The polymer susceptibilities are of the order of every organic
#: solid's (-9e-6 for PMMA); a foam's is scaled by its density. Not checked against a sheet.
HOLDER_MATERIALS: dict[str, tuple[float, float, float, str]] = {
    "pmi-foam": (
        52.0,
        -4.0e-7,
        1.0e-13,
        "closed-cell PMI foam (ROHACELL 51 class), 52 kg/m^3 (manufacturer's data sheet); "
        "chi and conductivity: estimates for an insulating organic foam (unchecked)",
    ),
    "peek": (
        1320.0,
        -9.0e-6,
        1.0e-14,
        "PEEK, 1320 kg/m^3 (unfilled grade data sheets); chi and conductivity: estimates for "
        "an insulating polymer (unchecked)",
    ),
    "pmma": (
        1190.0,
        -9.0e-6,
        1.0e-13,
        "PMMA, 1190 kg/m^3; chi about -9e-6 (MR-compatibility tables of plastics); "
        "conductivity: an insulator's (unchecked)",
    ),
}

#: the names a ``[holder] material`` may take
HOLDER_MATERIAL_NAMES = (*HOLDER_MATERIALS, *BALLAST_DENSITY)

_FOUR_PI = 4.0 * math.pi


def holder_material(name: str) -> Material:
    """The named holder material (one of :data:`HOLDER_MATERIAL_NAMES`)."""
    if name in HOLDER_MATERIALS:
        density, chi, sigma, _ = HOLDER_MATERIALS[name]
        return Material("holder", name, density, susceptibility=chi, conductivity=sigma)
    return Material(
        "holder",
        name,
        BALLAST_DENSITY[name],
        susceptibility=SUSCEPTIBILITY.get(name),
        conductivity=CONDUCTIVITY.get(name),
    )


# ----------------------------------------------------------------------- parts as spheres
@dataclass
class PartSpheres:
    """Every part as a concentric layered sphere.

    ``names`` (k,) name each part by its block and index in design.json (``magnet 0``,
    ``ballast 3``, ``carrier 2``); ``centres`` (k, 3) m; ``masses`` (k,) kg; ``layers`` per part
    a list of ``(density, r_in, r_out)``; ``outer`` (k,) the outer radius (its bore's).
    """

    names: list[str]
    centres: np.ndarray
    masses: np.ndarray
    layers: list[list[tuple[float, float, float]]]

    @property
    def outer(self) -> np.ndarray:
        return np.array([max((r for _, _, r in ls), default=0.0) for ls in self.layers])

    def radial_moments(self, power: int) -> np.ndarray:
        """``int r^power dm`` about each part's centre, (k,) (``power`` even, >= 0)."""
        n = power + 3
        return np.array(
            [sum(_FOUR_PI * rho * (ro**n - ri**n) / n for rho, ri, ro in ls) for ls in self.layers]
        )

    def own_inertia(self) -> np.ndarray:
        """Each part's moment of inertia about its centre (isotropic), kg m^2, (k,)."""
        return 2.0 / 3.0 * self.radial_moments(2)


def _shell_layers(
    mass: float, outer: float, wall: float | None
) -> list[tuple[float, float, float]]:
    """A carrier of this mass: a shell of ``wall`` (None: solid), its density from the mass."""
    inner = max(outer - wall, 0.0) if wall is not None else 0.0
    volume = _FOUR_PI / 3.0 * (outer**3 - inner**3)
    return [(mass / volume if volume > 0 else 0.0, inner, outer)]


def parts_from_arrays(
    *,
    carriers: tuple[np.ndarray, np.ndarray, np.ndarray, float | None] | None = None,
    magnets: tuple[np.ndarray, np.ndarray, np.ndarray, float, float] | None = None,
    ballast: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None,
    names: tuple[list[str], list[str], list[str]] | None = None,
) -> PartSpheres:
    """The parts as spheres from their arrays.

    ``carriers`` = (positions, masses, outer radii, wall or None); ``magnets`` = (positions,
    masses, volumes, magnet density, attached ballast density); ``ballast`` = (positions,
    masses, densities). ``names``: each block's part names (default ``carrier i`` ...).
    """
    # Each block's sizes as arrays at once (np.cbrt elementwise: the same bits as one part
    # at a time); the layers stay Python floats, part by part.
    out_names: list[str] = []
    centres: list[np.ndarray] = []
    masses: list[np.ndarray] = []
    layers: list[list[tuple[float, float, float]]] = []

    def start_block(index: int, label: str, pos: Any, mass: Any) -> np.ndarray:
        """One block's masses, its names and centres recorded (as many as it has masses)."""
        mass_f = np.asarray(mass, dtype=float).reshape(-1)
        out_names.extend(
            names[index][: len(mass_f)] if names else [f"{label} {i}" for i in range(len(mass_f))]
        )
        centres.append(np.asarray(pos, dtype=float).reshape(-1, 3)[: len(mass_f)])
        masses.append(mass_f)
        return mass_f

    if carriers is not None:
        pos, mass, radii, wall = carriers
        mass_f = start_block(0, "carrier", pos, mass)
        radii_f = np.asarray(radii, dtype=float).reshape(-1)
        layers += [
            _shell_layers(m, r, wall)
            for m, r in zip(mass_f.tolist(), radii_f.tolist(), strict=True)
        ]
    if magnets is not None:
        pos, mass, volume, density, attached = magnets
        mass_f = start_block(1, "magnet", pos, mass)
        volume_f = np.asarray(volume, dtype=float).reshape(-1)[: len(mass_f)]
        if not math.isfinite(density):  # no material written: points
            layers += [[] for _ in range(len(mass_f))]
        else:
            cores = sphere_radius(volume_f).tolist()
            extras = [
                max(m - density * v, 0.0)
                for m, v in zip(mass_f.tolist(), volume_f.tolist(), strict=True)
            ]
            outers = (
                sphere_radius(volume_f + np.array(extras) / attached).tolist()
                if attached > 0
                else [0.0] * len(extras)
            )
            for core, extra, outer in zip(cores, extras, outers, strict=True):
                block = [(density, 0.0, core)]
                if extra > 0 and attached > 0:
                    block.append((attached, core, outer))
                layers.append(block)
    if ballast is not None:
        pos, mass, rho = ballast
        mass_f = start_block(2, "ballast", pos, mass)
        rho_f = np.asarray(rho, dtype=float).reshape(-1)[: len(mass_f)]
        finite = np.isfinite(rho_f)
        with np.errstate(divide="ignore", invalid="ignore"):
            radii_b = sphere_radius(np.where(finite, mass_f / np.where(finite, rho_f, 1.0), 0.0))
        for ok, r, a in zip(finite.tolist(), rho_f.tolist(), radii_b.tolist(), strict=True):
            layers.append([(r, 0.0, a)] if ok else [])  # not finite: no material, a point
    return PartSpheres(
        out_names,
        np.concatenate(centres).reshape(-1, 3) if centres else np.zeros((0, 3)),
        np.concatenate(masses) if masses else np.zeros(0),
        layers,
    )


def design_parts(design: Any) -> PartSpheres:
    """Every written part of a physical design as spheres (its materials give the sizes)."""
    materials = design.materials or {}
    carrier = materials.get("carrier") or {}
    magnet = materials.get("magnet") or {}
    ballasts = ballast_materials(materials)
    attached = float(ballasts[0]["density_kg_per_m3"]) if ballasts else 0.0
    densities = np.full(len(design.mass_values), np.inf)
    for spec, idx in ballast_groups(design) if len(design.mass_values) else []:
        densities[idx] = spec["density_kg_per_m3"]
    return parts_from_arrays(
        carriers=(
            design.charge_positions,
            design.carrier_masses(),
            design.carrier_radii(),
            carrier.get("shell_thickness_m"),
        ),
        magnets=(
            design.dipole_positions,
            design.magnet_masses(),
            design.magnet_volumes(),
            float(magnet.get("density_kg_per_m3", np.inf)),
            attached,
        ),
        ballast=(design.mass_positions, design.mass_values, densities),
    )


# ------------------------------------------------------------------------ moments of spheres
def _double_factorial(n: int) -> int:
    return math.prod(range(n, 0, -2)) if n > 0 else 1


def direction_mean(p: int, q: int, r: int) -> float:
    """The mean of ``u_x^p u_y^q u_z^r`` over unit vectors (0 unless all are even)."""
    if p % 2 or q % 2 or r % 2:
        return 0.0
    return (
        _double_factorial(p - 1)
        * _double_factorial(q - 1)
        * _double_factorial(r - 1)
        / _double_factorial(p + q + r + 1)
    )


def monomial_moments(
    keys: list[str], centres: np.ndarray, radial: Any, masses: np.ndarray
) -> np.ndarray:
    """``int x^i y^j z^k dm`` of each sphere for each moment key, shape (len(keys), k).

    A concentric sphere about ``c`` has ``int rho^alpha dm = R_n E[u^alpha]`` (``n = |alpha|``,
    ``R_n = int r^n dm`` from ``radial(n)``, ``E`` the mean over directions): the monomial of
    ``c + rho`` expanded by the binomial theorem. Exact for every degree.
    """
    centres = np.asarray(centres, dtype=float).reshape(-1, 3)
    exps = [parse_moment_key(k) for k in keys]
    top = max((sum(e) for e in exps), default=0)
    radial_by_n = {n: (masses if n == 0 else radial(n)) for n in range(0, top + 1, 2)}
    out = np.zeros((len(keys), len(centres)))
    # each power of a centre coordinate once (the same expression, so the same bits)
    powers: dict[tuple[int, int], np.ndarray] = {}

    def power(axis: int, e: int) -> np.ndarray:
        if (axis, e) not in powers:
            powers[axis, e] = centres[:, axis] ** e
        return powers[axis, e]

    for a, (i, j, k) in enumerate(exps):
        for p in range(0, i + 1, 2):
            for q in range(0, j + 1, 2):
                for r in range(0, k + 1, 2):
                    mean = direction_mean(p, q, r)
                    coef = math.comb(i, p) * math.comb(j, q) * math.comb(k, r) * mean
                    out[a] += (
                        coef
                        * radial_by_n[p + q + r]
                        * power(0, i - p)
                        * power(1, j - q)
                        * power(2, k - r)
                    )
    return out


def part_moments(parts: PartSpheres, keys: list[str]) -> np.ndarray:
    """The parts' moments for each key, (len(keys), k)."""
    return monomial_moments(keys, parts.centres, parts.radial_moments, parts.masses)


# ------------------------------------------------------------------------------ the holder
@dataclass
class Holder:
    """A sphere of ``material`` about O of ``radius`` (m), with bores (spheres) at
    ``bore_centres`` (k, 3) of ``bore_radii`` (k,), each holding the part ``bore_parts[i]``."""

    material: str
    density: float
    radius: float
    bore_centres: np.ndarray
    bore_radii: np.ndarray
    bore_parts: list[str]
    susceptibility: float | None = None
    conductivity: float | None = None

    @property
    def bore_volumes(self) -> np.ndarray:
        return _FOUR_PI / 3.0 * self.bore_radii**3

    @property
    def volume(self) -> float:
        """The holder's material volume (the sphere less its bores), m^3."""
        return _FOUR_PI / 3.0 * self.radius**3 - float(np.sum(self.bore_volumes))

    @property
    def mass(self) -> float:
        return self.density * self.volume

    def radial(self, n: int) -> np.ndarray:
        """``int r^n dm`` of each bore's holder material about its centre, (k,)."""
        return _FOUR_PI * self.density * self.bore_radii ** (n + 3) / (n + 3)

    def moments(self, keys: list[str]) -> np.ndarray:
        """The holder's moments for each key (the full sphere less the bores), (len(keys),)."""
        full = monomial_moments(
            keys,
            np.zeros((1, 3)),
            lambda n: np.array([_FOUR_PI * self.density * self.radius ** (n + 3) / (n + 3)]),
            np.array([self.density * _FOUR_PI / 3.0 * self.radius**3]),
        )[:, 0]
        bores = monomial_moments(
            keys, self.bore_centres, self.radial, self.density * self.bore_volumes
        )
        return full - bores.sum(axis=1)

    def inertia(self) -> np.ndarray:
        """The holder's inertia tensor about O, kg m^2 (3, 3)."""
        sphere = 2.0 / 5.0 * self.density * _FOUR_PI / 3.0 * self.radius**5
        own = 2.0 / 3.0 * self.radial(2)
        return (
            sphere * np.eye(3)
            - point_inertia(self.bore_centres, self.density * self.bore_volumes)
            - float(np.sum(own)) * np.eye(3)
        )

    def record(self) -> dict[str, Any]:
        """design.json ``holder`` (the contract's keys)."""
        return {
            "material": self.material,
            "density_kg_per_m3": self.density,
            "radius_m": self.radius,
            "volume_m3": self.volume,
            "mass_kg": self.mass,
            "volume_susceptibility": self.susceptibility,
            "conductivity_S_per_m": self.conductivity,
            "wall_m": WALL_M,
            "bores": [
                {"position": [float(x) for x in c], "radius_m": float(a), "part": name}
                for c, a, name in zip(
                    self.bore_centres, self.bore_radii, self.bore_parts, strict=True
                )
            ],
        }

    @classmethod
    def from_record(cls, record: dict[str, Any]) -> Holder:
        bores = record.get("bores") or []
        return cls(
            material=str(record["material"]),
            density=float(record["density_kg_per_m3"]),
            radius=float(record["radius_m"]),
            bore_centres=np.array([b["position"] for b in bores], dtype=float).reshape(-1, 3),
            bore_radii=np.array([b["radius_m"] for b in bores], dtype=float),
            bore_parts=[str(b["part"]) for b in bores],
            susceptibility=record.get("volume_susceptibility"),
            conductivity=record.get("conductivity_S_per_m"),
        )


def enclosing_radius(parts: PartSpheres) -> float:
    """The holder's radius: the outermost bore's reach plus :data:`WALL_M`, rounded up to
    :data:`RADIUS_STEP_M`."""
    reach = float(np.max(np.linalg.norm(parts.centres, axis=1) + parts.outer, initial=0.0))
    return math.ceil((reach + WALL_M) / RADIUS_STEP_M - 1e-9) * RADIUS_STEP_M


def holder_for(material: Material, parts: PartSpheres, radius: float | None = None) -> Holder:
    """The holder of ``material`` for these parts (``radius`` None: :func:`enclosing_radius`)."""
    return Holder(
        material=material.name,
        density=material.density,
        radius=enclosing_radius(parts) if radius is None else radius,
        bore_centres=parts.centres.copy(),
        bore_radii=parts.outer,
        bore_parts=list(parts.names),
        susceptibility=material.susceptibility,
        conductivity=material.conductivity,
    )


# ------------------------------------------------------------------------ the whole inertia
def point_inertia(centres: np.ndarray, masses: np.ndarray) -> np.ndarray:
    """``sum m (|c|^2 1 - c c^T)``, kg m^2 (3, 3)."""
    c = np.asarray(centres, dtype=float).reshape(-1, 3)
    m = np.asarray(masses, dtype=float)
    return float(np.sum(m * np.sum(c**2, axis=1))) * np.eye(3) - (c * m[:, None]).T @ c


def whole_inertia(design: Any, holder: Holder | None = None) -> dict[str, Any]:
    """design.json ``inertia``: the 3x3 about O of the parts as points, their own (isotropic)
    inertia, the holder's (``design.holder`` when ``holder`` is None) and the total."""
    parts = design_parts(design)
    if holder is None and getattr(design, "holder", None):
        holder = Holder.from_record(design.holder)
    points = point_inertia(parts.centres, parts.masses)
    own = float(np.sum(parts.own_inertia())) * np.eye(3)
    held = holder.inertia() if holder is not None else np.zeros((3, 3))
    total = points + own + held
    return {
        "total_kg_m2": total.tolist(),
        "points_kg_m2": points.tolist(),
        "parts_own_kg_m2": own.tolist(),
        "holder_kg_m2": held.tolist(),
    }
