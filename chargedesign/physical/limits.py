"""Every physical limit, recomputed independently from a design's written elements.

The design stage (chargedesign.designer.assembly) keeps the limits as constraints; this module
recomputes them from the numbers in design.json alone, with denser surface samples than the
design used, so that "within its limits" is never the optimiser's word for itself (whether
the body is buildable, and realised, is the verdict's: :mod:`chargedesign.verdict`):

- surface fields: at points on every carrier sphere, the Coulomb field of all charges (each
  carrier's charge at its centre, exact for its own field) plus the largest external electric
  field over all orientations at that radius, against ``safety * breakdown``;
- parts do not overlap (carriers, magnets with any attached ballast, ballast spheres);
- every magnet has at least the volume ``|sigma| / M`` and the mass of that volume; every
  carrier at least the mass of its sphere or shell;
- the apparatus' field limits hold over the body region.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from chargedesign.formatting import PRECISE, fmt
from chargedesign.physical.coulomb import coulomb_field_gemm
from chargedesign.physical.field_bounds import RadialBound, field_magnitude_max, region_maxima
from chargedesign.physical.materials import (
    MAGNET_COERCIVITY,
    Material,
    ballast_materials,
    demagnetisation_limit,
    mass_densities,
    sphere_radius,
)
from chargedesign.physical.realism import field_response, k_law, magnet_continuum
from chargedesign.results import Result
from chargedesign.sampling import GOLDEN_ANGLE, fibonacci_sphere
from chargedesign.vocabulary import OLD_WITHIN_LIMITS_KEY, WITHIN_LIMITS_KEY

#: relative slack for rounding in the comparisons (not a physical margin)
ROUNDING_SLACK = 1e-9
#: sample points per carrier in the independent check
CHECK_SURFACE_SAMPLES = 1000
#: levels of refinement around the largest sample (caps of 1.5, 0.375, ... sample spacings)
REFINEMENTS = 4


def local_caps(directions: np.ndarray, angle: float, n: int = 48) -> np.ndarray:
    """Around each of ``directions`` (shape (k, 3)), the direction itself and ``n`` unit
    vectors within ``angle`` (rad) of it, spread evenly over the cap: shape (k, n + 1, 3)."""
    d = directions / np.linalg.norm(directions, axis=1, keepdims=True)
    helper = np.where(
        (np.abs(d[:, 0]) < 0.9)[:, None], np.array([1.0, 0.0, 0.0]), np.array([0.0, 1.0, 0.0])
    )
    u = np.cross(d, helper)
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    v = np.cross(d, u)
    i = np.arange(n) + 0.5
    r = angle * np.sqrt(i / n)  # uniform in the cap's area
    phi = GOLDEN_ANGLE * i
    ring = np.cos(phi)[None, :, None] * u[:, None, :] + np.sin(phi)[None, :, None] * v[:, None, :]
    out = np.cos(r)[None, :, None] * d[:, None, :] + np.sin(r)[None, :, None] * ring
    return np.concatenate([d[:, None, :], out], axis=1)


def sample_spacing(samples: int) -> float:
    """Typical angle between neighbouring Fibonacci directions, rad."""
    return math.sqrt(4.0 * math.pi / samples)


def carrier_surface_fields(
    positions: np.ndarray,
    charges: np.ndarray,
    radii: np.ndarray,
    electric: tuple[float, ...],
    samples: int = CHECK_SURFACE_SAMPLES,
) -> tuple[np.ndarray, np.ndarray]:
    """The largest surface field of each carrier, V/m, and the point where it occurs.

    Each carrier's own charge sits at its centre (its own field on the sphere is exact);
    the external field is its largest over orientations at the sample's radius. The
    Coulomb sums are the matrix-product kernel's
    (:func:`~chargedesign.physical.coulomb.coulomb_field_gemm`, in space axes: a code path
    of its own, neither the design's per-carrier kernel nor its cached geometry), within
    1e-10 of the direct sum and about 1.5x faster.

    Returns
    -------
    fields : ndarray, shape (n,)
    worst_points : ndarray, shape (n, 3)
    """
    n = len(charges)
    if n == 0:
        return np.zeros(0), np.zeros((0, 3))
    dirs = fibonacci_sphere(samples)
    r_top = float(np.max(np.linalg.norm(positions, axis=1) + radii, initial=0.0))
    external = _external_bound(tuple(electric), r_top * (1 + 1e-9))

    def magnitudes(unit: np.ndarray) -> np.ndarray:
        """|E| at ``positions + radii * unit`` (unit: (n, m, 3) directions), shape (n, m)."""
        flat = (positions[:, None, :] + radii[:, None, None] * unit).reshape(-1, 3)
        e = np.linalg.norm(coulomb_field_gemm(positions, charges, flat), axis=1)
        return (e + external(np.linalg.norm(flat, axis=1))).reshape(n, -1)

    # every carrier's samples at once, then caps of shrinking size around each one's largest,
    # so the maximum between samples is found too
    e = magnitudes(np.broadcast_to(dirs, (n, *dirs.shape)))
    rows = np.arange(n)
    top = np.argmax(e, axis=1)
    best, best_dir = e[rows, top], dirs[top]
    angle = 1.5 * sample_spacing(samples)
    for _ in range(REFINEMENTS):
        cap_dirs = local_caps(best_dir, angle)
        e_cap = magnitudes(cap_dirs)
        k = np.argmax(e_cap, axis=1)
        better = e_cap[rows, k] > best
        best = np.where(better, e_cap[rows, k], best)
        best_dir = np.where(better[:, None], cap_dirs[rows, k], best_dir)
        angle /= 4.0
    return best, positions + radii[:, None] * best_dir


def _external_bound(electric: tuple[float, ...], r_max: float) -> Any:
    """The external field's :class:`~chargedesign.physical.field_bounds.RadialBound` up to
    ``r_max``: the bound of the field scaled to its largest coefficient, times that
    coefficient (the largest magnitude is homogeneous of degree 1 in the coefficients), so
    the bodies of one frontier, whose electric fields differ by the rate alone, share it."""
    scale = max((abs(c) for c in electric), default=0.0)
    if scale == 0.0:
        return RadialBound(tuple(electric), r_max)
    unit = _unit_bound(tuple(c / scale for c in electric), r_max)
    return lambda radii: scale * unit(radii)


@functools.lru_cache(maxsize=8)
def _unit_bound(electric: tuple[float, ...], r_max: float) -> RadialBound:
    return RadialBound(electric, r_max)


def within_limits(record: dict[str, Any] | None) -> bool:
    """``buildability.parts_within_limits`` of a limits record (or the old ``buildable``)."""
    record = record or {}
    return bool(record.get(WITHIN_LIMITS_KEY, record.get(OLD_WITHIN_LIMITS_KEY)))


@dataclass(repr=False)
class LimitsReport(Result):
    """The verdict on a design's physical limits.

    Attributes
    ----------
    parts_within_limits : bool
        Every part within every limit (design.json ``buildability.parts_within_limits``;
        files written before the rename say ``buildable``, read by :func:`within_limits`).
        Not the verdict: magnets below the continuum size and parasitics above the fraction
        are judged there (:mod:`chargedesign.verdict`).
    surface_fields : ndarray, shape (n,)
        Largest surface field of every carrier, V/m.
    safe_field : float
        ``safety * breakdown``, V/m.
    violations : list[str]
        One line per limit broken.
    field_maxima : dict[str, float]
        Largest |B|, |E|, |g| over the body region.
    region_radius : float
        Radius of the body region, m.
    field_response : dict
        The applied field acting on the parts' materials (induced magnetisation, eddy
        currents; :func:`chargedesign.physical.realism.field_response`): realism verdicts,
        not limits, so they do not decide ``parts_within_limits``.
    k_law : dict
        The induced-magnetisation parasitic at the K frontier by the size-free law
        ``6 (chi/rho) / (mu0 G^2)`` (:func:`chargedesign.physical.realism.k_law`), recomputed
        from design.json (``frontier.K_max`` when written); empty when it does not apply.
    magnet_continuum : dict
        The magnets against the continuum size their material data hold for
        (:func:`chargedesign.physical.realism.magnet_continuum`): magnets below it are
        flagged in the text and in ``to_dict``, not counted as a broken limit.
    """

    parts_within_limits: bool
    surface_fields: np.ndarray
    safe_field: float
    breakdown: float
    violations: list[str] = field(default_factory=list)
    field_maxima: dict[str, float] = field(default_factory=dict)
    region_radius: float = 0.0
    field_response: dict[str, Any] = field(default_factory=dict)
    k_law: dict[str, Any] = field(default_factory=dict)
    magnet_continuum: dict[str, Any] = field(default_factory=dict)

    @property
    def worst_fraction_of_breakdown(self) -> float:
        return float(np.max(self.surface_fields, initial=0.0)) / self.breakdown

    def to_dict(self) -> dict[str, Any]:
        return {
            WITHIN_LIMITS_KEY: self.parts_within_limits,
            "largest_surface_field_V_per_m": float(np.max(self.surface_fields, initial=0.0)),
            "largest_surface_field_fraction_of_breakdown": self.worst_fraction_of_breakdown,
            "safe_field_V_per_m": self.safe_field,
            "violations": list(self.violations),
            "field_maxima": dict(self.field_maxima),
            "region_radius_m": self.region_radius,
            "field_response": dict(self.field_response),
            "k_law": dict(self.k_law),
            "magnet_continuum": dict(self.magnet_continuum),
        }

    def _summary(self) -> dict[str, Any]:
        return {
            WITHIN_LIMITS_KEY: self.parts_within_limits,
            "fraction_of_breakdown": self.worst_fraction_of_breakdown,
            "carriers": len(self.surface_fields),
            "violations": len(self.violations),
        }

    def _text(self) -> str:
        top = float(np.max(self.surface_fields, initial=0.0))
        lines = [
            (
                "parts within their limits"
                if self.parts_within_limits
                else "parts NOT within their limits"
            )
            + f" (recomputed from the elements): largest carrier surface field "
            f"{fmt(top, PRECISE)} V/m, {fmt(self.worst_fraction_of_breakdown, PRECISE)} of"
            " breakdown "
            f"({fmt(self.breakdown)} V/m; safe {fmt(self.safe_field)} V/m)"
        ]
        lines += [f"violation: {v}" for v in self.violations]
        for key, item in self.field_response.items():
            if key.startswith("induced"):
                # the induced magnetisation is printed once, as its one figure (the check's
                # own, physical.budget.induced_magnetisation); the energy over the typical
                # torque stays in to_dict as its input
                continue
            value = item.get("value")
            shown = "inf" if value is None else f"{fmt(value)}"
            lines.append(f"{key.replace('_', ' ')}: {shown} ({item['verdict']}): {item['note']}")
        if self.k_law:
            value = self.k_law.get("value", self.k_law["ratio"])
            lines.append(
                f"the K law (ordinary matter's induced-magnetisation energy range at the K "
                f"frontier): {fmt(value)} x the designed K torques C K_max^2 "
                f"({self.k_law['verdict']}): {self.k_law['note']}"
            )
        below = self.magnet_continuum.get("below", 0)
        if below:
            m = self.magnet_continuum
            lines.append(
                f"magnets below the continuum size: {below} of {m['count']} "
                f"({fmt(m['smallest_m'])} m to {fmt(m['largest_m'])} m across, under "
                f"{fmt(m['continuum_size_m'])} m): single-domain nanoparticles whose moment and "
                "coercivity are not their material's data (not buildable as specified)"
            )
        return "\n".join(lines)


def part_radii(design: Any) -> tuple[np.ndarray, np.ndarray]:
    """Every part as a sphere: centres (p, 3) and radii (p,), m.

    Carriers have their radius; a magnet the sphere of its volume plus any ballast attached
    to it (mass beyond its own); ballast the sphere of its volume.
    """
    materials = design.materials
    magnet_rho = materials["magnet"]["density_kg_per_m3"] if "magnet" in materials else 0.0
    ballasts = ballast_materials(materials)  # a magnet's attached ballast: the first
    ballast_rho = ballasts[0]["density_kg_per_m3"] if ballasts else np.inf
    vol = design.magnet_volumes()
    extra = np.maximum(design.magnet_masses() - magnet_rho * vol, 0.0) / ballast_rho
    magnet_r = sphere_radius(vol + extra)
    ballast_r = sphere_radius(design.mass_values / mass_densities(design))
    centres = np.concatenate(
        [design.charge_positions, design.dipole_positions, design.mass_positions]
    )
    radii = np.concatenate([design.carrier_radii(), magnet_r, ballast_r])
    return centres, radii


#: up to this many points :func:`close_pairs` compares blocks of rows in numpy (the limits
#: check's parts, and the check command then loads no scipy); beyond, scipy's KD-tree (the
#: testbed's level sets, up to about 1,200 states; docs/benchmarks.md, "Close pairs"), the
#: same pairs
PAIRS_BY_BLOCKS_MAX = 256


def close_pairs(centres: np.ndarray, reach: float) -> np.ndarray:
    """Index pairs ``(i, j)``, ``i < j``, of the points at most ``reach`` apart (``<=``),
    shape (k, 2), in lexicographic order.

    ``centres`` has shape (p, d): the parts' centres (m, ``reach`` m), or the testbed's scaled
    states (d = 6, :mod:`chargedesign.airbearing.bearing`). A pair is in when the squares of
    its differences, summed in axis order, are at most ``reach * reach``: so the numpy blocks
    (a few MB of differences at a time; ``scipy.spatial``, used here before, cost about 0.5 s
    of CPU to import, a third of the whole check of the default design) and the KD-tree's
    ``query_pairs`` beyond :data:`PAIRS_BY_BLOCKS_MAX` points find the same pairs, ties
    included (tests/physical/test_overlap.py).
    """
    n = len(centres)
    if n > PAIRS_BY_BLOCKS_MAX:
        from scipy.spatial import cKDTree

        pairs = cKDTree(centres).query_pairs(reach, output_type="ndarray")
        return pairs[np.lexsort((pairs[:, 1], pairs[:, 0]))]
    block = max(1, 2**17 // max(n, 1))
    found = []
    for start in range(0, n - 1, block):
        rows = centres[start : start + block]
        d2 = np.sum((rows[:, None, :] - centres[None, start + 1 :, :]) ** 2, axis=2)
        i, j = np.nonzero(d2 <= reach * reach)
        j = j + start + 1
        keep = j > i + start
        found.append(np.stack([i[keep] + start, j[keep]], axis=1))
    return np.concatenate(found) if found else np.empty((0, 2), dtype=np.intp)


def overlapping_pairs(
    centres: np.ndarray, radii: np.ndarray, slack: float = 0.0
) -> tuple[np.ndarray, np.ndarray]:
    """The pairs of spheres (``centres`` (p, 3), ``radii`` (p,), m) that overlap by more than
    ``slack`` of their centres' distance, ``(i, j)`` with ``i < j`` in lexicographic order,
    shape (k, 2), and their overlaps ``r_i + r_j - d``, m, shape (k,): the limits check's
    parts and the testbed's ballast."""
    if len(centres) < 2:
        return np.empty((0, 2), dtype=np.intp), np.zeros(0)
    pairs = close_pairs(centres, 2.0 * float(radii.max()))
    d = np.linalg.norm(centres[pairs[:, 0]] - centres[pairs[:, 1]], axis=1)
    gap = d - radii[pairs[:, 0]] - radii[pairs[:, 1]]
    bad = gap < -slack * d
    return pairs[bad], -gap[bad]


def _demagnetised(design: Any, magnet: dict[str, Any], volumes: np.ndarray) -> list[str]:
    """A magnet in a field beyond what its material withstands loses its magnetisation.

    The coercivity is the written one, else the named material's (older files); unknown:
    nothing is said. Each magnet is the sphere of its volume; the field is the largest |B|
    over every orientation anywhere on it.
    """
    coercivity = magnet.get("intrinsic_coercivity_A_per_m", MAGNET_COERCIVITY.get(magnet["name"]))
    magnetic = design.field("magnetic")
    if coercivity is None or not magnetic or not len(volumes):
        return []
    withstood = demagnetisation_limit(magnet["remanent_magnetisation_A_per_m"], coercivity)
    reach = np.linalg.norm(design.dipole_positions, axis=1) + sphere_radius(volumes)
    fields = field_magnitude_max(tuple(magnetic), reach)
    over = np.flatnonzero(fields > withstood * (1 + ROUNDING_SLACK))
    if not len(over):
        return []
    i = int(over[np.argmax(fields[over])])
    return [
        f"dipole {i}: the field reaches {fmt(fields[i])} T there, beyond the {fmt(withstood)} T "
        f"a {magnet['name']} magnet withstands (intrinsic coercivity {fmt(coercivity)} A/m less "
        f"its own demagnetising field M/3): it would be demagnetised as the body turns"
        + (f" ({len(over)} magnets)" if len(over) > 1 else "")
    ]


def check_limits(design: Any, samples: int = CHECK_SURFACE_SAMPLES) -> LimitsReport:
    """Recompute every physical limit of ``design`` from its elements (see the module doc).

    ``design`` is a :class:`~chargedesign.body.Design` with ``medium`` and ``materials``.
    """
    medium = design.medium
    safe = medium.safety * medium.breakdown
    breakdown = medium.breakdown
    violations: list[str] = []
    radii = design.carrier_radii()
    fields, _ = carrier_surface_fields(
        design.charge_positions, design.charge_values, radii, design.field("electric"), samples
    )
    over = np.flatnonzero(fields > safe * (1 + ROUNDING_SLACK))
    for i in over[:5]:
        violations.append(
            f"charge {i}: surface field {fmt(fields[i])} V/m is {fmt(fields[i] / safe)}x the safe "
            f"field of {medium.name} ({fmt(safe)} V/m)"
        )
    if len(over) > 5:
        violations.append(f"... and {len(over) - 5} more carriers above the safe field")
    point_carriers = np.flatnonzero((radii == 0) & (design.charge_values != 0))
    if len(point_carriers):
        violations.append(f"charge {point_carriers[0]}: a point charge has no carrier")
    centres, part_r = part_radii(design)
    pairs, overlaps = overlapping_pairs(centres, part_r, slack=ROUNDING_SLACK)
    if len(pairs):
        i, j = pairs[0]
        violations.append(f"parts {i} and {j} overlap ({fmt(overlaps[0])} m)")
    magnet = design.materials.get("magnet")
    if magnet is not None and len(design.dipole_moments):
        need = (
            np.linalg.norm(design.dipole_moments, axis=1) / magnet["remanent_magnetisation_A_per_m"]
        )
        vol = design.magnet_volumes()
        small = np.flatnonzero(vol < need * (1 - ROUNDING_SLACK))
        if len(small):
            violations.append(
                f"dipole {small[0]}: volume {fmt(vol[small[0]])} m^3 below |sigma|/M = "
                f"{fmt(need[small[0]])} m^3"
            )
        light = np.flatnonzero(
            design.magnet_masses() < magnet["density_kg_per_m3"] * vol * (1 - ROUNDING_SLACK)
        )
        if len(light):
            violations.append(f"dipole {light[0]}: lighter than its volume of magnet material")
        violations += _demagnetised(design, magnet, vol)
    carrier = design.materials.get("carrier")
    if carrier is not None and len(radii):
        material = Material(
            "carrier",
            carrier["name"],
            carrier["density_kg_per_m3"],
            shell_thickness=carrier.get("shell_thickness_m"),
        )
        # Material.sphere_mass on every carrier at once (a shell at least as thick as the
        # sphere is the solid sphere)
        wall = material.shell_thickness
        inner = np.zeros_like(radii) if wall is None else np.where(wall < radii, radii - wall, 0)
        need_mass = material.density * 4.0 / 3.0 * math.pi * (radii**3 - inner**3)
        light = np.flatnonzero(design.carrier_masses() < need_mass * (1 - ROUNDING_SLACK))
        if len(light):
            violations.append(f"charge {light[0]}: carrier lighter than its sphere of material")
    region = float(np.max(np.linalg.norm(centres, axis=1) + part_r, initial=0.0))
    limits = design.field_limits or {}
    maxima = region_maxima(
        {kind: design.field(kind) for kind in ("magnetic", "electric", "gravity")}, region
    )
    for kind, top in maxima.items():
        if kind in limits and top > limits[kind] * (1 + ROUNDING_SLACK):
            violations.append(
                f"fields.{kind}: reaches {fmt(top)} over the body region, above its "
                f"max = {fmt(limits[kind])}"
            )
    response = field_response(design)
    return LimitsReport(
        parts_within_limits=not violations,
        field_response=response,
        k_law=k_law(design, response),
        magnet_continuum=magnet_continuum(design),
        surface_fields=fields,
        safe_field=safe,
        breakdown=breakdown,
        violations=violations,
        field_maxima=maxima,
        region_radius=region,
    )
