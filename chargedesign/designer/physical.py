"""Physical design: every element a real part within the limits of its medium and material.

The conditions engine gives, per source, ``A w = b`` (SI). With the theorem's time rate ``s``
(``n, K -> s n, s K``; ``kappa, lambda, rho -> s^2 ...``; the same motion s times faster)
the charges' right-hand sides and the derived electric field scale with ``s``, the dipoles'
with ``s^2``, and the masses' not at all. The design at rate ``s`` is two convex programs,
because the charges' conditions involve no mass while the carriers' masses depend on which
carriers are used:

1. **charges** (carriers of radius ``a`` at candidate points): ``A_c q = s b_c`` and, at sample
   points x on every carrier surface, ``|sum_j q_j G_j(x)| <= E_safe - s E_ext(|x|)`` (second-
   order cones, linear in q; ``E_ext`` the largest external field over orientations). Solved
   by constraint generation: an LP with each carrier's own-field bound
   ``|q_i| <= 4 pi eps0 a^2 (E_safe - s E_ext)`` (necessary, so its infeasibility proves the
   design impossible), then cones only where the independent surface check finds a carrier
   above its limit, on the working set of used carriers;
2. **magnets and masses** jointly, on the sites not holding a carrier: ``A_d sigma = s^2 b_d``,
   ``A_m w = b_m - A_m(carriers) m_carrier`` (the inertia and centre of mass of all mass), site
   mass ``w_i >= rho_magnet |sigma_i| / M`` (a magnet weighs at least its volume), and
   ``|sigma_i| / M + w_i / rho_ballast <= V_cell`` (magnet plus ballast fit in the cell).

Both are polished to machine precision on their supports and the limits verified again with
denser samples (:func:`chargedesign.physical.limits.check_limits`). :func:`physical_problem`
returns the second stage, or both stages as one cvxpy problem for a given carrier set, for a
user to extend.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace
from typing import Any

import numpy as np
from scipy import sparse
from scipy.optimize import linprog
from scipy.spatial import cKDTree

from chargedesign.body import Design
from chargedesign.candidates import CandidateSet
from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.designer.acceptance import balance_bound
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.result import DesignResult, SourceResult, record_provenance
from chargedesign.designer.robust import robust_costs, weighted_norm
from chargedesign.designer.solvers import least_norm
from chargedesign.designer.system import relative_residual
from chargedesign.errors import InfeasibleError, InputError, SolverError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.larmor import LarmorReading
from chargedesign.moment_conditions import LinearConditions
from chargedesign.params import Parameters
from chargedesign.physical.coulomb import coulomb_field_gemm, coulomb_kernel
from chargedesign.physical.field_bounds import field_magnitude_max
from chargedesign.physical.induced import induced_rows
from chargedesign.physical.limits import (
    check_limits,
    fibonacci_directions,
    local_caps,
    sample_spacing,
)
from chargedesign.physical.realism import realism_budget
from chargedesign.scene.design import DesignOptions, Progress
from chargedesign.scene.physical import CARRIER_RADIUS_FRACTION, PhysicalSpec

#: the design keeps every limit this fraction below its value, so that polishing (relative
#: changes ~1e-10) and the check's denser samples never find it above
DESIGN_MARGIN = 1e-3
#: objectives of the physical design (l2 and linf are not built for the cones and cells)
PHYSICAL_OBJECTIVES = ("l1", "robust")
#: surface samples of the in-loop check (constraint generation)
LOOP_SURFACE_SAMPLES = 200
#: LP rounds first (at most LP_ROUNDS), then cone rounds until the total reaches this
MAX_ROUNDS = 26
#: rounds of own-field bound tightening before the cones
LP_ROUNDS = 12
#: carriers above this fraction of the safe field get cones before they break it
CONE_THRESHOLD = 0.95
#: charges below these fractions of the largest are dropped before the polish, the first
#: that polishes within the limits is kept: an interior point leaves the zeros of the optimum
#: at its tolerance, carriers that would take the masses' cells for nothing (measured on the
#: small test body at s = 79.2: Clarabel left 7 carriers at 5e-9 to 2e-6 of the largest, the
#: smallest true charge being 1.7e-3 of it); 1e-9 keeps the solver's whole support
CHARGE_RESIDUES = (1e-5, 1e-9)
#: the polished charges meet A q = s b to this relative residual
POLISHED_RESIDUAL = 1e-12


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
    #: per-candidate objective costs of the sources designed robustly (others cost 1)
    costs: dict[str, np.ndarray] = field(default_factory=dict)
    #: candidates where a magnet keeps its magnetisation: the largest |B| over its cell stays
    #: below what the magnet material withstands (all True when its coercivity is unknown)
    magnet_sites: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    #: how the theorem's n is realised (rate at time rate 1); ``params`` are then the
    #: parameters the elements realise (n = 0 for ``frame``)
    larmor: LarmorReading | None = None

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

    def charge_caps(self, s: float) -> np.ndarray:
        """Own-field bound of each candidate carrier at rate s, C (<= 0: unusable)."""
        limit = self.safe_field * (1 - DESIGN_MARGIN) - self.external_max(
            np.linalg.norm(self.points, axis=1) + self.carrier_radius, s
        )
        return 4 * math.pi * EPSILON_0 * self.carrier_radius**2 * limit

    def field_bound(self, s: float) -> float:
        """Largest rate the apparatus' electric-field limit allows (inf: no limit)."""
        limit = self.spec.field_limits.get("electric")
        if limit is None or not self.electric:
            return math.inf
        top = float(field_magnitude_max(self.electric, np.array([self.region_radius]))[0])
        return limit / top if top > 0 else math.inf


def _check_physical_options(options: DesignOptions, conditions: LinearConditions) -> None:
    """The [design] options a physical design takes (one line naming the one it does not)."""
    for source in ("charges", "dipoles", "masses"):
        if options.objective_for(source) not in PHYSICAL_OBJECTIVES:
            raise InputError(
                f"design.objective: {options.objective_for(source)!r} for {source} is not "
                "available with [medium] (expected " + " or ".join(PHYSICAL_OBJECTIVES) + ")"
            )
    if "inertia" not in (options.realise or conditions.realise):
        raise InputError(
            "design.realise: a physical design realises the inertia (every part has mass)"
        )
    if options.total_charge is not None or options.n_charges is not None:
        raise InputError(
            "design.total_charge / n_charges: not available with [medium] (the carriers' "
            "limits decide the charges)"
        )


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


def _check_field_limits(spec: PhysicalSpec, conditions: LinearConditions, region: float) -> None:
    """The scene's magnetic and gravity fields within their ``max`` over the body region
    (the electric field's limit bounds the rate instead)."""
    for kind, limit in spec.field_limits.items():
        coeffs = conditions.fields.get(kind, ())
        if kind == "electric" or not coeffs:
            continue
        top = float(field_magnitude_max(coeffs, np.array([region]))[0])
        if top > limit:
            raise InputError(
                f"fields.{kind}.max: the scene's {kind} field already reaches {fmt(top, PRECISE)}"
                " over the "
                f"body region (radius {fmt(region, PRECISE)} m), above max = {fmt(limit, PLAIN)}"
            )


def _magnet_sites(
    spec: PhysicalSpec,
    conditions: LinearConditions,
    points: np.ndarray,
    cell: np.ndarray,
    dipoles: tuple[np.ndarray, np.ndarray],
) -> np.ndarray:
    """Candidates where a magnet keeps its magnetisation (the largest |B| over its cell stays
    below what the magnet withstands); InfeasibleError when V's moments cannot be met there."""
    magnet_sites = np.ones(len(points), dtype=bool)
    withstood = spec.magnet.field_withstood()
    magnetic = tuple(conditions.fields.get("magnetic", ()))
    if withstood is not None and magnetic:
        reach = field_magnitude_max(magnetic, np.linalg.norm(points, axis=1) + cell)
        magnet_sites = reach <= withstood
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


def _cells(points: np.ndarray) -> tuple[np.ndarray, float]:
    """Each candidate's cell radius (half its nearest neighbour's distance) and the spacing."""
    if len(points) < 2:
        raise InputError("body: a physical design needs at least two candidate points")
    dist, _ = cKDTree(points).query(points, k=2)
    return 0.5 * dist[:, 1], float(np.min(dist[:, 1]))


def _electric_grid(
    conditions: LinearConditions, region: float
) -> tuple[tuple[float, ...], np.ndarray, np.ndarray]:
    """The electric field's coefficients, and its largest magnitude on radii out to ``region``."""
    electric = tuple(conditions.fields.get("electric", ()))
    grid = np.linspace(0.0, region, 513)
    values = field_magnitude_max(electric, grid) if electric else np.zeros_like(grid)
    return electric, grid, values


def setup_physical(
    params: Parameters,
    conditions: LinearConditions,
    candidates: CandidateSet,
    spec: PhysicalSpec,
    options: DesignOptions | None = None,
    *,
    larmor: LarmorReading | None = None,
) -> PhysicalSetup:
    """Validate the physical spec against the candidates and build the systems at rate 1.

    ``params`` and ``conditions`` are those the elements realise; ``larmor`` (its rate the
    theorem's n at rate 1) is recorded in every design built (n = 0 in ``params`` for
    ``frame``).
    """
    options = options or DesignOptions()
    _check_physical_options(options, conditions)
    points = candidates.points
    cell, spacing = _cells(points)
    a = _carrier_radius(spec, spacing)
    region = float(np.max(np.linalg.norm(points, axis=1) + cell))
    _check_field_limits(spec, conditions, region)
    systems = {s: conditions.system(s, points) for s in ("charges", "dipoles", "masses")}
    costs = {
        source: robust_costs(points, source, conditions.fields, params, options.robust_weight)
        for source in systems
        if options.objective_for(source) == "robust"
    }
    magnet_sites = _magnet_sites(spec, conditions, points, cell, systems["dipoles"])
    electric, grid, values = _electric_grid(conditions, region)
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
        electric=electric,
        e_grid=grid,
        e_grid_values=values,
        costs=costs,
        magnet_sites=magnet_sites,
        larmor=larmor,
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


# ------------------------------------------------------------------------------ charges
@dataclass
class ChargeSolution:
    sites: np.ndarray  # candidate indices of the carriers
    charges: np.ndarray  # C
    surface_fields: np.ndarray  # V/m, per carrier (in-loop samples)
    residual: float
    rounds: int
    cones: int
    objective_lp: float
    method: str


def _row_scaled(A: np.ndarray, b: np.ndarray, col_scale: float) -> tuple[np.ndarray, np.ndarray]:
    """Rows divided by their largest entry (columns in units of ``col_scale``)."""
    As = A * col_scale
    top = np.max(np.abs(As), axis=1) if As.shape[1] else np.ones(len(b))
    top = np.where(top > 0, top, 1.0)
    return As / top[:, None], b / top


def lp_charges(
    A: np.ndarray, b: np.ndarray, caps: np.ndarray, cost: np.ndarray | None = None
) -> np.ndarray | None:
    """min sum cost_j |q_j| with A q = b, |q| <= caps, by HiGHS (None: infeasible)."""
    usable = caps > 0
    cols = np.flatnonzero(usable)
    if len(cols) == 0:
        return None
    qs = float(np.max(caps[cols]))
    As, bs = _row_scaled(A[:, cols], b, qs)
    k = len(cols)
    res = linprog(
        np.ones(2 * k) if cost is None else np.tile(cost[cols], 2),
        A_eq=np.hstack([As, -As]),
        b_eq=bs,  # q = qs * u
        bounds=list(zip(np.zeros(2 * k), np.tile(caps[cols] / qs, 2), strict=True)),
        method="highs",
    )
    if res.status == 2:
        return None
    if res.status != 0 or res.x is None:
        raise SolverError(f"charges: HiGHS failed on the carriers' own-field LP ({res.message})")
    q = np.zeros(len(caps))
    q[cols] = (res.x[:k] - res.x[k:]) * qs
    return q


def _surface_check(
    setup: PhysicalSetup, positions: np.ndarray, q: np.ndarray, s: float, samples: int
) -> tuple[np.ndarray, np.ndarray]:
    """Largest surface field of each carrier over the safe field, and where it occurs.

    ``samples`` Fibonacci points per carrier, then a refinement around the largest one
    (:func:`~chargedesign.physical.limits.local_cap`), so the maximum between samples is found.

    Returns
    -------
    ratios : ndarray, shape (k,)
    worst : ndarray, shape (k, 3)
    """
    k = len(q)
    if k == 0:
        return np.zeros(0), np.zeros((0, 3))
    dirs = fibonacci_directions(samples)
    a = setup.carrier_radius

    def magnitudes(points: np.ndarray) -> np.ndarray:
        """|E| at points (k, m, 3) from every carrier plus the external bound: (k, m)."""
        flat = points.reshape(-1, 3)
        e = np.linalg.norm(coulomb_field_gemm(positions, q, flat), axis=1)
        e = e + setup.external_max(np.linalg.norm(flat, axis=1), s)
        return e.reshape(k, -1)

    # every carrier's samples in one evaluation, then a cap around each one's largest
    e = magnitudes(positions[:, None, :] + a * dirs[None, :, :])
    caps = positions[:, None, :] + a * local_caps(
        dirs[np.argmax(e, axis=1)], 1.5 * sample_spacing(samples)
    )
    e_cap = magnitudes(caps)
    best = np.argmax(e_cap, axis=1)
    rows = np.arange(k)
    ratios = np.maximum(e_cap[rows, best], e.max(axis=1)) / setup.safe_field
    return ratios, caps[rows, best]


def _socp_charges(
    setup: PhysicalSetup,
    sites: np.ndarray,
    s: float,
    cones: list[tuple[int, np.ndarray]],
    caps: np.ndarray,
) -> np.ndarray | None:
    """min sum cost_j |q_j| on ``sites`` with the charge conditions, own-field caps and
    surface cones (:class:`~chargedesign.designer.cone_program.ConeProgram`, in ``x = (u, w)``,
    ``q = qs u``, ``w >= |u|`` carrying the cost)."""
    A, b = setup.systems["charges"]
    qs = float(np.max(caps[sites]))
    As, bs = _row_scaled(A[:, sites], s * b, qs)
    k = len(sites)
    limit = setup.safe_field * (1 - DESIGN_MARGIN)
    eye = sparse.identity(k, format="csr")
    zero = sparse.csr_matrix((k, k))
    cap = caps[sites] / qs
    G_lin = sparse.vstack(
        [
            sparse.hstack([eye, -eye]),  # u - w <= 0
            sparse.hstack([-eye, -eye]),  # -u - w <= 0
            sparse.hstack([eye, zero]),  # u <= cap
            sparse.hstack([-eye, zero]),  # -u <= cap
        ],
        format="csr",
    )
    h_lin = np.concatenate([np.zeros(2 * k), cap, cap])
    G_soc, h_soc = np.zeros((0, 4, 2 * k)), np.zeros((0, 4))
    if cones:
        points = np.array([point for _, point in cones])
        G = coulomb_kernel(setup.points[sites], points, COULOMB * qs / limit)  # (m, 3, k)
        G_soc = np.zeros((len(points), 4, 2 * k))
        G_soc[:, 1:, :k] = -G  # the cone's (room, G u)
        h_soc = np.zeros((len(points), 4))
        h_soc[:, 0] = 1.0 - setup.external_max(np.linalg.norm(points, axis=1), s) / limit
    cost = np.concatenate([np.zeros(k), setup.cost("charges")[sites]])
    A_eq = np.hstack([As, np.zeros_like(As)])
    program = ConeProgram(
        cost, A_eq, bs, G_lin, h_lin, G_soc, h_soc, "charges: the surface-field cones"
    )
    x = program.solve()
    return None if x is None else x[:k] * qs


def _polish_equal(A: np.ndarray, b: np.ndarray, w: np.ndarray, cols: np.ndarray) -> np.ndarray:
    """Least-norm correction of ``w`` on ``cols`` so that ``A w = b`` to rounding."""
    out = w.copy()
    if len(cols) == 0:
        return out
    top = np.max(np.abs(A[:, cols]), axis=1)
    top = np.where(top > 0, top, 1.0)
    As = A[:, cols] / top[:, None]
    for _ in range(3):
        out[cols] += least_norm(As, (b - A @ out) / top)
    return out


def _excess(ratio: float) -> str:
    return f"needs {fmt(ratio)}x" if ratio >= 1.01 else "reaches"


def charge_support(q: np.ndarray) -> np.ndarray:
    top = float(np.max(np.abs(q))) if len(q) else 0.0
    return np.flatnonzero(np.abs(q) > 1e-9 * top) if top > 0 else np.zeros(0, dtype=int)


def _charges_method(rounds: int, n_cones: int) -> str:
    """How the charges were found, for design.json's solver record."""
    return (
        "HiGHS LP with the carriers' own-field bounds"
        + (f", tightened in {rounds - 1} rounds" if rounds > 1 and not n_cones else "")
        + (f", then Clarabel with {n_cones} surface cones" if n_cones else "")
    )


def _cone_round(
    setup: PhysicalSetup,
    working: np.ndarray,
    s: float,
    cones: list[tuple[int, np.ndarray]],
    caps: np.ndarray,
) -> tuple[np.ndarray | None, np.ndarray]:
    """The surface cones solved on the working set, else on every usable candidate: the
    charges on the working set returned (None: infeasible there too) and that set.

    The working set may lack carriers a solution needs: on every usable candidate the cones
    (a subset of the surface limits) relax the true problem, so its infeasibility proves the
    rate infeasible, and every faster one too (the feasible charges scale down with the
    rate): the frontier then sees a monotone answer.
    """
    solved = _socp_charges(setup, working, s, cones, caps)
    usable = np.flatnonzero(caps > 0)
    if solved is None and len(working) < len(usable):
        working = usable
        solved = _socp_charges(setup, working, s, cones, caps)
    return solved, working


def _meet_surface_limits(
    setup: PhysicalSetup, s: float, caps: np.ndarray, q_lp: np.ndarray
) -> tuple[np.ndarray, str, int, int]:
    """Charges on all candidates that keep every carrier's surface field within its limit.

    Constraint generation, cheapest first: (1) the LP's answer when no carrier is over;
    (2) LP rounds where each carrier over its limit gets its own-field bound divided by its
    excess (neighbours' fields then push the charge onto more carriers); (3) the second-order
    cones at the worst surface points of the carriers near their limit, on the working set of
    every carrier the LPs used (Clarabel), until the surface check passes. Raises
    PhysicalInfeasible when the LPs run out of room and the cones cannot be met.
    """
    A, b = setup.systems["charges"]
    working = charge_support(q_lp)
    q = q_lp
    lp_caps = caps.copy()
    cones: list[tuple[int, np.ndarray]] = []
    worst_ratio, worst_site = 0.0, -1
    lp_alive = True
    for rounds in range(1, MAX_ROUNDS + 1):
        sites = charge_support(q)
        ratios, worst = _surface_check(
            setup, setup.points[sites], q[sites], s, LOOP_SURFACE_SAMPLES
        )
        over = np.flatnonzero(ratios > 1 - DESIGN_MARGIN / 2)
        if len(over) == 0:
            return q, _charges_method(rounds, len(cones)), rounds, len(cones)
        k = int(over[np.argmax(ratios[over])])
        worst_ratio, worst_site = float(ratios[k]), int(sites[k])
        if lp_alive and rounds <= LP_ROUNDS:
            near = np.flatnonzero(ratios > CONE_THRESHOLD)
            lp_caps[sites[near]] *= np.minimum(1.0, (1 - DESIGN_MARGIN) / ratios[near])
            more = lp_charges(A, s * b, lp_caps, setup.cost("charges"))
            if more is not None:
                working = np.union1d(working, charge_support(more))
                q = more
                continue
            lp_alive = False
        near = np.flatnonzero(ratios > CONE_THRESHOLD)
        cones.extend((int(sites[i]), worst[i]) for i in near)
        working = np.union1d(working, sites)
        solved, working = _cone_round(setup, working, s, cones, caps)
        if solved is None:
            proved = True  # the cones on every usable candidate: a relaxation
            break
        q = np.zeros(len(setup.points))
        q[working] = solved
    else:
        proved = False  # the rounds ran out
    raise PhysicalInfeasible(_surface_binding(setup, worst_ratio, worst_site, proved))


def _surface_binding(
    setup: PhysicalSetup, worst_ratio: float, worst_site: int, proved: bool
) -> Binding:
    """The carriers' fields add up beyond the safe surface field at the worst carrier."""
    return Binding(
        "charges",
        f"{_excess(worst_ratio)} the safe surface field of {setup.spec.medium.name} "
        f"({fmt(setup.safe_field)} V/m): the carriers' fields add up",
        f"charge at {np.array2string(setup.points[worst_site], precision=4)} m",
        worst_ratio,
        proved=proved,
    )


def _check_field_rate(setup: PhysicalSetup, s: float) -> None:
    """Refuse a rate whose electric field exceeds ``fields.electric.max``."""
    if s > setup.field_bound(s) * (1 + 1e-12):
        raise PhysicalInfeasible(
            Binding(
                "fields",
                f"the electric field this rate needs exceeds fields.electric.max "
                f"({fmt(setup.spec.field_limits.get('electric'), PLAIN)} V/m)",
                "fields.electric",
                s / setup.field_bound(s),
                proved=True,
            )
        )


def _lp_charges(
    setup: PhysicalSetup, A: np.ndarray, rhs: np.ndarray, caps: np.ndarray
) -> np.ndarray:
    """The linear program's charges within every carrier's own-field cap (refused: none)."""
    q_lp = lp_charges(A, rhs, caps, setup.cost("charges"))
    if q_lp is None:
        raise PhysicalInfeasible(
            Binding(
                "charges",
                f"no charges on carriers of radius {fmt(setup.carrier_radius)} m meet the "
                f"conditions with every carrier's own surface field within the safe field of "
                f"{setup.spec.medium.name} ({fmt(setup.safe_field)} V/m)",
                "the carriers",
                proved=True,  # the own-field bounds are necessary
            )
        )
    return q_lp


def _polished_charges(
    setup: PhysicalSetup, s: float, caps: np.ndarray, q_full: np.ndarray, residue: float
) -> tuple[np.ndarray, np.ndarray] | None:
    """The charges without those below ``residue`` times the largest, polished to meet
    ``A q = s b`` to rounding on the rest, and their surface ratios (None: the polished
    charges miss the conditions, unless ``residue`` is the last resort, or come within
    DESIGN_MARGIN / 4 of a limit)."""
    A, b = setup.systems["charges"]
    top = float(np.max(np.abs(q_full)))
    kept = np.flatnonzero(np.abs(q_full) > residue * top)
    full = np.zeros(len(setup.points))
    full[kept] = q_full[kept]
    full = _polish_equal(A, s * b, full, kept)
    sites = np.flatnonzero(full)
    q = full[sites]
    ratios, _ = _surface_check(setup, setup.points[sites], q, s, LOOP_SURFACE_SAMPLES)
    if (
        (residue != CHARGE_RESIDUES[-1] and relative_residual(A, full, s * b) > POLISHED_RESIDUAL)
        or np.any(ratios > 1 - DESIGN_MARGIN / 4)
        or np.any(np.abs(q) > np.maximum(caps[sites], 0) * (1 + 1e-9))
    ):
        return None
    return full, ratios


def design_charges(setup: PhysicalSetup, s: float) -> ChargeSolution:
    """The carriers and their charges at rate ``s`` (see the module doc).

    Raises
    ------
    PhysicalInfeasible
        Naming the binding limit.
    """
    A, b = setup.systems["charges"]
    _check_field_rate(setup, s)
    if not np.any(b):
        return ChargeSolution(
            np.zeros(0, dtype=int), np.zeros(0), np.zeros(0), 0.0, 0, 0, 0.0, "none"
        )
    caps = setup.charge_caps(s)
    q_lp = _lp_charges(setup, A, s * b, caps)
    objective_lp = float(np.sum(np.abs(q_lp)))
    q_full, method, rounds, n_cones = _meet_surface_limits(setup, s, caps, q_lp)
    sites = charge_support(q_full)
    if not len(sites):
        raise SolverError(f"charges: the solver returned no charges at rate s = {fmt(s)}")
    for residue in CHARGE_RESIDUES:
        polished = _polished_charges(setup, s, caps, q_full, residue)
        if polished is not None:
            break
    else:
        raise SolverError("charges: polishing pushed a carrier to its surface-field limit")
    full, ratios = polished
    sites = np.flatnonzero(full)
    q = full[sites]
    return ChargeSolution(
        sites=sites,
        charges=q,
        surface_fields=ratios * setup.safe_field,
        residual=relative_residual(A, full, s * b),
        rounds=rounds,
        cones=n_cones,
        objective_lp=objective_lp,
        method=method,
    )


# ------------------------------------------------------- the charges' limit on the rate
#: the rounds of :func:`charges_rate_limit` stop when the largest field the surface check
#: finds exceeds the working points' bound by less than this fraction
MINMAX_GAP = 1e-3
#: carriers whose largest surface field passes this fraction of the working points' bound
#: get a cone at their worst point (at the minimum many carriers share the largest field)
MINMAX_CONES = 0.99
#: cones whose field at a round's charges stays below this fraction of its bound are dropped
#: (the check adds a carrier's worst point again when it comes back near the bound)
MINMAX_KEEP = 0.9
#: at most this many cone rounds in :func:`charges_rate_limit`
MINMAX_ROUNDS = 40


@dataclass
class ChargesLimit:
    """The largest rate the charges allow, from one convex problem (see
    :func:`charges_rate_limit`).

    Attributes
    ----------
    rate : float
        Largest time rate at which charges can meet ``A q = s b`` with every carrier's surface
        field within ``E_safe (1 - DESIGN_MARGIN)`` at the check's points (inf: no charge
        conditions and no electric-field limit).
    gap : float
        Charges exist at ``rate / (1 + gap)`` (``q = rate / (1 + gap) * u``), relative.
    t : float
        ``min_u max_x |E(u)|(x) + E_ext(|x|)`` at rate 1, V/m: the largest surface field per
        unit rate of the best charges (inf: none meet the conditions).
    sites : ndarray, shape (k,)
        Candidate indices of the carriers of those charges.
    charges : ndarray, shape (k,)
        Their charges at rate 1 (``u``), C.
    worst_site : int
        The candidate whose surface carries the largest field (-1: none).
    rounds, cones : int
        Constraint-generation rounds and surface cones used.
    stage : str
        What sets ``rate``: ``charges`` (the surface fields), ``fields`` (the apparatus'
        ``fields.electric.max``) or ``none``.
    """

    rate: float
    gap: float
    t: float
    sites: np.ndarray
    charges: np.ndarray
    worst_site: int
    rounds: int
    cones: int
    stage: str


def _minmax_charges(
    setup: PhysicalSetup, cones: list[np.ndarray]
) -> tuple[float, np.ndarray, np.ndarray] | None:
    """``min t`` over charges ``u`` (rate 1) on every candidate with ``A u = b``, each
    carrier's own surface field plus the external one within ``t``, and the same at the cone
    points (:class:`~chargedesign.designer.cone_program.ConeProgram` in ``x = (u, t)``, u in
    units of the charge whose own surface field is the limit, t in units of the limit).
    Returns ``t`` in V/m, ``u`` in C, and each cone point's field over ``t``; None: no charges
    meet the conditions.
    """
    A, b = setup.systems["charges"]
    limit = setup.safe_field * (1 - DESIGN_MARGIN)
    a = setup.carrier_radius
    qs = 4 * math.pi * EPSILON_0 * a**2 * limit  # the charge whose own surface field is limit
    As, bs = _row_scaled(A, b, qs)
    k = len(setup.points)
    own_ext = setup.external_max(np.linalg.norm(setup.points, axis=1) + a, 1.0) / limit
    eye = sparse.identity(k, format="csr")
    minus_t = sparse.csr_matrix(-np.ones((k, 1)))
    # u_j + own_ext_j <= t and -u_j + own_ext_j <= t
    G_lin = sparse.vstack([sparse.hstack([eye, minus_t]), sparse.hstack([-eye, minus_t])])
    h_lin = np.concatenate([-own_ext, -own_ext])
    G_soc, h_soc = np.zeros((0, 4, k + 1)), np.zeros((0, 4))
    if cones:
        points = np.array(cones)
        G = coulomb_kernel(setup.points, points, COULOMB * qs / limit)  # (m, 3, k)
        ext = setup.external_max(np.linalg.norm(points, axis=1), 1.0) / limit
        G_soc = np.zeros((len(points), 4, k + 1))
        G_soc[:, 0, k] = -1.0  # the cone's (t - ext, G u)
        G_soc[:, 1:, :k] = -G
        h_soc = np.zeros((len(points), 4))
        h_soc[:, 0] = -ext
    cost = np.zeros(k + 1)
    cost[k] = 1.0
    program = ConeProgram(
        cost,
        np.hstack([As, np.zeros((len(bs), 1))]),
        bs,
        G_lin,
        h_lin,
        G_soc,
        h_soc,
        "charges: the charges' minmax",
    )
    x = program.solve()
    if x is None:
        return None
    t = float(x[k])
    used = np.zeros(0)
    if cones:
        used = (np.linalg.norm(G @ x[:k], axis=1) + ext) / t
    return t * limit, x[:k] * qs, used


def charges_rate_limit(setup: PhysicalSetup, gap: float = MINMAX_GAP) -> ChargesLimit:
    """The largest rate the charges' stage allows, computed directly.

    At rate ``s`` the charges meet ``A q = s b`` (:func:`design_charges`) with every carrier's
    surface field ``|E(q)(x)| + s E_ext(|x|) <= E_lim = E_safe (1 - DESIGN_MARGIN)`` and their
    own-field caps ``|q_j| / (4 pi eps0 a^2) + s E_ext <= E_lim``, all homogeneous of degree 1
    in ``(q, s)``. With ``q = s u`` the largest such rate is ``E_lim / t*`` with the one convex
    problem (an SOCP) ``t* = min_u max_x (|E(u)(x)| + E_ext(|x|))`` subject to ``A u = b``.
    It is solved by the design's constraint generation: cones at the worst surface point of
    every used carrier near the maximum (the design's surface check,
    :data:`LOOP_SURFACE_SAMPLES` samples per carrier and a refinement), re-solved until the
    check's maximum exceeds the working points' ``t`` by less than :data:`MINMAX_GAP`. The
    working points are a subset of the check's, so each round's ``t`` is a lower bound and
    ``E_lim / t`` bounds the rate from above; the last charges reach ``E_lim`` at
    ``E_lim / t / (1 + gap)``. The apparatus' ``fields.electric.max`` caps the rate too
    (:meth:`PhysicalSetup.field_bound`).

    The cones hold at their points whether or not a body puts a carrier there (a body that
    leaves a candidate empty is not bound on its surface): the bound is the one the design's
    own proof uses (the cones on every usable carrier, :func:`_meet_surface_limits`). Tested
    against the frontier's bisection (the bound lies in its bracket where the charges bind)
    and the charges' stage (refused at 1.001 times the bound).

    Returns
    -------
    ChargesLimit

    Raises
    ------
    SolverError
        Clarabel fails, or the rounds run out before the gap closes.
    """
    _, b = setup.systems["charges"]
    bound = setup.field_bound(1.0)
    empty = np.zeros(0, dtype=int)
    if not np.any(b):
        stage = "fields" if math.isfinite(bound) else "none"
        return ChargesLimit(bound, 0.0, 0.0, empty, np.zeros(0), -1, 0, 0, stage)
    limit = setup.safe_field * (1 - DESIGN_MARGIN)
    cones: list[np.ndarray] = []
    for rounds in range(1, MINMAX_ROUNDS + 1):
        solved = _minmax_charges(setup, cones)
        if solved is None:
            return ChargesLimit(0.0, 0.0, math.inf, empty, np.zeros(0), -1, rounds, 0, "charges")
        t, u, used = solved
        sites = charge_support(u)
        s = limit / t
        # the check at rate s on the charges s u: ratios to E_safe, so 1 - DESIGN_MARGIN is t
        ratios, worst = _surface_check(
            setup, setup.points[sites], s * u[sites], s, LOOP_SURFACE_SAMPLES
        )
        top = float(np.max(ratios)) / (1 - DESIGN_MARGIN)
        if top <= 1 + gap:
            rate = s
            stage = "charges"
            if bound < rate:
                rate, stage = bound, "fields"
            return ChargesLimit(
                rate=rate,
                gap=max(top - 1.0, 0.0),
                t=t,
                sites=sites,
                charges=u[sites],
                worst_site=int(sites[np.argmax(ratios)]),
                rounds=rounds,
                cones=len(cones),
                stage=stage,
            )
        near = np.flatnonzero(ratios > MINMAX_CONES * (1 - DESIGN_MARGIN))
        cones = [point for point, value in zip(cones, used, strict=True) if value >= MINMAX_KEEP]
        cones.extend(worst[i] for i in near)
    raise SolverError(
        f"charges: the charges' minmax did not close its gap to {fmt(gap, PLAIN)} in"
        f" {MINMAX_ROUNDS} rounds"
    )


@dataclass
class ChargeProgram:
    """The charges' stage as one cvxpy problem on every candidate (no constraint generation).

    ``problem`` minimises ``sum |q|`` subject to the charge conditions and a second-order cone
    at every one of ``samples`` points on every candidate carrier's surface. ``q`` is in units
    of ``charge_scale`` (C). Dense: meant for small candidate sets, for users who add their
    own constraints, and as the reference the constraint generation is tested against.
    """

    problem: Any
    q: Any
    charge_scale: float


def charge_program(setup: PhysicalSetup, s: float, samples: int = 26) -> ChargeProgram:
    """Build (not solve) the full charges program at rate ``s`` (see :class:`ChargeProgram`)."""
    import cvxpy as cp

    A, b = setup.systems["charges"]
    caps = setup.charge_caps(s)
    qs = float(np.max(caps))
    As, bs = _row_scaled(A, s * b, qs)
    q = cp.Variable(len(setup.points))
    limit = setup.safe_field * (1 - DESIGN_MARGIN)
    dirs = fibonacci_directions(samples)
    points = (setup.points[:, None, :] + setup.carrier_radius * dirs[None, :, :]).reshape(-1, 3)
    G = coulomb_kernel(setup.points, points, COULOMB * qs / limit)
    room = 1.0 - setup.external_max(np.linalg.norm(points, axis=1), s) / limit
    fields = cp.reshape(G.reshape(-1, len(setup.points)) @ q, (len(points), 3), order="C")
    cost = setup.cost("charges")
    problem = cp.Problem(
        cp.Minimize(cp.norm(cp.multiply(cost, q), 1)),
        [As @ q == bs, cp.norm(fields, 2, axis=1) <= room],
    )
    return ChargeProgram(problem, q, qs)


# ------------------------------------------------------------------- magnets and masses
@dataclass
class MassSolution:
    sites: np.ndarray  # candidate indices of the sites (no carrier)
    moments: np.ndarray  # (k, 3) A m^2
    site_masses: np.ndarray  # (k,) kg
    residual_dipoles: float
    residual_masses: float
    method: str
    #: with several ballast materials: each entry's material (index into ``spec.ballasts``;
    #: -1 for a magnet), and the induced-magnetisation rows' relative residual
    materials: np.ndarray | None = None
    residual_induced: float | None = None


@dataclass
class MassProgram:
    """The second stage as a cvxpy problem: variables and what they mean."""

    problem: Any
    sigma: Any  # (k, 3) in units of sigma_scale
    mass: Any  # (k,) in units of mass_scale
    sites: np.ndarray
    sigma_scale: float
    mass_scale: float
    rhs_masses: np.ndarray


def _unknown_scale(A: np.ndarray, b: np.ndarray) -> float:
    """The size of the unknowns ``A w = b`` asks for (0 when b = 0): max_i |b_i| / max_j |A_ij|."""
    if A.size == 0 or not np.any(b):
        return 0.0
    top = np.max(np.abs(A), axis=1)
    ok = top > 0
    return float(np.max(np.abs(b[ok]) / top[ok])) if np.any(ok) else 0.0


def mass_program(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassProgram:
    """Build (not solve) the magnets-and-masses program at rate ``s`` for these carriers.

    Returns a :class:`MassProgram`; ``program.problem`` is a ``cvxpy.Problem`` a user may add
    constraints to (``program.sigma`` and ``program.mass`` are the variables, scaled).
    """
    import cvxpy as cp

    spec = setup.spec
    n = len(setup.points)
    free = np.ones(n, dtype=bool)
    free[carrier_sites] = False
    sites = np.flatnonzero(free)
    Ad, bd = setup.systems["dipoles"]
    Am, bm = setup.systems["masses"]
    bd = s * s * bd
    bm = bm - Am[:, carrier_sites] @ np.full(len(carrier_sites), setup.carrier_mass)
    M, rho_m, rho_b = spec.magnet.magnetisation or 1.0, spec.magnet.density, spec.ballast.density
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[sites] ** 3 * (1 - DESIGN_MARGIN)
    mass_scale = _unknown_scale(Am[:, sites], bm) or float(np.max(v_cap)) * rho_b
    cols = (3 * sites[:, None] + np.arange(3)).reshape(-1)
    sigma_scale = _unknown_scale(Ad[:, cols], bd) or float(np.max(v_cap)) * M
    k = len(sites)
    sigma = cp.Variable((k, 3))
    mass = cp.Variable(k, nonneg=True)
    constraints = []
    if len(bd):
        Ads, bds = _row_scaled(Ad[:, cols], bd, sigma_scale)
        constraints.append(Ads @ cp.reshape(sigma, (3 * k,), order="C") == bds)
    if len(bm):
        Ams, bms = _row_scaled(Am[:, sites], bm, mass_scale)
        constraints.append(Ams @ mass == bms)
    blocked = np.flatnonzero(~setup.magnet_sites[sites])
    if len(blocked):  # the field there would demagnetise a magnet
        constraints.append(sigma[blocked, :] == 0)
    norms = cp.norm(sigma, 2, axis=1)
    constraints.append(mass >= (1 + 1e-6) * rho_m * sigma_scale / M / mass_scale * norms)
    constraints.append(
        cp.multiply(sigma_scale / M / v_cap, norms) + cp.multiply(mass_scale / rho_b / v_cap, mass)
        <= 1.0
    )
    # both terms in their natural units: the l1 norm of the moments keeps the magnets few
    # (each weighted by its site's cost under the robust objective)
    objective = cp.Minimize(
        setup.cost("masses")[sites] @ mass + setup.cost("dipoles")[sites] @ norms
    )
    return MassProgram(
        problem=cp.Problem(objective, constraints),
        sigma=sigma,
        mass=mass,
        sites=sites,
        sigma_scale=sigma_scale,
        mass_scale=mass_scale,
        rhs_masses=bm,
    )


def _solved_mass_program(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassProgram:
    """The magnets-and-masses program around the carriers, solved (PhysicalInfeasible
    naming the binding limit when it has no solution)."""
    import cvxpy as cp

    if len(np.unique(carrier_sites)) >= len(setup.points):
        # (the minmax's charges on every candidate, say): nothing left to solve for
        raise PhysicalInfeasible(
            Binding(
                "masses",
                f"the {len(setup.points)} carriers fill every candidate site: no cell is left "
                "for the magnets and the ballast",
                "ballast cells",
            )
        )
    program = mass_program(setup, s, carrier_sites)
    _, bd = setup.systems["dipoles"]
    if np.any(bd != 0) and not np.any(setup.magnet_sites[program.sites]):
        # every free cell would demagnetise a magnet, and V needs magnets: no solver asked
        raise PhysicalInfeasible(_mass_binding(setup, s, carrier_sites))
    try:
        program.problem.solve(solver=cp.CLARABEL)
    except cp.SolverError as exc:
        raise SolverError(f"magnets and masses: Clarabel failed ({exc})") from exc
    if program.problem.status in ("infeasible", "infeasible_inaccurate"):
        raise PhysicalInfeasible(_mass_binding(setup, s, carrier_sites))
    if program.sigma.value is None or program.mass.value is None:
        raise SolverError(f"magnets and masses: Clarabel returned {program.problem.status}")
    return program


def _polish_moments(
    setup: PhysicalSetup, s: float, sites: np.ndarray, sigma: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """The solver's moments on ``sites`` polished on their support: all moments (3 n,) and
    which sites keep a magnet."""
    Ad, bd = setup.systems["dipoles"]
    n = len(setup.points)
    # polish each system on its support
    sig_norm = np.linalg.norm(sigma, axis=1)
    top_sigma = max(float(np.max(sig_norm, initial=0.0)), 1e-300)
    sig_keep = sig_norm > 1e-6 * top_sigma
    full_sigma = np.zeros(3 * n)
    cols = (3 * sites[sig_keep][:, None] + np.arange(3)).reshape(-1)
    full_sigma[cols] = sigma[sig_keep].reshape(-1)
    big = sites[sig_norm > 1e-3 * top_sigma]
    if len(bd):
        # corrections on the strong magnets only (relative changes ~ the solver's residual)
        big_cols = (3 * big[:, None] + np.arange(3)).reshape(-1)
        full_sigma = _polish_equal(Ad, s * s * bd, full_sigma, big_cols)
    return full_sigma, sig_keep


def _magnet_mass(setup: PhysicalSetup, moments: np.ndarray, factor: float = 1.0) -> np.ndarray:
    """``factor`` times the mass of each moment's magnet (density x |moment| / magnetisation)."""
    return (
        factor
        * setup.spec.magnet.density
        * np.linalg.norm(moments, axis=1)
        / (setup.spec.magnet.magnetisation or 1.0)
    )


def design_masses(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> MassSolution:
    """Magnets and ballast at rate ``s`` around the given carriers (see the module doc)."""
    program = _solved_mass_program(setup, s, carrier_sites)
    sites = program.sites
    sigma = np.asarray(program.sigma.value) * program.sigma_scale
    mass = np.maximum(np.asarray(program.mass.value), 0.0) * program.mass_scale
    Ad, bd = setup.systems["dipoles"]
    Am, _ = setup.systems["masses"]
    n = len(setup.points)
    full_sigma, sig_keep = _polish_moments(setup, s, sites, sigma)
    # a magnet weighs at least its volume: lift the solver's slack on that bound (relative
    # changes at the solver's tolerance; the heavy sites absorb them in the polish below)
    sig_polished = full_sigma.reshape(n, 3)[sites]
    magnet_floor = _magnet_mass(setup, sig_polished, 1 + 1e-6)
    mass = np.maximum(mass, magnet_floor)
    top_mass = max(float(np.max(mass, initial=0.0)), 1e-300)
    mass_keep = (mass > 1e-9 * top_mass) | sig_keep
    full_rhs = program.rhs_masses
    full_mass = np.zeros(n)
    full_mass[sites[mass_keep]] = mass[mass_keep]
    # the correction goes to the heavy sites only, so that light ones (and magnets) keep
    # their sign and their bound: relative changes there are ~ the solver's residual. A
    # robust design spreads its masses, so the heaviest few may not span the mass rows:
    # lighter sites then join, as long as every mass stays nonnegative.
    full_mass = _polish_masses(Am, full_rhs, full_mass, sites, mass, top_mass)
    sig = full_sigma.reshape(n, 3)[sites]
    m = full_mass[sites]
    magnet_mass = _magnet_mass(setup, sig)
    if np.any(m < magnet_mass * (1 - 1e-9)):
        raise SolverError("magnets: polishing left a magnet lighter than its volume")
    used = (np.linalg.norm(sig, axis=1) > 0) | (m > 0)
    residual_dipoles = relative_residual(Ad, full_sigma, s * s * bd) if len(bd) else 0.0
    if setup.spec.designs_induced:
        return induced_ballast(setup, carrier_sites, full_sigma.reshape(n, 3), residual_dipoles)
    return MassSolution(
        sites=sites[used],
        moments=sig[used],
        site_masses=m[used],
        residual_dipoles=residual_dipoles,
        residual_masses=relative_residual(Am, full_mass, full_rhs) if len(full_rhs) else 0.0,
        method="Clarabel (magnet-mass and cell-volume cones), least-norm polish on the supports",
    )


def _susceptibilities(spec: PhysicalSpec) -> dict[tuple[str, str], float]:
    """Each part material's susceptibility by (name, role); one line naming the table whose
    material has none."""
    chi = {}
    for part in (spec.carrier, spec.magnet, *spec.ballasts):
        if part.susceptibility is None:
            table = "carriers" if part.role == "carrier" else f"{part.role}s"
            raise InputError(
                f"{table}.susceptibility: cancelling the induced magnetisation needs the "
                f"{part.role} material's susceptibility ({part.name} has none)"
            )
        chi[part.name, part.role] = part.susceptibility
    return chi


def _one_material_per_cell(
    cost: np.ndarray, room: np.ndarray, As: np.ndarray, bs: np.ndarray, mats: Any
) -> np.ndarray:
    """The ballast LP (masses per material and cell, scaled; shape (materials, cells)) with
    one material per cell: cells given two are fixed to the one filling more of the cell
    and the LP solved again."""
    J, k = len(mats), room.shape[0]
    allowed = np.ones(J * k, dtype=bool)
    for _ in range(6):
        res = linprog(
            cost,
            A_ub=room,
            b_ub=np.ones(k),
            A_eq=As,
            b_eq=bs,
            bounds=[(0.0, None if ok else 0.0) for ok in allowed],
            method="highs",
        )
        if res.status == 2:
            raise PhysicalInfeasible(
                Binding(
                    "masses",
                    "no ballast of " + ", ".join(m.name for m in mats) + " in the free cells "
                    "makes A = B = 2C, the centre of mass at O and the induced magnetisation "
                    "independent of the orientation",
                    "ballast.material",
                )
            )
        if res.status != 0 or res.x is None:
            raise SolverError(
                f"ballast: HiGHS failed on the induced-magnetisation LP ({res.message})"
            )
        x = res.x.reshape(J, k)
        top = max(float(np.max(x)), 1e-300)
        used = x > 1e-12 * top
        split = np.flatnonzero(used.sum(axis=0) > 1)
        if not len(split):
            return x
        keep = np.argmax(x[:, split] / np.array([m.density for m in mats])[:, None], axis=0)
        mask = allowed.reshape(J, k)
        mask[:, split] = False
        mask[keep, split] = True
    raise SolverError("ballast: cells kept two materials after 6 rounds of the LP")


def induced_ballast(
    setup: PhysicalSetup, carrier_sites: np.ndarray, sigma: np.ndarray, residual_dipoles: float
) -> MassSolution:
    """Ballast of several materials that cancels the parts' induced magnetisation.

    The carriers and the magnets ``sigma`` (n, 3), A m^2, are kept; the ballast is designed
    anew, one material per free cell: its masses (per cell and material, kg) meet the mass
    rows (inertia, centre of mass) and the induced-magnetisation rows (:func:`induced_rows`,
    linear in the masses through ``chi v = (chi / rho) m``), within the cells' room. A linear
    program (HiGHS, least total mass); cells given two materials are fixed to the larger and
    the program solved again; then a least-norm polish on the support to rounding.
    """
    spec = setup.spec
    mats = spec.ballasts
    chi = _susceptibilities(spec)
    n = len(setup.points)
    legendre = tuple(setup.conditions.fields.get("magnetic", ()))
    Am, bm = setup.systems["masses"]
    M = spec.magnet.magnetisation or 1.0
    norms = np.linalg.norm(sigma, axis=1)
    magnet_sites = np.flatnonzero(norms > 0)
    volumes = norms[magnet_sites] / M
    magnet_mass = spec.magnet.density * volumes
    carrier_volume = setup.carrier_mass / spec.carrier.density
    rows_all = induced_rows(legendre, setup.points)
    # what the carriers and magnets already contribute (constants of both row sets)
    fixed_mass = np.zeros(n)
    fixed_mass[carrier_sites] = setup.carrier_mass
    fixed_mass[magnet_sites] = magnet_mass
    chi_v = np.zeros(n)
    chi_v[carrier_sites] = chi[spec.carrier.name, "carrier"] * carrier_volume
    chi_v[magnet_sites] = chi[spec.magnet.name, "magnet"] * volumes
    free = np.setdiff1d(np.arange(n), np.concatenate([carrier_sites, magnet_sites]))
    k, J = len(free), len(mats)
    per_kg = np.array([chi[m.name, "ballast"] / m.density for m in mats])  # chi v per kg
    A = np.vstack(
        [
            np.hstack([Am[:, free]] * J),
            np.hstack([rows_all[:, free] * c for c in per_kg]),
        ]
    )
    b = np.concatenate([bm - Am @ fixed_mass, -rows_all @ chi_v])
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[free] ** 3 * (1 - DESIGN_MARGIN)
    scale = _unknown_scale(A, b) or float(np.max(v_cap)) * mats[0].density
    As, bs = _row_scaled(A, b, scale)
    # one material per cell: sum_j m_j / (rho_j v_cap) <= 1
    room = np.hstack([np.diag(scale / (m.density * v_cap)) for m in mats])
    cost = np.tile(setup.cost("masses")[free], J)
    x = _one_material_per_cell(cost, room, As, bs, mats)
    flat = x.reshape(-1) * scale
    support = np.flatnonzero(flat > 1e-12 * float(np.max(flat)))
    # the solver's crumbs off the support are dropped before the polish, so that the parts
    # written are exactly the ones the rows were polished with
    flat = np.where(np.isin(np.arange(len(flat)), support), flat, 0.0)
    polished = _polish_equal(A, b, flat, support)
    if np.any(polished < 0):
        raise SolverError("ballast: polishing made a ballast mass negative")
    per = polished.reshape(J, k)
    entries = [(j, i) for j in range(J) for i in range(k) if per[j, i] > 0]
    nm = len(magnet_sites)
    material = np.concatenate([np.full(nm, -1), [j for j, _ in entries]]).astype(int)
    site_list = np.concatenate([magnet_sites, [free[i] for _, i in entries]]).astype(int)
    moments = np.vstack([sigma[magnet_sites], np.zeros((len(entries), 3))])
    masses = np.concatenate([magnet_mass, [per[j, i] for j, i in entries]])
    full = fixed_mass.copy()
    full[free] += per.sum(axis=0)
    n_mass = len(bm)
    return MassSolution(
        sites=site_list,
        moments=moments,
        site_masses=masses,
        residual_dipoles=residual_dipoles,
        residual_masses=relative_residual(Am, full, bm) if n_mass else 0.0,
        method="Clarabel for the magnets; HiGHS for the ballast of "
        + ", ".join(m.name for m in mats)
        + " (induced magnetisation cancelled), least-norm polish on the supports",
        materials=material,
        residual_induced=relative_residual(A[n_mass:], polished, b[n_mass:])
        if len(b) > n_mass
        else 0.0,
    )


def _polish_masses(
    Am: np.ndarray,
    rhs: np.ndarray,
    full_mass: np.ndarray,
    sites: np.ndarray,
    mass: np.ndarray,
    top_mass: float,
) -> np.ndarray:
    """Masses meeting ``Am m = rhs`` to rounding, corrected on the heaviest sites that do it.

    Heavy sets from the heaviest (above 1e-3 of the largest mass) to every site are tried;
    the best nonnegative result wins (the first at rounding level ends the search).
    """
    best: tuple[float, np.ndarray] | None = None
    for level in (1e-3, 1e-6, 1e-9, 0.0):
        polished = _polish_equal(Am, rhs, full_mass, sites[mass > level * top_mass])
        if np.any(polished < 0):
            continue
        residual = relative_residual(Am, polished, rhs) if len(rhs) else 0.0
        if best is None or residual < best[0]:
            best = (residual, polished)
        if residual < 1e-15:
            break
    if best is None:
        raise SolverError("masses: polishing made a site mass negative")
    return best[1]


def _mass_binding(setup: PhysicalSetup, s: float, carrier_sites: np.ndarray) -> Binding:
    """Why the second stage is infeasible: the carriers' mass, the ballast's room, or the
    magnets' volume (each tried without the later ones)."""
    import cvxpy as cp

    Am, bm = setup.systems["masses"]
    free = np.setdiff1d(np.arange(len(setup.points)), carrier_sites)
    rhs = bm - Am[:, carrier_sites] @ np.full(len(carrier_sites), setup.carrier_mass)
    scale = _unknown_scale(Am[:, free], rhs) or 1.0
    Ams, bms = _row_scaled(Am[:, free], rhs, scale)
    v_cap = 4.0 / 3.0 * math.pi * setup.cell_radius[free] ** 3 * (1 - DESIGN_MARGIN)

    def feasible(room: bool) -> bool:
        w = cp.Variable(len(free), nonneg=True)
        cons = [Ams @ w == bms]
        if room:
            cons.append(w * scale / setup.spec.ballast.density <= v_cap)
        prob = cp.Problem(cp.Minimize(0), cons)
        prob.solve(solver=cp.CLARABEL)
        return prob.status not in ("infeasible", "infeasible_inaccurate")

    carriers_c = float(
        setup.carrier_mass * np.sum(np.sum(setup.points[carrier_sites, :2] ** 2, axis=1))
    )
    if not feasible(room=False):
        return Binding(
            "masses",
            f"the {len(carrier_sites)} carriers ({fmt(setup.carrier_mass)} kg each, their own "
            f"C = {fmt(carriers_c)} kg m^2) leave no nonnegative ballast that makes A = B = 2C "
            f"with C = {fmt(setup.params.C, PRECISE)} kg m^2 and the centre of mass at O",
            "inertia",
        )
    if not feasible(room=True):
        return Binding(
            "masses",
            f"the {setup.spec.ballast.name} ballast that makes A = B = 2C (C = "
            f"{fmt(setup.params.C, PRECISE)} kg m^2) does not fit in the cells the "
            f"{len(carrier_sites)} carriers leave free",
            "ballast cells",
        )
    return _magnet_binding(setup, free)


def _magnet_binding(setup: PhysicalSetup, free: np.ndarray) -> Binding:
    """Why the magnets do not fit: the field demagnetises some cells, or no room at all."""
    magnet = setup.spec.magnet
    allowed = setup.magnet_sites[free]
    if not np.all(allowed):
        withstood = magnet.field_withstood() or 0.0
        where = (
            f"{int(np.sum(allowed))} of the {len(free)} free cells"
            if np.any(allowed)
            else "none of the free cells"
        )
        return Binding(
            "magnets",
            f"the magnets need more volume of {magnet.name} (M = {fmt(magnet.magnetisation)} A/m) "
            f"than {where} hold beside the ballast where the field stays below the "
            f"{fmt(withstood)} T a {magnet.name} magnet withstands (intrinsic coercivity less its "
            "own demagnetising field); a higher-coercivity grade (ndfeb-eh, smco) or a weaker "
            "field reaches further",
            "magnets.material",
        )
    return Binding(
        "magnets",
        f"the magnets need more volume of {magnet.name} (M = "
        f"{fmt(magnet.magnetisation)} A/m) than the free cells hold beside the ballast",
        "magnet cells",
    )


# --------------------------------------------------------------------------- assembling
@dataclass
class PhysicalOutcome:
    charges: ChargeSolution
    masses: MassSolution
    scale: float
    seconds: float


def design_at_rate(setup: PhysicalSetup, s: float) -> PhysicalOutcome:
    """Both stages at time rate ``s``; raises PhysicalInfeasible naming the binding limit."""
    t0 = time.perf_counter()
    charges = design_charges(setup, s)
    masses = design_masses(setup, s, charges.sites)
    return PhysicalOutcome(charges, masses, s, time.perf_counter() - t0)


def scaled_parameters(params: Parameters, s: float) -> Parameters:
    """The theorem's parameters at time rate ``s`` (n, K x s; kappa, lambda, rho x s^2)."""
    return replace(
        params,
        n=params.n * s,
        K=params.K * s,
        kappa=params.kappa * s * s,
        lam=params.lam * s * s,
        rho=params.rho * s * s,
    )


def build_design(setup: PhysicalSetup, outcome: PhysicalOutcome) -> Design:
    """The Design of an outcome: carriers, magnets (with any attached ballast), ballast."""
    s = outcome.scale
    spec = setup.spec
    ch, ms = outcome.charges, outcome.masses
    magnets = np.linalg.norm(ms.moments, axis=1) > 0
    M = spec.magnet.magnetisation or 1.0
    fields = {k: tuple(v) for k, v in setup.conditions.fields.items()}
    if "electric" in fields:
        fields["electric"] = tuple(s * x for x in fields["electric"])
    larmor = setup.larmor
    design = Design(
        parameters=scaled_parameters(setup.theorem_params, s),
        fields=fields,
        charge_positions=setup.points[ch.sites],
        charge_values=ch.charges,
        charge_radii=np.full(len(ch.sites), setup.carrier_radius),
        charge_masses=np.full(len(ch.sites), setup.carrier_mass),
        dipole_positions=setup.points[ms.sites[magnets]],
        dipole_moments=ms.moments[magnets],
        dipole_volumes=np.linalg.norm(ms.moments[magnets], axis=1) / M,
        dipole_masses=ms.site_masses[magnets],
        mass_positions=setup.points[ms.sites[~magnets]],
        mass_values=ms.site_masses[~magnets],
        mass_materials=(
            [spec.ballasts[j].name for j in ms.materials[~magnets]]
            if ms.materials is not None
            else None
        ),
        realises=list(setup.options.realise or setup.conditions.realise),
        medium=spec.medium.to_dict(),
        materials=spec.materials_dict(),
        larmor=None if larmor is None else LarmorReading(larmor.reading, larmor.rate * s),
    )
    design.field_limits = dict(spec.field_limits)
    design.time_rate = s
    if spec.material_errors:
        design.material_errors = dict(spec.material_errors)
    return design


def _source_result(
    setup: PhysicalSetup,
    seconds: float,
    source: str,
    value: float,
    units: str,
    method: str,
    residual: float,
    count: int,
) -> SourceResult:
    """One source's outcome: its objective value, method, residual and element count."""
    A, b = setup.systems[source]
    return SourceResult(
        source=source,
        objective=setup.options.objective_for(source),
        objective_value=value,
        objective_value_raw=value,
        units=units,
        solver="HiGHS+Clarabel" if source == "charges" else "Clarabel",
        method=method,
        status="optimal",
        n_conditions=len(b),
        rank=int(np.linalg.matrix_rank(A)) if A.size else 0,
        n_candidates=len(setup.points),
        n_elements=count,
        residual_before=residual,
        residual_after=residual,
        seconds=seconds,
    )


def source_results(setup: PhysicalSetup, outcome: PhysicalOutcome) -> dict[str, SourceResult]:
    """The per-source outcomes in the form the report and summary read."""
    ch, ms = outcome.charges, outcome.masses

    def result(source: str, value: float, units: str, method: str, residual: float, count: int):
        return _source_result(setup, outcome.seconds, source, value, units, method, residual, count)

    out = {
        "charges": result(
            "charges",
            weighted_norm(ch.charges, setup.cost("charges")[ch.sites]),
            "C",
            ch.method,
            ch.residual,
            len(ch.sites),
        ),
        "dipoles": result(
            "dipoles",
            weighted_norm(ms.moments, setup.cost("dipoles")[ms.sites]),
            "A m^2",
            ms.method,
            ms.residual_dipoles,
            int(np.count_nonzero(np.linalg.norm(ms.moments, axis=1))),
        ),
        "masses": result(
            "masses",
            weighted_norm(ms.site_masses, setup.cost("masses")[ms.sites]),
            "kg",
            ms.method,
            ms.residual_masses,
            len(ms.sites),
        ),
    }
    return {k: v for k, v in out.items() if len(setup.systems[k][1])}


def design_physical(
    setup: PhysicalSetup,
    *,
    scale: float = 1.0,
    progress: Progress | None = None,
) -> DesignResult:
    """Design the physical body at time rate ``scale`` (1: the scene's parameters).

    The body is accepted as :mod:`chargedesign.designer.acceptance` says: its limits are
    checked again from the written parts and, under gravity, its balance; the realism budget
    (:func:`chargedesign.physical.realism.realism_budget`) is written into
    ``design.realism``. The design never locates the frontier (the frontier calls
    the design): :func:`chargedesign.designer.pipeline.design_from_scene` adds it.

    A rate beyond what the limits allow raises :class:`~chargedesign.errors.InfeasibleError`
    with the binding element and limit, in one line.
    """
    t0 = time.perf_counter()
    if progress is not None:
        progress(
            f"physical design: {len(setup.points)} candidate sites, medium {setup.spec.medium.name}"
        )
    try:
        design, outcome, limits = accept_at_rate(setup, scale)
    except PhysicalInfeasible as exc:
        raise InfeasibleError(beyond_message(setup, exc.binding, scale)) from None
    result = DesignResult(
        design=design,
        sources=source_results(setup, outcome),
        candidates=setup.candidates,
        options=setup.options,
        conditions=setup.conditions,
        timings={"physical": time.perf_counter() - t0},
        notes=[],
    )
    record_provenance(design, result)
    design.buildability = limits.to_dict()
    design.realism = realism_budget(design, limits.field_response)
    design.physical_design = {
        "carrier_radius_m": setup.carrier_radius,
        "carrier_mass_kg": setup.carrier_mass,
        "constraint_generation_rounds": outcome.charges.rounds,
        "surface_cones": outcome.charges.cones,
        "design_margin": DESIGN_MARGIN,
    }
    return result


_FURTHER = {
    "charges": "vacuum or a medium with a higher breakdown, more or larger carriers, a stronger "
    "magnetic field (a2 for K, a1 for n in the charges reading), or a smaller, lighter body "
    "reaches further",
    "fields": "a larger fields.electric.max reaches further",
    "masses": "lighter carriers (thinner shells, a lighter material, fewer) or a larger C "
    "reach further",
    "magnets": "a stronger magnet material, a larger gradient a2 or larger cells reach further",
    "balance": "a faster rate, a heavier designed potential or less gravity reaches it",
}


def beyond_message(setup: PhysicalSetup, binding: Binding, s: float) -> str:
    """One line: what fails at rate ``s`` and what would reach further (no frontier search:
    ``chargedesign frontier`` gives the largest rate)."""
    return (
        f"{binding.text(setup.spec.medium.name)} at time rate s = {fmt(s, PRECISE)}; "
        f"{_FURTHER.get(binding.stage, 'see docs/buildable.md')} (chargedesign frontier "
        "finds the largest rate)"
    )


def accept_at_rate(setup: PhysicalSetup, s: float) -> tuple[Design, PhysicalOutcome, Any]:
    """The body at rate ``s`` with the design's acceptance before the forward check: both
    stages, the limits recomputed from the written parts, and the balance under gravity.

    Returns
    -------
    design : Design
    outcome : PhysicalOutcome
    limits : chargedesign.physical.limits.LimitsReport

    Raises
    ------
    PhysicalInfeasible
        Naming the binding limit (stage ``balance`` when the check cannot confirm the
        balance gravity asks at this rate).
    SolverError
        The body fails its own limits check.
    """
    outcome = design_at_rate(setup, s)
    design = build_design(setup, outcome)
    limits = check_limits(design)
    if not limits.buildable:
        raise SolverError("physical design failed its own limits check: " + limits.violations[0])
    balance = balance_bound(design)
    if balance is not None:
        design.balance = balance.to_dict()
        if not balance.confirmed:
            raise PhysicalInfeasible(
                Binding(
                    "balance",
                    f"{balance.text()}; rates are accepted from s ="
                    f" {fmt(balance.lowest_rate, PRECISE)} up",
                    "centre of mass",
                    balance.held / balance.needed if balance.needed > 0 else math.inf,
                )
            )
    return design, outcome, limits
