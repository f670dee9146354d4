"""The bill of materials: one row per part, then totals and the fields the apparatus makes."""

from __future__ import annotations

import csv
import io
from typing import Any

import numpy as np

from chargedesign.formatting import fmt
from chargedesign.physical.materials import ballast_groups, ballast_materials, mass_densities

BOM_COLUMNS = (
    "part",
    "kind",
    "x_m",
    "y_m",
    "z_m",
    "size",
    "size_unit",
    "material",
    "charge_C",
    "moment_x_A_m2",
    "moment_y_A_m2",
    "moment_z_A_m2",
    "mass_kg",
)


def bom_rows(design: Any) -> list[dict[str, Any]]:
    """Carriers (radius, m), magnets (volume, m^3) and ballast (volume, m^3), in that order."""
    materials = design.materials
    carrier = materials.get("carrier", {}).get("name", "point")
    magnet = materials.get("magnet", {}).get("name", "point dipole")
    ballasts = ballast_materials(materials)
    ballast = ballasts[0] if ballasts else {}  # a magnet's attached ballast: the first
    rows: list[dict[str, Any]] = []
    radii, cmass = design.carrier_radii(), design.carrier_masses()
    for i, (pos, q) in enumerate(zip(design.charge_positions, design.charge_values, strict=True)):
        rows.append(_row(f"C{i}", "carrier", pos, radii[i], "m", carrier, q, None, cmass[i]))
    vols, mmass = design.magnet_volumes(), design.magnet_masses()
    rho_m = materials.get("magnet", {}).get("density_kg_per_m3", 0.0)
    for i, (pos, sigma) in enumerate(
        zip(design.dipole_positions, design.dipole_moments, strict=True)
    ):
        extra = mmass[i] - rho_m * vols[i]
        name = magnet + (
            f" + {fmt(extra)} kg {ballast.get('name', 'ballast')}" if extra > 0 else ""
        )
        rows.append(_row(f"M{i}", "magnet", pos, vols[i], "m^3", name, None, sigma, mmass[i]))
    names = ["point"] * len(design.mass_values)
    for spec, idx in ballast_groups(design):  # each part's own material
        for i in idx:
            names[i] = spec.get("name", "ballast")
    densities = mass_densities(design)  # inf: no material given, a point mass
    for i, (pos, m) in enumerate(zip(design.mass_positions, design.mass_values, strict=True)):
        vol = m / densities[i]
        rows.append(_row(f"B{i}", "ballast", pos, vol, "m^3", names[i], None, None, m))
    return rows


def _row(part, kind, pos, size, unit, material, q, sigma, mass) -> dict[str, Any]:
    """One part's row, its values in the order of :data:`BOM_COLUMNS`."""
    sigma = np.zeros(3) if sigma is None else sigma
    charge = 0.0 if q is None else float(q)
    values = (part, kind, *map(float, pos[:3]), float(size), unit, material, charge)
    return dict(zip(BOM_COLUMNS, (*values, *map(float, sigma[:3]), float(mass)), strict=True))


def bom_csv(design: Any) -> str:
    """``bom.csv``: a plain header row, then one row per part (reads with pandas.read_csv)."""
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=list(BOM_COLUMNS), lineterminator="\n")
    writer.writeheader()
    for row in bom_rows(design):
        writer.writerow({k: (repr(v) if isinstance(v, float) else v) for k, v in row.items()})
    return buffer.getvalue()


def bom_totals(design: Any) -> dict[str, Any]:
    """Counts, masses, charges, magnet volume and the fields the apparatus must make."""
    limits = design.buildability or {}
    return {
        "carriers": len(design.charge_values),
        "magnets": len(design.dipole_moments),
        "ballast": len(design.mass_values),
        "mass_carriers_kg": float(np.sum(design.carrier_masses())),
        "mass_magnets_kg": float(np.sum(design.magnet_masses())),
        "mass_ballast_kg": float(np.sum(design.mass_values)),
        "mass_total_kg": design.total_mass,
        "charge_net_C": float(np.sum(design.charge_values)),
        "charge_abs_C": float(np.sum(np.abs(design.charge_values))),
        "magnet_volume_m3": float(np.sum(design.magnet_volumes())),
        "fields": {k: list(v) for k, v in design.fields.items()},
        "field_maxima_over_body": limits.get("field_maxima", {}),
    }
