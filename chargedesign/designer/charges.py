"""Physical design, the charges' stage (carriers of radius ``a`` at candidate points).

``A_c q = s b_c`` and, at sample points x on every carrier surface,
``|sum_j q_j G_j(x)| <= E_safe - s E_ext(|x|)`` (second-order cones, linear in q; ``E_ext``
the largest external field over orientations). Solved by constraint generation: an LP with each
carrier's own-field bound ``|q_i| <= 4 pi eps0 a^2 (E_safe - s E_ext)`` (necessary, so its
infeasibility proves the design impossible), then cones only where the independent surface
check finds a carrier above its limit, on the working set of used carriers. The charges are
polished to machine precision on their support and the limits verified again with denser
samples (:func:`chargedesign.physical.limits.check_limits`). :func:`charge_program` returns the
whole stage as one cvxpy problem, for a user to extend and for the tests to compare.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse

from chargedesign.constants import COULOMB
from chargedesign.designer.charge_symmetry import ChargeSymmetry, one_per_orbit
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.linear_program import linprog_highs
from chargedesign.designer.physical_setup import (
    DESIGN_MARGIN,
    Binding,
    PhysicalInfeasible,
    PhysicalSetup,
)
from chargedesign.designer.polish import support_of
from chargedesign.designer.system import polish_equal, relative_residual, row_scaled
from chargedesign.errors import SolverError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.coulomb import coulomb_kernel, sphere_fields, sphere_kernel
from chargedesign.physical.limits import (
    local_caps,
    sample_spacing,
)
from chargedesign.sampling import fibonacci_sphere

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


#: the own-field LP is solved by columns above this many usable carriers
LP_COLUMNS_MIN = 400


#: the key of ``PhysicalSetup.warm`` that seeds the own-field LP's working set (the last
#: support, at this rate or a neighbouring one)
CHARGE_SEED = "charges: working set"


#: rounds of the LP's column generation at most (then the whole LP decides)
LP_COLUMN_ROUNDS = 60


#: the polished charges meet A q = s b to this relative residual
POLISHED_RESIDUAL = 1e-12


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


def lp_charges(
    A: np.ndarray,
    b: np.ndarray,
    caps: np.ndarray,
    cost: np.ndarray | None = None,
    seed: np.ndarray | None = None,
) -> np.ndarray | None:
    """min sum cost_j |q_j| with A q = b, |q| <= caps, by HiGHS (None: infeasible).

    Above :data:`LP_COLUMNS_MIN` usable carriers by columns (:func:`lp_by_columns`, seeded
    from ``seed``, candidate indices), the whole LP deciding when they cannot.
    """
    usable = caps > 0
    cols = np.flatnonzero(usable)
    if len(cols) == 0:
        return None
    qs = float(np.max(caps[cols]))
    As, bs = row_scaled(A[:, cols], b, qs)
    c = np.ones(len(cols)) if cost is None else cost[cols]
    u = None
    if len(cols) > LP_COLUMNS_MIN:
        start = None if seed is None else np.flatnonzero(np.isin(cols, seed))
        u = lp_by_columns(As, bs, caps[cols] / qs, c, start)
    if u is None:
        u = _whole_lp(As, bs, caps[cols] / qs, c)
    if u is None:
        return None
    q = np.zeros(len(caps))
    q[cols] = u * qs
    return q


def _whole_lp(As: np.ndarray, bs: np.ndarray, cap: np.ndarray, c: np.ndarray) -> np.ndarray | None:
    """The scaled LP on every column by HiGHS: ``u`` (None: infeasible)."""
    k = len(c)
    res = linprog_highs(
        np.tile(c, 2),
        A_eq=np.hstack([As, -As]),
        b_eq=bs,  # q = qs * u
        bounds=list(zip(np.zeros(2 * k), np.tile(cap, 2), strict=True)),
    )
    if res.status == 2:
        return None
    if res.status != 0 or res.x is None:
        raise SolverError(f"charges: HiGHS failed on the carriers' own-field LP ({res.message})")
    return np.asarray(res.x[:k] - res.x[k:])


def lp_by_columns(
    As: np.ndarray, bs: np.ndarray, cap: np.ndarray, c: np.ndarray, start: np.ndarray | None
) -> np.ndarray | None:
    """The scaled LP ``min c |u|``, ``As u = bs``, ``|u| <= cap`` by column generation.

    Restricted LPs on a working set carry elastic slacks; every column is priced with the
    duals ``y`` (a column at zero cannot improve when ``c_j >= |a_j . y|``) and the worst
    join, until none is left: then the restricted optimum is the LP's. None: a slack stayed
    or the rounds ran out (the whole LP decides, infeasibility too).
    """
    m, n = As.shape
    penalty = 1e4 * float(np.max(c)) * max(1.0, float(np.max(np.abs(bs), initial=0.0)))
    size = min(n, max(4 * m, 60))
    picks = [np.argsort(-np.abs(As.T @ bs))[:size], np.argsort(-cap)[:size]]
    if start is not None:
        picks.append(start)
    in_work = np.zeros(n, dtype=bool)
    in_work[np.concatenate(picks)] = True
    eye = np.eye(m)
    step = max(2 * m, 40)
    for _ in range(LP_COLUMN_ROUNDS):
        work = np.flatnonzero(in_work)
        k = len(work)
        Aw = As[:, work]
        res = linprog_highs(
            np.concatenate([c[work], c[work], np.full(2 * m, penalty)]),
            A_eq=np.hstack([Aw, -Aw, eye, -eye]),
            b_eq=bs,
            bounds=[(0.0, u) for u in np.tile(cap[work], 2)] + [(0.0, None)] * (2 * m),
        )
        if res.status != 0 or res.x is None or res.eq_duals is None:
            return None
        reduced = c - np.abs(As.T @ res.eq_duals)
        reduced[in_work] = 0.0
        violators = np.flatnonzero(reduced < -1e-9 * float(np.max(c)))
        if len(violators):
            in_work[violators[np.argsort(reduced[violators])][:step]] = True
            continue
        if float(np.sum(res.x[2 * k :])) > 1e-9 * max(1.0, float(np.max(np.abs(bs)))):
            return None
        u = np.zeros(n)
        u[work] = res.x[:k] - res.x[k : 2 * k]
        return u
    return None


def surface_check(
    setup: PhysicalSetup, positions: np.ndarray, q: np.ndarray, s: float, samples: int
) -> tuple[np.ndarray, np.ndarray]:
    """Largest surface field of each carrier over the safe field, and where it occurs.

    ``samples`` Fibonacci points per carrier, then a refinement around the largest one
    (:func:`~chargedesign.physical.limits.local_caps`), so the maximum between samples is found.
    The fields are summed in each carrier's own coordinates
    (:func:`~chargedesign.physical.coulomb.sphere_fields`: its own charge exact); at the
    samples through the candidates' charge-free geometry, kept per candidate set
    (:func:`~chargedesign.physical.coulomb.sphere_kernel`), when ``positions`` are candidates.

    Returns
    -------
    ratios : ndarray, shape (k,)
    worst : ndarray, shape (k, 3)
    """
    k = len(q)
    if k == 0:
        return np.zeros(0), np.zeros((0, 3))
    dirs = fibonacci_sphere(samples)
    a = setup.carrier_radius
    radii = np.full(k, a)
    kernel = sphere_kernel(setup.points, a, dirs)
    rows = None if kernel is None else kernel.rows_of(positions)
    if kernel is not None and rows is not None:
        fields, distances = kernel.fields(rows, q), kernel.distances[rows]
    else:
        fields = sphere_fields(positions, q, radii, dirs)
        distances = np.linalg.norm(positions[:, None, :] + a * dirs[None, :, :], axis=2)
    # every carrier's samples, then a cap around each one's largest
    e = np.linalg.norm(fields, axis=2) + setup.external_max(distances, s)
    cap_dirs = local_caps(dirs[np.argmax(e, axis=1)], 1.5 * sample_spacing(samples))
    caps = positions[:, None, :] + a * cap_dirs
    e_cap = np.linalg.norm(sphere_fields(positions, q, radii, cap_dirs), axis=2)
    e_cap += setup.external_max(np.linalg.norm(caps, axis=2), s)
    best = np.argmax(e_cap, axis=1)
    rows_k = np.arange(k)
    ratios = np.maximum(e_cap[rows_k, best], e.max(axis=1)) / setup.safe_field
    return ratios, caps[rows_k, best]


class ConeRows:
    """The field per unit charge of the sources at the surface cones' points, each point's
    rows computed once while the columns stay the same (the constraint generation's rounds
    keep their cones, add a few, and mostly keep their working set; a new set of columns
    starts afresh, so the kept rows never outgrow one round's program).

    ``of(points, scale, cols)`` is ``coulomb_kernel(sources[cols], points, scale)`` to the
    bit: the kernel is elementwise in the (point, source) pairs and ``scale`` multiplies the
    unit rows last, as there (tests/designer/test_cone_rows.py).
    """

    def __init__(self, sources: np.ndarray) -> None:
        self.sources = sources
        self.cols: np.ndarray | None = None
        self.rows: dict[bytes, np.ndarray] = {}

    def of(self, points: np.ndarray, scale: float, cols: np.ndarray | None = None) -> np.ndarray:
        """The rows at ``points`` (m, 3) of the sources ``cols`` (all: None), times ``scale``
        over ``COULOMB``: shape (m, 3, k)."""
        same = (cols is None and self.cols is None) or (
            cols is not None and self.cols is not None and np.array_equal(cols, self.cols)
        )
        if not same:
            self.cols, self.rows = (None if cols is None else np.array(cols)), {}
        sources = self.sources if self.cols is None else self.sources[self.cols]
        keys = [point.tobytes() for point in points]
        missing = [i for i, key in enumerate(keys) if key not in self.rows]
        if missing:
            fresh = coulomb_kernel(sources, points[missing], 1.0)
            self.rows.update((keys[i], row) for i, row in zip(missing, fresh, strict=True))
        return scale * np.stack([self.rows[key] for key in keys])


def socp_charges(
    setup: PhysicalSetup,
    sites: np.ndarray,
    s: float,
    cones: list[tuple[int, np.ndarray]],
    caps: np.ndarray,
    rows: ConeRows | None = None,
    symmetry: ChargeSymmetry | None = None,
) -> np.ndarray | None:
    """min sum cost_j |q_j| on ``sites`` with the charge conditions, own-field caps and
    surface cones (:class:`~chargedesign.designer.cone_program.ConeProgram`, in ``x = (u, w)``,
    ``q = qs u``, ``w >= |u|`` carrying the cost); ``rows`` keeps the cones' kernel rows
    between rounds.

    With a ``symmetry`` (``sites`` a union of its orbits, costs the same on each orbit) the
    charges are the symmetric ones, ``u = basis v`` with one unknown per orbit: their optimum
    is the program's with every cone at every image of its point
    (:class:`~chargedesign.designer.charge_symmetry.ChargeSymmetry`)."""
    A, b = setup.systems["charges"]
    qs = float(np.max(caps[sites]))
    As, bs = row_scaled(A[:, sites], s * b, qs)
    limit = setup.surface_limit
    cap = caps[sites] / qs
    cost = setup.cost("charges")[sites]
    basis = None
    if symmetry is not None:
        orbits = np.unique(symmetry.orbit[sites])
        orbits = orbits[orbits >= 0]  # a candidate whose charge is zero: a zero row
        basis = symmetry.basis[np.ix_(sites, orbits)]  # at most one nonzero in each row
        weight = np.abs(basis)
        As = As @ basis
        # |u_j| = |B_jo| |v_o| <= cap_j on every candidate of the orbit; the cost of |v_o|
        room = np.divide(cap[:, None], weight, out=np.full(weight.shape, np.inf), where=weight > 0)
        cap = np.min(room, axis=0)
        cost = cost @ weight
    k = len(cap)
    eye = sparse.identity(k, format="csr")
    zero = sparse.csr_matrix((k, k))
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
        rows = ConeRows(setup.points) if rows is None else rows
        G = rows.of(points, COULOMB * qs / limit, sites)  # (m, 3, sites)
        if basis is not None:
            G = G @ basis  # (m, 3, k): the field of each orbit's unit charges
        G_soc = np.zeros((len(points), 4, 2 * k))
        G_soc[:, 1:, :k] = -G  # the cone's (room, G u)
        h_soc = np.zeros((len(points), 4))
        h_soc[:, 0] = 1.0 - setup.external_max(np.linalg.norm(points, axis=1), s) / limit
    A_eq = np.hstack([As, np.zeros_like(As)])
    program = ConeProgram(
        np.concatenate([np.zeros(k), cost]),
        A_eq,
        bs,
        G_lin,
        h_lin,
        G_soc,
        h_soc,
        "charges: the surface-field cones",
    )
    x = program.solve()
    if x is None:
        return None
    u = x[:k] if basis is None else basis @ x[:k]
    return u * qs


def _excess(ratio: float) -> str:
    return f"needs {fmt(ratio)}x" if ratio >= 1.01 else "reaches"


def charge_support(q: np.ndarray) -> np.ndarray:
    return support_of(q, 1, 1e-9)


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
    rows: ConeRows | None = None,
    symmetry: ChargeSymmetry | None = None,
) -> tuple[np.ndarray | None, np.ndarray]:
    """The surface cones solved on the working set, else on every usable candidate: the
    charges on the working set returned (None: infeasible there too) and that set.

    The working set may lack carriers a solution needs: on every usable candidate the cones
    (a subset of the surface limits) relax the true problem, so its infeasibility proves the
    rate infeasible, and every faster one too (the feasible charges scale down with the
    rate): the frontier then sees a monotone answer. With a ``symmetry`` the working set is
    the union of its orbits and the charges symmetric (:func:`socp_charges`): infeasible
    there, no charges meet the cones at every image of their points, a relaxation too.
    """
    usable = np.flatnonzero(caps > 0)
    if symmetry is not None:
        working = _orbits_of(working, symmetry)
        usable = _orbits_of(usable, symmetry)
    solved = socp_charges(setup, working, s, cones, caps, rows, symmetry)
    if solved is None and len(working) < len(usable):
        working = usable
        solved = socp_charges(setup, working, s, cones, caps, rows, symmetry)
    return solved, working


def _orbits_of(sites: np.ndarray, symmetry: ChargeSymmetry) -> np.ndarray:
    """The candidates of every orbit that meets ``sites`` (the orbits whose charges are zero
    in every symmetric solution left out)."""
    orbits = np.unique(symmetry.orbit[sites])
    return np.flatnonzero(np.isin(symmetry.orbit, orbits[orbits >= 0]))


def design_symmetry(setup: PhysicalSetup) -> ChargeSymmetry | None:
    """The charges' symmetry the design's cone rounds use: that of the conditions
    (:attr:`~chargedesign.designer.physical_setup.PhysicalSetup.symmetry`) when the charges'
    costs are the same on each orbit (None: none)."""
    symmetry = setup.symmetry
    if symmetry is None:
        return None
    cost = setup.cost("charges")
    kept = symmetry.orbit >= 0
    mean = np.bincount(symmetry.orbit[kept], cost[kept]) / np.bincount(symmetry.orbit[kept])
    if not np.allclose(cost[kept], mean[symmetry.orbit[kept]], rtol=1e-12, atol=0.0):
        return None
    return symmetry


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
    rows = ConeRows(setup.points)
    worst_ratio, worst_site = 0.0, -1
    lp_alive = True
    # the charges' symmetry, looked for when the cones start
    symmetry: ChargeSymmetry | None = None
    looked = False
    for rounds in range(1, MAX_ROUNDS + 1):
        sites = charge_support(q)
        ratios, worst = surface_check(setup, setup.points[sites], q[sites], s, LOOP_SURFACE_SAMPLES)
        over = np.flatnonzero(ratios > 1 - DESIGN_MARGIN / 2)
        if len(over) == 0:
            return q, _charges_method(rounds, len(cones)), rounds, len(cones)
        k = int(over[np.argmax(ratios[over])])
        worst_ratio, worst_site = float(ratios[k]), int(sites[k])
        if lp_alive and rounds <= LP_ROUNDS:
            near = np.flatnonzero(ratios > CONE_THRESHOLD)
            lp_caps[sites[near]] *= np.minimum(1.0, (1 - DESIGN_MARGIN) / ratios[near])
            more = lp_charges(A, s * b, lp_caps, setup.cost("charges"), seed=working)
            if more is not None:
                working = np.union1d(working, charge_support(more))
                q = more
                continue
            lp_alive = False
        near = np.flatnonzero(ratios > CONE_THRESHOLD)
        if not looked:
            symmetry, looked = design_symmetry(setup), True
        if symmetry is not None:
            # the symmetric charges meet a cone at every image of its point
            near = one_per_orbit(near, ratios, symmetry.orbit[sites])
        cones.extend((int(sites[i]), worst[i]) for i in near)
        working = np.union1d(working, sites)
        solved, working = _cone_round(setup, working, s, cones, caps, rows, symmetry)
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
    if s > setup.rate_bound * (1 + 1e-12):
        raise PhysicalInfeasible(
            Binding(
                "fields",
                f"the electric field this rate needs exceeds fields.electric.max "
                f"({fmt(setup.spec.field_limits.get('electric'), PLAIN)} V/m)",
                "fields.electric",
                s / setup.rate_bound,
                proved=True,
            )
        )


def _lp_charges(
    setup: PhysicalSetup, A: np.ndarray, rhs: np.ndarray, caps: np.ndarray
) -> np.ndarray:
    """The linear program's charges within every carrier's own-field cap (refused: none)."""
    q_lp = lp_charges(A, rhs, caps, setup.cost("charges"), seed=setup.warm.get(CHARGE_SEED))
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
    setup.warm[CHARGE_SEED] = charge_support(q_lp)
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
    full = polish_equal(A, s * b, full, kept)
    sites = np.flatnonzero(full)
    q = full[sites]
    ratios, _ = surface_check(setup, setup.points[sites], q, s, LOOP_SURFACE_SAMPLES)
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
    As, bs = row_scaled(A, s * b, qs)
    q = cp.Variable(len(setup.points))
    limit = setup.surface_limit
    dirs = fibonacci_sphere(samples)
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
