"""The frontier's bound from the charges alone: the fastest rate any charges could reach.

The charges' minmax (:func:`charges_rate_limit`) bounds, by duality, every rate the charges'
stage (:mod:`chargedesign.designer.charges`) could design; the frontier
(:mod:`chargedesign.designer.frontier`) searches below it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import sparse

from chargedesign.constants import COULOMB, EPSILON_0
from chargedesign.designer.charge_symmetry import ChargeSymmetry, one_per_orbit
from chargedesign.designer.charges import (
    LOOP_SURFACE_SAMPLES,
    ConeRows,
    charge_support,
    surface_check,
)
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.physical_setup import DESIGN_MARGIN, PhysicalSetup
from chargedesign.designer.system import row_scaled
from chargedesign.errors import SolverError
from chargedesign.formatting import PLAIN, fmt

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
    cone_points : ndarray, shape (m, 3)
        The surface points of the last round's cones, m (a design near ``rate`` may start
        its own cones there; with a symmetry each stands for its images).
    symmetry : int
        The order of the charges' symmetry group the minmax used
        (:attr:`PhysicalSetup.symmetry`; 1: none).
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
    cone_points: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    symmetry: int = 1


def minmax_charges(
    setup: PhysicalSetup,
    cones: list[np.ndarray],
    rows: ConeRows | None = None,
    symmetry: ChargeSymmetry | None = None,
) -> tuple[float, np.ndarray, np.ndarray] | None:
    """``min t`` over charges ``u`` (rate 1) on every candidate with ``A u = b``, each
    carrier's own surface field plus the external one within ``t``, and the same at the cone
    points (:class:`~chargedesign.designer.cone_program.ConeProgram` in ``x = (u, t)``, u in
    units of the charge whose own surface field is the limit, t in units of the limit).
    Returns ``t`` in V/m, ``u`` in C, and each cone point's field over ``t``; None: no charges
    meet the conditions. ``rows`` keeps the cones' kernel rows between rounds.

    With a ``symmetry`` (:attr:`PhysicalSetup.symmetry`) the charges are ``u = basis v``, one
    unknown per orbit (the same ``t``: see :class:`ChargeSymmetry`), each cone standing for
    its point's images and each orbit's own-field rows for its candidates'.
    """
    A, b = setup.systems["charges"]
    limit = setup.surface_limit
    a = setup.carrier_radius
    qs = 4 * math.pi * EPSILON_0 * a**2 * limit  # the charge whose own surface field is limit
    As, bs = row_scaled(A, b, qs)
    own_ext = setup.carrier_external / limit  # the external field at each carrier's surface
    basis = None if symmetry is None else symmetry.basis
    if symmetry is None:
        k = len(setup.points)
        eye = sparse.identity(k, format="csr")
    else:
        assert basis is not None
        k = basis.shape[1]
        As = As @ basis
        own_ext = own_ext[symmetry.reps]
        # u at each orbit's candidate: its column's entry times v
        eye = sparse.diags(basis[symmetry.reps, np.arange(k)], format="csr")
    minus_t = sparse.csr_matrix(-np.ones((k, 1)))
    # u_j + own_ext_j <= t and -u_j + own_ext_j <= t
    G_lin = sparse.vstack([sparse.hstack([eye, minus_t]), sparse.hstack([-eye, minus_t])])
    h_lin = np.concatenate([-own_ext, -own_ext])
    G_soc, h_soc = np.zeros((0, 4, k + 1)), np.zeros((0, 4))
    if cones:
        points = np.array(cones)
        rows = ConeRows(setup.points) if rows is None else rows
        G = rows.of(points, COULOMB * qs / limit)  # (m, 3, candidates)
        if basis is not None:
            G = G @ basis  # (m, 3, k): the field of each orbit's unit charges
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
    u = x[:k] if basis is None else basis @ x[:k]
    return t * limit, u * qs, used


def charges_rate_limit(setup: PhysicalSetup, gap: float = MINMAX_GAP) -> ChargesLimit:
    """The largest rate the charges' stage allows, computed directly.

    At rate ``s`` the charges meet ``A q = s b`` (the charges' stage) with every carrier's
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
    (:attr:`PhysicalSetup.rate_bound`). Where the candidates and the conditions have
    symmetries (:attr:`PhysicalSetup.symmetry`) the programs
    are solved on the symmetric charges, one unknown per orbit and one cone per orbit of
    carriers near the maximum: the same optimum (the symmetric charges reach it), the check
    on every carrier as before (the default body: 67 unknowns instead of 257, its minmax
    about 4x faster).

    The cones hold at their points whether or not a body puts a carrier there (a body that
    leaves a candidate empty is not bound on its surface): the bound is the one the design's
    own proof uses (the cones on every usable carrier). Tested
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
    bound = setup.rate_bound
    empty = np.zeros(0, dtype=int)
    if not np.any(b):
        stage = "fields" if math.isfinite(bound) else "none"
        return ChargesLimit(bound, 0.0, 0.0, empty, np.zeros(0), -1, 0, 0, stage)
    limit = setup.surface_limit
    cones: list[np.ndarray] = []
    rows = ConeRows(setup.points)
    symmetry = setup.symmetry
    for rounds in range(1, MINMAX_ROUNDS + 1):
        solved = minmax_charges(setup, cones, rows, symmetry)
        if solved is None:
            return ChargesLimit(0.0, 0.0, math.inf, empty, np.zeros(0), -1, rounds, 0, "charges")
        t, u, used = solved
        sites = charge_support(u)
        s = limit / t
        # the check at rate s on the charges s u: ratios to E_safe, so 1 - DESIGN_MARGIN is t
        ratios, worst = surface_check(
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
                cone_points=np.array(cones).reshape(-1, 3),
                symmetry=1 if symmetry is None else symmetry.order,
            )
        near = np.flatnonzero(ratios > MINMAX_CONES * (1 - DESIGN_MARGIN))
        if symmetry is not None:
            near = one_per_orbit(near, ratios, symmetry.orbit[sites])
        cones = [point for point, value in zip(cones, used, strict=True) if value >= MINMAX_KEEP]
        cones.extend(worst[i] for i in near)
    raise SolverError(
        f"charges: the charges' minmax did not close its gap to {fmt(gap, PLAIN)} in"
        f" {MINMAX_ROUNDS} rounds"
    )
