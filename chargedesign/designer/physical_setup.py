"""Physical design, its setup: every element a real part within the limits of its medium.

The conditions engine gives, per source, ``A w = b`` (SI). With the theorem's time rate ``s``
(``n, K -> s n, s K``; ``kappa, lambda, rho -> s^2 ...``; the same motion s times faster)
the charges' right-hand sides and the derived electric field scale with ``s``, the dipoles'
with ``s^2``, and the masses' not at all. The design at rate ``s`` is two convex programs,
because the charges' conditions involve no mass while the carriers' masses depend on which
carriers are used: the charges (:mod:`chargedesign.designer.charges`), then the magnets and
masses jointly (:mod:`chargedesign.designer.masses`); :mod:`chargedesign.designer.assembly`
puts them together into a body. This module holds what all stages share: the setup at rate 1
(:func:`setup_physical`), the design margin and the binding limit of a refusal.
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from functools import cached_property
from typing import Any

import numpy as np

from chargedesign.candidates import CandidateSet, nearest_distances
from chargedesign.constants import EPSILON_0
from chargedesign.designer.charge_symmetry import ChargeSymmetry, charge_symmetry
from chargedesign.designer.robust import robust_costs
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.larmor import LarmorReading
from chargedesign.moment_conditions import LinearConditions
from chargedesign.params import Parameters
from chargedesign.physical.field_bounds import FieldReach, field_reach
from chargedesign.scene.design import DesignOptions
from chargedesign.scene.physical import CARRIER_RADIUS_FRACTION, PhysicalSpec

#: the design keeps every limit this fraction below its value, so that polishing (relative
#: changes ~1e-10) and the check's denser samples never find it above
DESIGN_MARGIN = 1e-3


@dataclass
class Binding:
    """The limit that stops a design: which element, which limit, and by how much."""

    stage: str  # charges | magnets | masses | fields | balance | limits | forward
    limit: str
    element: str = ""
    factor: float = math.inf  # the limit is exceeded by this factor (inf: not measured)
    #: the refusal is proved for this rate and every faster one (a relaxation of the limits
    #: is infeasible, and feasible charges scale down with the rate), not only found by the
    #: heuristic: the frontier need not design faster rates
    proved: bool = False

    def text(self, medium: str) -> str:
        return f"{self.element + ': ' if self.element else ''}{self.limit}"

    def to_dict(self) -> dict[str, Any]:
        return {"stage": self.stage, "limit": self.limit, "element": self.element}


class PhysicalInfeasible(InfeasibleError):
    """A design at this time rate breaks a physical limit (``binding`` names it)."""

    def __init__(self, binding: Binding) -> None:
        super().__init__(binding.text(""))
        self.binding = binding


@dataclass
class PhysicalSetup:
    """Everything the physical design needs at time rate 1, in SI units."""

    params: Parameters
    conditions: LinearConditions
    candidates: CandidateSet
    spec: PhysicalSpec
    options: DesignOptions
    points: np.ndarray
    cell_radius: np.ndarray  # half the nearest-neighbour distance of each candidate, m
    carrier_radius: float
    carrier_mass: float
    region_radius: float
    systems: dict[str, tuple[np.ndarray, np.ndarray]] = field(default_factory=dict)
    electric: tuple[float, ...] = ()
    e_grid: np.ndarray = field(default_factory=lambda: np.zeros(0))
    e_grid_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    #: the largest rate the apparatus' electric-field limit allows (inf: no limit); computed
    #: once, where the setup is made
    rate_bound: float = math.inf
    #: per-candidate objective costs of the sources designed robustly (others cost 1)
    costs: dict[str, np.ndarray] = field(default_factory=dict)
    #: candidates where a magnet keeps its magnetisation: the largest |B| over its cell stays
    #: below what the magnet material withstands (all True when its coercivity is unknown)
    magnet_sites: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    #: how the theorem's n is realised (rate at time rate 1); ``params`` are then the
    #: parameters the elements realise (n = 0 for ``frame``)
    larmor: LarmorReading | None = None
    #: a general case's design.json ``case`` record (None: the theorem's body), written into
    #: every body built: its budgets read the case's own rate and terms from it
    model_record: dict[str, Any] | None = None
    #: the constraint generations' last working sets (candidate indices), seeds of the next
    #: solve on the same candidates (the whole-inertia rounds, probes at other rates)
    warm: dict[str, np.ndarray] = field(default_factory=dict, repr=False, compare=False)

    @property
    def theorem_params(self) -> Parameters:
        """The theorem's parameters at rate 1 (``params`` with the Larmor rate as n)."""
        if self.larmor is not None and self.larmor.is_frame:
            return replace(self.params, n=self.larmor.rate)
        return self.params

    def cost(self, source: str) -> np.ndarray:
        """Objective cost of each candidate for ``source`` (ones unless robust)."""
        return self.costs.get(source, np.ones(len(self.points)))

    @property
    def safe_field(self) -> float:
        return self.spec.medium.safe_field

    @property
    def surface_limit(self) -> float:
        """The surface field every carrier is held to, V/m: the medium's safe field less the
        design margin (:data:`DESIGN_MARGIN`)."""
        return self.safe_field * (1 - DESIGN_MARGIN)

    def external_max(self, radii: np.ndarray, s: float) -> np.ndarray:
        """Largest external electric field over orientations at these radii, rate s (V/m).

        A nondecreasing function of the radius sampled on a grid: the next grid value up is
        an upper bound.
        """
        if not self.electric:
            return np.zeros_like(radii)
        idx = np.searchsorted(self.e_grid, radii, side="left")
        idx = np.minimum(idx, len(self.e_grid) - 1)
        return s * self.e_grid_values[idx]

    @cached_property
    def carrier_external(self) -> np.ndarray:
        """The external field's bound at each candidate carrier's outer surface at rate 1,
        V/m, shape (n,): read once from the grid (every rate scales it)."""
        return self.external_max(np.linalg.norm(self.points, axis=1) + self.carrier_radius, 1.0)

    def charge_caps(self, s: float) -> np.ndarray:
        """Own-field bound of each candidate carrier at rate s, C (<= 0: unusable)."""
        limit = self.surface_limit - s * self.carrier_external
        return 4 * math.pi * EPSILON_0 * self.carrier_radius**2 * limit

    @cached_property
    def symmetry(self) -> ChargeSymmetry | None:
        """The symmetries of the charges' conditions on the candidates (None: the identity
        alone), found once for every program of the charges' stage that uses them."""
        A, b = self.systems["charges"]
        return charge_symmetry(A, b, self.points)

    @cached_property
    def rest_caps(self) -> np.ndarray:
        """Each candidate carrier's own-field bound at rate 0, C, shape (n,)
        (:meth:`charge_caps` at ``s = 0``), computed once."""
        return self.charge_caps(0.0)

    @cached_property
    def caps_per_rate(self) -> np.ndarray:
        """What the external field takes of each carrier's bound per unit rate, C, shape
        (n,): ``rest_caps - charge_caps(1)``, computed once (the caps are linear in the rate)."""
        return self.rest_caps - self.charge_caps(1.0)


def _carrier_radius(spec: PhysicalSpec, spacing: float) -> float:
    """The carriers' radius: the scene's, below half the candidate spacing, or a fixed
    fraction of it."""
    a = spec.carrier_radius
    if a is None:
        return CARRIER_RADIUS_FRACTION * spacing
    if a >= 0.5 * spacing:
        raise InputError(
            f"body.carrier_radius: expected below half the candidate spacing "
            f"({fmt(0.5 * spacing, PRECISE)} m) so carriers cannot touch, got {fmt(a, PLAIN)}"
        )
    return float(a)


def _check_field_limits(spec: PhysicalSpec, maxima: Mapping[str, float], region: float) -> None:
    """The scene's magnetic and gravity fields within their ``max`` over the body region
    (``maxima``: each field's largest magnitude there; the electric field's limit bounds the
    rate instead)."""
    for kind, limit in spec.field_limits.items():
        top = maxima.get(kind)
        if kind == "electric" or top is None:
            continue
        if top > limit:
            raise InputError(
                f"fields.{kind}.max: the scene's {kind} field already reaches "
                f"{fmt(top, PRECISE)} over the body region (radius {fmt(region, PRECISE)} m), "
                f"above max = {fmt(limit, PLAIN)}"
            )


def _magnet_sites(
    spec: PhysicalSpec,
    withstood: float | None,
    reach: FieldReach,
    dipoles: tuple[np.ndarray, np.ndarray],
    n: int,
) -> np.ndarray:
    """Candidates where a magnet keeps its magnetisation (the largest |B| over its cell,
    ``reach.magnetic_at``, stays below ``withstood``, what the magnet material withstands;
    None: unknown); InfeasibleError when V's moments cannot be met there."""
    magnet_sites = np.ones(n, dtype=bool)
    if withstood is not None and reach.magnetic_at is not None:
        magnet_sites = reach.magnetic_at <= withstood
        if not _moments_reachable(dipoles, magnet_sites):
            where = (
                f"at every candidate site but {int(np.sum(magnet_sites))}, and magnets there "
                "cannot give the moments V needs"
                if np.any(magnet_sites)
                else "at every candidate site, and V needs magnets"
            )
            raise InfeasibleError(
                f"magnets.material: a {spec.magnet.name} magnet withstands {fmt(withstood)} T "
                "(its intrinsic coercivity less its own demagnetising field M/3), but the "
                f"magnetic field exceeds that as the body turns {where}: use a "
                "higher-coercivity grade (ndfeb-eh, smco), a weaker field or a larger body"
            )
    return magnet_sites


def check_physical_candidates(n: int, body: Mapping[str, Any] | None = None) -> None:
    """A physical design's candidates: at least two (each cell is half the nearest
    neighbour's distance). ``body`` (the ``[body]`` table) lets the line say why: a spacing
    larger than the body's size leaves one point (a sweep's 0.25 m spacing on a 5 cm ball)."""
    if n < 2:
        why = ""
        table = body or {}
        spacing = table.get("spacing")
        sizes = [table[k] for k in ("radius", "size", "height") if k in table]
        sizes = [max(v) if isinstance(v, list) else v for v in sizes]
        if isinstance(spacing, (int, float)) and sizes:
            why = (
                f": body.spacing = {fmt(spacing, PLAIN)} m on a {table.get('shape', 'body')} "
                f"of {fmt(max(sizes), PLAIN)} m gives {n}; give a spacing well below its size"
            )
        raise InputError(f"body: a physical design needs at least two candidate points{why}")


def _cells(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Each candidate's cell radius (half its nearest neighbour's distance) and the spacing."""
    check_physical_candidates(len(points))
    nearest = nearest_distances(points)
    return 0.5 * nearest, float(np.min(nearest))


def _electric_rate_bound(spec: PhysicalSpec, reach: FieldReach) -> float:
    """The largest rate the apparatus' electric-field limit allows (inf: no limit)."""
    limit = spec.field_limits.get("electric")
    top = reach.maxima.get("electric")  # the grid's last value, to the last bit
    if limit is None or top is None:
        return math.inf
    return limit / top if top > 0 else math.inf


def setup_physical(
    params: Parameters,
    conditions: LinearConditions,
    candidates: CandidateSet,
    spec: PhysicalSpec,
    options: DesignOptions | None = None,
    *,
    larmor: LarmorReading | None = None,
    model_record: dict[str, Any] | None = None,
) -> PhysicalSetup:
    """Validate the physical spec against the candidates and build the systems at rate 1.

    ``params`` and ``conditions`` are those the elements realise; ``larmor`` (its rate the
    theorem's n at rate 1) is recorded in every design built (n = 0 in ``params`` for
    ``frame``). ``options`` are those
    :func:`~chargedesign.designer.pipeline.check_physical_options` took, before the candidates
    and conditions were made. ``model_record``: a general case's design.json ``case`` record
    (:attr:`PhysicalSetup.model_record`).
    """
    options = options or DesignOptions()
    points = candidates.points
    cell, spacing = _cells(points)
    a = _carrier_radius(spec, spacing)
    reach_of_cells = np.linalg.norm(points, axis=1) + cell
    region = float(np.max(reach_of_cells))
    # every applied field's bound over the region and the cells, in one descent; the
    # magnetic field's over each cell only where a magnet material's coercivity is known
    withstood = spec.magnet.field_withstood()
    reach = field_reach(
        conditions.fields,
        region,
        magnetic_radii=reach_of_cells if withstood is not None else None,
    )
    _check_field_limits(spec, reach.maxima, region)
    systems = {s: conditions.system(s, points) for s in ("charges", "dipoles", "masses")}
    magnet_sites = _magnet_sites(spec, withstood, reach, systems["dipoles"], len(points))
    rate_bound = _electric_rate_bound(spec, reach)
    # the robust costs (the placement sensitivities) are weighed once no setup refusal is
    # left: a magnet material the field demagnetises is refused before that work
    costs = {
        source: robust_costs(points, source, conditions.fields, params, options.robust_weight)
        for source in systems
        if options.objective_for(source) == "robust"
    }
    return PhysicalSetup(
        params=params,
        conditions=conditions,
        candidates=candidates,
        spec=spec,
        options=options,
        points=points,
        cell_radius=cell,
        carrier_radius=a,
        carrier_mass=spec.carrier.sphere_mass(a),
        region_radius=region,
        systems=systems,
        electric=tuple(conditions.fields.get("electric", ())),
        e_grid=reach.electric_grid,
        e_grid_values=reach.electric_values,
        rate_bound=rate_bound,
        costs=costs,
        magnet_sites=magnet_sites,
        larmor=larmor,
        model_record=model_record,
    )


def _moments_reachable(system: tuple[np.ndarray, np.ndarray], sites: np.ndarray) -> bool:
    """Whether dipoles on ``sites`` alone can meet ``A sigma = b`` (any size, any rate: the
    right-hand side only scales with the rate), by least squares on those columns."""
    A, b = system
    if not len(b) or not np.any(b != 0):
        return True
    idx = np.flatnonzero(sites)
    if not len(idx):
        return False
    cols = (3 * idx[:, None] + np.arange(3)).reshape(-1)
    x, *_ = np.linalg.lstsq(A[:, cols], b, rcond=None)
    return bool(np.linalg.norm(A[:, cols] @ x - b) <= 1e-9 * np.linalg.norm(b))
