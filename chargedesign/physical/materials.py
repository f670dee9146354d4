"""Media (breakdown fields) and materials (densities, magnetisations), with their sources.

Every number here is read from the sources table (:mod:`chargedesign.physical.sources`,
``chargedesign sources``) by its key (:data:`KEYS`), and that table's rows quote the sources
in words. A scene may always give its own
value instead (``[medium] breakdown = ...``, ``density = ...``, ``magnetisation = ...``).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from chargedesign.constants import MU_0
from chargedesign.physical.sources import value

#: breakdown field of each named medium, V/m (sources table: media.breakdown.<name>)
BREAKDOWN_V_PER_M = {m: value(f"media.breakdown.{m}") for m in ("air", "sf6", "oil", "vacuum")}

#: kinematic data of the gas media for the drag estimate: (density kg/m^3, viscosity Pa s)
#: (sources table: media.density.<name>, media.viscosity.<name>; vacuum has none)
GAS_PROPERTIES = {
    **{
        m: (value(f"media.density.{m}"), value(f"media.viscosity.{m}"))
        for m in ("air", "sf6", "oil")
    },
    "vacuum": (0.0, 0.0),
}


def _density(name: str) -> float:
    return value(f"materials.density.{name}")


#: carrier materials: density, kg/m^3 (materials.density.<name>)
CARRIER_DENSITY = {m: _density(m) for m in ("aluminium", "titanium", "copper", "stainless")}

#: the magnet materials the tool knows
MAGNETS = ("ndfeb", "ndfeb-eh", "smco", "ferrite")

#: magnet materials: (remanent magnetisation A/m, density kg/m^3) (materials.remanence.<name>)
MAGNET_DATA = {m: (value(f"materials.remanence.{m}"), _density(m)) for m in MAGNETS}

#: intrinsic coercivity Hcj of each magnet material at 20 C, A/m (the minimum of its grade):
#: a reverse field inside the magnet beyond it demagnetises it for good
#: (materials.coercivity.<name>)
MAGNET_COERCIVITY = {m: value(f"materials.coercivity.{m}") for m in MAGNETS}

#: ballast materials: density, kg/m^3 (materials.density.<name>); alumina, zirconia and
#: fused silica are insulating, low-chi ballast (no eddy currents)
BALLAST_DENSITY = {
    m: _density(m)
    for m in (
        "tungsten",
        "lead",
        "brass",
        "steel",
        "aluminium",
        "bismuth",
        "copper",
        "alumina",
        "zirconia",
        "fused-silica",
    )
}

#: every named material of a part
_MATERIALS = (*CARRIER_DENSITY, *BALLAST_DENSITY, *MAGNETS)
_NAMED = tuple(dict.fromkeys(_MATERIALS))

#: SI volume susceptibility chi (dimensionless) of every named material at 20 C. A part of
#: volume v in a field B gains the energy -chi v |B|^2 / (2 mu0) (|chi| << 1): in a field
#: gradient this depends on the body's orientation (materials.susceptibility.<name>;
#: elements: CRC molar susceptibilities chi_mol (cgs) converted as 4 pi chi_mol rho / M)
SUSCEPTIBILITY = {m: value(f"materials.susceptibility.{m}") for m in _NAMED}

#: electrical conductivity, S/m, at 20 C (eddy currents in the rotating parts)
#: (materials.conductivity.<name>)
CONDUCTIVITY = {m: value(f"materials.conductivity.{m}") for m in _NAMED}

#: smallest magnet, m (edge of the cube of its volume), that the magnet data above describe:
#: bulk properties of sintered magnets; below about 10-20 nm a ferromagnet is a
#: single-domain nanoparticle (limits.magnet_continuum_size; the upper end is used)
MAGNET_CONTINUUM_SIZE = value("limits.magnet_continuum_size")

#: a balance a builder reaches, m: published automatic balancing reaches an estimated
#: 0.14 um horizontally; 0.1 um, the floor used for gravity's parasitic on Earth
#: (limits.builder_balance_m)
BUILDER_BALANCE_M = value("limits.builder_balance_m")

#: the sources table's key of each figure above, by the dict it fills and the material
KEYS = {
    "breakdown": {m: f"media.breakdown.{m}" for m in BREAKDOWN_V_PER_M},
    "density": {m: f"materials.density.{m}" for m in _NAMED},
    "remanence": {m: f"materials.remanence.{m}" for m in MAGNETS},
    "coercivity": {m: f"materials.coercivity.{m}" for m in MAGNETS},
    "susceptibility": {m: f"materials.susceptibility.{m}" for m in _NAMED},
    "conductivity": {m: f"materials.conductivity.{m}" for m in _NAMED},
}


@dataclass(frozen=True)
class Material:
    """A material of a part: its density, and its remanent magnetisation for magnets.

    Attributes
    ----------
    role : str
        ``carrier``, ``magnet`` or ``ballast``.
    name : str
    density : float
        kg/m^3.
    magnetisation : float, optional
        Remanent magnetisation, A/m (magnets only).
    shell_thickness : float, optional
        Wall thickness of a hollow carrier sphere, m (None: solid).
    coercivity : float, optional
        Intrinsic coercivity Hcj, A/m (magnets only; None: unknown).
    susceptibility : float, optional
        SI volume susceptibility (None: unknown, for a custom material).
    conductivity : float, optional
        Electrical conductivity, S/m (None: unknown).
    """

    role: str
    name: str
    density: float
    magnetisation: float | None = None
    shell_thickness: float | None = None
    coercivity: float | None = None
    susceptibility: float | None = None
    conductivity: float | None = None

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {"name": self.name, "density_kg_per_m3": self.density}
        if self.magnetisation is not None:
            out["remanent_magnetisation_A_per_m"] = self.magnetisation
        if self.shell_thickness is not None:
            out["shell_thickness_m"] = self.shell_thickness
        if self.coercivity is not None:
            out["intrinsic_coercivity_A_per_m"] = self.coercivity
        if self.susceptibility is not None:
            out["volume_susceptibility"] = self.susceptibility
        if self.conductivity is not None:
            out["conductivity_S_per_m"] = self.conductivity
        return out

    def field_withstood(self) -> float | None:
        """The largest applied |B| (T) this magnet withstands in any direction, or None.

        Inside a magnetised sphere its own field is ``-M / 3``; an applied field reversed
        against the magnetisation adds to it. Below ``Hcj`` in total the magnet recovers:
        ``mu0 (Hcj - M / 3)``. The body turns every way in the field, so any direction counts.
        """
        if self.coercivity is None or self.magnetisation is None:
            return None
        return demagnetisation_limit(self.magnetisation, self.coercivity)

    def sphere_mass(self, radius: float) -> float:
        """Mass of a sphere (or shell, with ``shell_thickness``) of this material, kg."""
        outer = radius**3
        if self.shell_thickness is None or self.shell_thickness >= radius:
            inner = 0.0
        else:
            inner = (radius - self.shell_thickness) ** 3
        return self.density * 4.0 / 3.0 * 3.141592653589793 * (outer - inner)


def sphere_radius(volume: Any) -> Any:
    """Radius of the sphere of this volume (m; arrays elementwise)."""
    return np.cbrt(3.0 * np.asarray(volume, dtype=float) / (4.0 * np.pi))


def demagnetisation_limit(magnetisation: float, coercivity: float) -> float:
    """``mu0 (Hcj - M / 3)``, T: the applied field a magnetised sphere withstands reversed."""
    return MU_0 * (coercivity - magnetisation / 3.0)


def ballast_materials(materials: Any) -> list[dict[str, Any]]:
    """design.json ``materials.ballast`` as a list of material dicts (empty: no ballast).

    One material is written as an object, several (the chi design) as a list.
    """
    ballast = (materials or {}).get("ballast")
    if ballast is None:
        return []
    return list(ballast) if isinstance(ballast, list) else [ballast]


def ballast_groups(design: Any) -> list[tuple[dict[str, Any], np.ndarray]]:
    """Each ballast material of ``design`` with the indices of its mass parts, shape (k,).

    With one material every ballast part is made of it; with several, ``masses.material``
    (``design.mass_materials``) names each part's material.
    """
    materials = ballast_materials(design.materials)
    count = len(design.mass_values)
    if not materials:
        return []
    if len(materials) == 1:
        return [(materials[0], np.arange(count))]
    names = np.asarray(design.mass_materials if design.mass_materials is not None else [])
    return [(m, np.flatnonzero(names == m["name"])) for m in materials]


def mass_densities(design: Any) -> np.ndarray:
    """Density of each ballast part's material, kg/m^3, shape (m,) (inf: no material given)."""
    out = np.full(len(design.mass_values), np.inf)
    for material, idx in ballast_groups(design):
        out[idx] = material["density_kg_per_m3"]
    return out


def ballast_label(materials: Any) -> str:
    """The ballast material names for a report: ``tungsten`` or ``tungsten + bismuth``."""
    names = [m.get("name", "?") for m in ballast_materials(materials)]
    return " + ".join(names) if names else "?"


#: relative accuracy of susceptibility metrology: a calibrated ac susceptometer holds its
#: magnitude error below 0.7 % (materials.susceptibility_metrology: Chen & Skumryev, Rev.
#: Sci. Instrum. 81, 025104 (2010))
SUSCEPTIBILITY_METROLOGY = value("materials.susceptibility_metrology")

#: conductivity of insulators a part could be made of, S/m at 20 C (upper ends, from the
#: volume resistivities: 99.5 % alumina > 1e14 ohm cm, e.g. CoorsTek AD-995 data sheet;
#: PTFE > 1e18 ohm cm, Chemours Teflon PTFE data sheet; soda-lime glass 1e10-1e14 ohm m,
#: Serway, Physics for Scientists and Engineers, table 27.2)
INSULATOR_CONDUCTIVITY = {
    name: value(f"materials.insulator_conductivity.{name.replace(' ', '_')}")
    for name in ("alumina", "soda-lime glass", "PTFE")
}
