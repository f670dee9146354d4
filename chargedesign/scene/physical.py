"""What a scene says about the physical body: medium, materials, part sizes, field limits.

Scene tables (docs/buildable.md)::

    [medium]            name = "air" | "vacuum" | "sf6" | "oil"  (or breakdown = V/m); safety;
                        gas (whose drag the realism budget estimates; default the name's)
    [carriers]          material = "aluminium" (or density), shell_thickness (m; 0 = solid),
                        samples (surface points per carrier in the design)
    [magnets]           material = "ndfeb" (or magnetisation A/m and density kg/m^3),
                        coercivity (intrinsic, A/m)
    [ballast]           material = "tungsten" (or density), or a list of named materials
                        of opposite susceptibilities, e.g. ["tungsten", "bismuth"]: the
                        design then cancels the parts' induced magnetisation
    (each of the three) susceptibility (SI volume), conductivity (S/m): override the
                        material's values, which the realism budget uses
    [holder]            material (default: the ballast's): a sphere about O with a bore for
                        each part, whose inertia, susceptibility and conductivity count
    [body]              carrier_radius (m; default a quarter of the candidate spacing)
    [tolerance]         chi_relative, density_relative, magnetisation_relative: the
                        materials' relative errors that ``tolerance`` analyses
    [fields.*]          max: the largest |B| (T) or |E| (V/m) the apparatus makes over the body

A scene without ``[medium]`` is the mathematical case: point elements, no limits.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from chargedesign.errors import InputError
from chargedesign.formatting import fmt
from chargedesign.physical.holder import HOLDER_MATERIAL_NAMES, holder_material
from chargedesign.physical.materials import (
    BALLAST_DENSITY,
    CARRIER_DENSITY,
    CONDUCTIVITY,
    MAGNET_COERCIVITY,
    MAGNET_DATA,
    SUSCEPTIBILITY,
    Material,
)
from chargedesign.scene.keys import KEY, check_table, check_value, default_of
from chargedesign.scene.medium import Medium, medium_from_table
from chargedesign.scene.tables import material_errors_from_table
from chargedesign.validation import as_finite_float, input_error

#: default carrier radius as a fraction of the candidate spacing (carriers never touch)
CARRIER_RADIUS_FRACTION = 0.25
#: default wall of a hollow carrier, m (thin spun or drawn aluminium)
DEFAULT_SHELL_THICKNESS = default_of("carriers", "shell_thickness")
#: surface sample points per carrier in the design (constraint generation adds the worst)
DEFAULT_SURFACE_SAMPLES = default_of("carriers", "samples")
#: how a part's material answers the applied field: magnetisation and eddy currents
_RESPONSE_KEYS = ("susceptibility", "conductivity")


@dataclass(frozen=True)
class PhysicalSpec:
    """The physical side of a scene.

    Attributes
    ----------
    medium : Medium
    carrier : Material
        With ``shell_thickness`` (m) or None (solid spheres).
    magnet : Material
        With ``magnetisation`` (A/m).
    ballast : Material
        The (first) ballast material; a magnet's attached ballast is made of it.
    carrier_radius : float or None
        m; None: ``CARRIER_RADIUS_FRACTION`` of the candidate spacing.
    field_limits : dict[str, float]
        The largest |B| (T), |E| (V/m) or |g| the apparatus makes over the body region.
    surface_samples : int
        Sample points per carrier surface in the design.
    ballasts : tuple of Material
        Every ballast material when several are given (``[ballast] material = [...]``): the
        design then cancels the induced magnetisation; empty: ``ballast`` alone.
    """

    medium: Medium
    carrier: Material
    magnet: Material
    ballast: Material
    carrier_radius: float | None = None
    field_limits: dict[str, float] = field(default_factory=dict)
    surface_samples: int = DEFAULT_SURFACE_SAMPLES
    ballasts: tuple[Material, ...] = ()
    #: the scene's ``[tolerance]`` material errors (relative), recorded in design.json
    material_errors: dict[str, float] = field(default_factory=dict)
    #: the holder's material (``[holder]``; None: no holder, the parts are not held)
    holder: Material | None = None

    @property
    def designs_induced(self) -> bool:
        """Whether the design cancels the induced magnetisation (several ballast materials)."""
        return len(self.ballasts) > 1

    def materials_dict(self) -> dict[str, Any]:
        """design.json ``materials`` (``ballast`` a list when several are given)."""
        ballast: Any = (
            [m.to_dict() for m in self.ballasts] if self.designs_induced else self.ballast.to_dict()
        )
        return {
            "carrier": self.carrier.to_dict(),
            "magnet": self.magnet.to_dict(),
            "ballast": ballast,
        }

    def to_dict(self) -> dict[str, Any]:
        return {
            "medium": self.medium.to_dict(),
            "materials": self.materials_dict(),
            "field_limits": dict(self.field_limits),
        }


def _density(table: Mapping[str, Any], where: str, known: Mapping[str, float], default: str):
    """(name, density) of a table: a named material or a given density (kg/m^3)."""
    name = table.get("material", default if "density" not in table else "custom")
    if not isinstance(name, str):
        raise input_error(f"{where}.material", "a material name", name)
    if "density" in table:
        return name, check_value(where, "density", table["density"], f"{where}.density")
    if name not in known:
        raise input_error(f"{where}.material", "one of " + ", ".join(known), name)
    return name, known[name]


def _response(table: Mapping[str, Any], where: str, name: str) -> dict[str, float | None]:
    """The material's susceptibility and conductivity: the table's, else the named material's
    (None for a custom material: the realism budget then says it was not estimated)."""
    chi = SUSCEPTIBILITY.get(name)
    if "susceptibility" in table:
        chi = as_finite_float(table["susceptibility"], f"{where}.susceptibility")
        if chi <= -1.0:
            raise input_error(f"{where}.susceptibility", "a number > -1", chi)
    sigma = CONDUCTIVITY.get(name)
    if "conductivity" in table:
        sigma = as_finite_float(table["conductivity"], f"{where}.conductivity")
        if sigma < 0.0:
            raise input_error(f"{where}.conductivity", "a number >= 0 (S/m)", sigma)
    return {"susceptibility": chi, "conductivity": sigma}


def spec_from_tables(
    tables: Mapping[str, Any], field_limits: Mapping[str, float] | None = None
) -> PhysicalSpec | None:
    """The physical spec of a scene's tables, or None when the scene has no ``[medium]``."""
    material_errors: dict[str, float] = {}
    if "tolerance" in tables:
        material_errors = material_errors_from_table(tables["tolerance"])
    if "medium" not in tables:
        for name in ("carriers", "magnets", "ballast", "holder", "tolerance"):
            if name in tables:
                raise InputError(
                    f"{name}: physical parts need a [medium] table (vacuum, air, sf6, oil)"
                )
        return None
    medium = medium_from_table(tables["medium"])
    carrier, samples = _carrier(tables.get("carriers", {}))
    magnet = _magnet(tables.get("magnets", {}))
    ballasts = _ballasts(tables.get("ballast", {}))
    body = tables.get("body", {})
    radius = None
    if isinstance(body, Mapping) and KEY.carrier_radius in body:
        radius = as_finite_float(body[KEY.carrier_radius], "body.carrier_radius", positive=True)
    return PhysicalSpec(
        medium=medium,
        carrier=carrier,
        magnet=magnet,
        ballast=ballasts[0],
        carrier_radius=radius,
        field_limits=dict(field_limits or {}),
        surface_samples=samples,
        ballasts=tuple(ballasts) if len(ballasts) > 1 else (),
        material_errors=material_errors,
        holder=_holder(tables["holder"], ballasts[0]) if "holder" in tables else None,
    )


def _holder(table: Mapping[str, Any], ballast: Material) -> Material:
    """``[holder]``: its material, by default the (first) ballast's."""
    check_table(table, "holder")
    name = table.get("material")
    if name is None:
        return replace(ballast, role="holder")
    if not isinstance(name, str) or name not in HOLDER_MATERIAL_NAMES:
        raise input_error("holder.material", "one of " + ", ".join(HOLDER_MATERIAL_NAMES), name)
    return holder_material(name)


def _carrier(carriers: Mapping[str, Any]) -> tuple[Material, int]:
    """``[carriers]``: the carriers' material and the surface samples per carrier."""
    check_table(carriers, "carriers")
    name, density = _density(carriers, "carriers", CARRIER_DENSITY, "aluminium")
    shell = as_finite_float(
        carriers.get("shell_thickness", DEFAULT_SHELL_THICKNESS), "carriers.shell_thickness"
    )
    if shell < 0:
        raise input_error("carriers.shell_thickness", "a thickness >= 0 (0: solid)", shell)
    samples = check_value("carriers", "samples", carriers.get("samples", DEFAULT_SURFACE_SAMPLES))
    carrier = Material(
        "carrier",
        name,
        density,
        shell_thickness=shell if shell > 0 else None,
        **_response(carriers, "carriers", name),
    )
    return carrier, samples


def _magnet(magnets: Mapping[str, Any]) -> Material:
    """``[magnets]``: a named magnet material, or its magnetisation and density."""
    check_table(magnets, "magnets")
    mname = magnets.get(
        "material", "ndfeb" if not {"density", "magnetisation"} & set(magnets) else "custom"
    )
    if not isinstance(mname, str):
        raise input_error("magnets.material", "a material name", mname)
    if mname in MAGNET_DATA:
        m_mag, m_rho = MAGNET_DATA[mname]
    elif not {"density", "magnetisation"} <= set(magnets):
        raise input_error(
            "magnets.material",
            "one of " + ", ".join(MAGNET_DATA) + " (or magnetisation and density)",
            mname,
        )
    else:
        m_mag, m_rho = 0.0, 0.0
    if "magnetisation" in magnets:
        m_mag = check_value("magnets", "magnetisation", magnets["magnetisation"])
    if "density" in magnets:
        m_rho = check_value("magnets", "density", magnets["density"])
    coercivity = MAGNET_COERCIVITY.get(mname)
    if "coercivity" in magnets:
        coercivity = check_value("magnets", "coercivity", magnets["coercivity"])
    return Material(
        "magnet",
        mname,
        m_rho,
        magnetisation=m_mag,
        coercivity=coercivity,
        **_response(magnets, "magnets", mname),
    )


def _ballasts(table: Mapping[str, Any]) -> list[Material]:
    """``[ballast]``: its material(s), at least one (the first is a magnet's attached mass)."""
    check_table(table, "ballast")
    ballasts = _ballast_list(table)
    if ballasts:
        return ballasts
    name, density = _density(table, "ballast", BALLAST_DENSITY, "tungsten")
    return [Material("ballast", name, density, **_response(table, "ballast", name))]


def _ballast_list(table: Mapping[str, Any]) -> list[Material]:
    """``[ballast] material = [...]``: the named materials (empty when a single name is given).

    A list asks the design to cancel the parts' induced magnetisation, which needs materials
    of both signs of susceptibility: at least one diamagnetic (chi < 0) one.
    """
    names = table.get("material")
    if not isinstance(names, list):
        return []
    if not names or not all(isinstance(x, str) for x in names) or len(set(names)) != len(names):
        raise input_error("ballast.material", "a material name or a list of distinct names", names)
    for key in ("density", *_RESPONSE_KEYS):
        if key in table:
            raise input_error(
                f"ballast.{key}", "no override with a list of materials (one material only)", key
            )
    out = []
    for name in names:
        if name not in BALLAST_DENSITY:
            raise input_error("ballast.material", "names among " + ", ".join(BALLAST_DENSITY), name)
        out.append(
            Material("ballast", name, BALLAST_DENSITY[name], **_response({}, "ballast", name))
        )
    if len(out) > 1 and not any((m.susceptibility or 0.0) < 0.0 for m in out):
        given = ", ".join(f"{m.name} (chi {fmt(m.susceptibility)})" for m in out)
        diamagnetic = ", ".join(
            k for k, v in SUSCEPTIBILITY.items() if v < 0 and k in BALLAST_DENSITY
        )
        raise InputError(
            f"ballast.material: cancelling the induced magnetisation needs a diamagnetic "
            f"material (chi < 0) beside {given}: add one of {diamagnetic}"
        )
    return out
