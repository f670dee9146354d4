"""The magnets-and-masses program by column generation over the free sites (Clarabel).

The program of :func:`chargedesign.designer.masses.mass_program` has few equality rows (the
dipole and mass conditions, tens) and a small conic set per site::

    S_i = {(w, sigma): w >= alpha |sigma|, beta_i |sigma| + gamma_i w <= 1}

(a magnet weighs at least its volume; magnet and ballast fit in the cell), with the cost
``cm_i w + cd_i |sigma|``. A site left out of a restricted program (its parts zero) cannot
improve it when, with the restricted program's equality duals ``y``, the Lagrangian of that
site is nonnegative on ``S_i``: with ``r = cm_i + y_m . a_i`` and ``p = cd_i - |D_i^T y_d|``
that is ``r >= 0`` and ``alpha r + p >= 0`` (the two extreme rays of the cone that ``S_i``
cuts). So a restricted program on a working set of sites is solved, every site priced in
closed form, the violators join, until none is left: the restricted optimum is then the
program's optimum (its duals are feasible for the whole program).

Restricted programs carry elastic slacks on the equality rows (so each is feasible); a slack
left at the end (or rounds run out) hands the decision to the whole program
(``None`` is returned; :func:`whole_infeasible` proves a refusal on it directly). The
working set is seeded from the last one on the same candidates (the whole-inertia rounds, and
probes at neighbouring rates).

Measured (docs/design.md): the default body at 9,939 candidates, one solve of the whole
program through cvxpy and Clarabel 4-7 s, by columns a few tenths of a second.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import sparse

#: rounds of pricing at most (then the whole program decides)
MAX_ROUNDS = 60
#: a site joins when its Lagrangian's minimum over its set is below -PRICE_TOL x the cost scale
PRICE_TOL = 1e-9
#: the elastic slacks' penalty over the largest cost and right-hand side
PENALTY = 1e4
#: a slack above this (relative to the right-hand side) leaves the decision to the whole program
SLACK_TOL = 1e-9
#: a reduced cost within this (times the cost scale) of zero puts a site on the optimal face
FACE_TOL = 1e-7
#: parts above this fraction of the largest seed the next working set
SEED_FRACTION = 1e-6
#: Clarabel's tolerances on the restricted programs (the penalty of the slacks costs two
#: digits of the objective at its default 1e-8, measured: 1.6e-7 against 1.6e-9)
CLARABEL_TOL = 1e-10


@dataclass
class MassData:
    """The program's data on the free ``sites`` (scaled as :func:`mass_program` scales it).

    ``Ads`` (rows, 3 k) and ``Ams`` (rows, k) are the row-scaled equality rows in the scaled
    unknowns ``sigma / sigma_scale`` and ``w / mass_scale``; ``alpha`` (scalar), ``beta`` and
    ``gamma`` (k,) the sets' coefficients; ``cm``, ``cd`` (k,) the costs; ``blocked`` (k,)
    the sites where a magnet would be demagnetised (no moment); the unknowns' scales.
    """

    sites: np.ndarray
    Ads: np.ndarray
    bds: np.ndarray
    Ams: np.ndarray
    bms: np.ndarray
    alpha: float
    beta: np.ndarray
    gamma: np.ndarray
    cm: np.ndarray
    cd: np.ndarray
    blocked: np.ndarray
    sigma_scale: float = 1.0
    mass_scale: float = 1.0
    #: the mass rows' right-hand side (kg m^k, unscaled: the carriers' and the correction's
    #: share taken off)
    rhs_masses: np.ndarray | None = None


@dataclass
class ColumnsSolution:
    """Scaled moments (k, 3) and masses (k,) on every free site; how they were found."""

    sigma: np.ndarray
    mass: np.ndarray
    rounds: int
    working: np.ndarray


def restricted_matrix(data: MassData, work: np.ndarray, free: np.ndarray) -> sparse.csc_matrix:
    """The restricted program's constraint matrix (CSC, canonical: rows sorted in each
    column; the zeros of the dense rows not stored), assembled from its triplets at once.

    Rows: the equality rows (dipoles, then masses), the linear rows (``-w + alpha t <= 0``,
    ``gamma w + beta t <= 1``, ``e >= 0``), then one block of 4 per second-order cone;
    columns ``(w, t, sigma, e+, e-)`` (see :func:`restricted_program`)."""
    k, kf = len(work), len(free)
    md, mm = len(data.bds), len(data.bms)
    me = md + mm
    n = k + kf + 3 * kf + 2 * me
    t0, s0, e0 = k, k + kf, k + 4 * kf
    lin0, soc0 = me, me + 2 * k + 2 * me
    where_free = np.searchsorted(work, free)
    sig_cols = (3 * free[:, None] + np.arange(3)).reshape(-1)
    block_m = data.Ams[:, work]
    mi, mj = np.nonzero(block_m)
    block_d = data.Ads[:, sig_cols]
    di, dj = np.nonzero(block_d)
    r, f, e = np.arange(k), np.arange(kf), np.arange(me)
    rows = [
        md + mi,  # the mass rows on w
        lin0 + r,  # -w
        lin0 + k + r,  # gamma w
        lin0 + where_free,  # alpha t
        lin0 + k + where_free,  # beta t
        soc0 + 4 * f,  # -t in its cone
        di,  # the dipole rows on sigma
        soc0 + 4 * f[:, None] + 1 + np.arange(3),  # -sigma in its cone
        e,  # e+ in the equality rows
        lin0 + 2 * k + e,  # -e+
        e,  # -e- in the equality rows
        lin0 + 2 * k + me + e,  # -e-
    ]
    cols = [
        mj,
        r,
        r,
        t0 + f,
        t0 + f,
        t0 + f,
        s0 + dj,
        s0 + 3 * f[:, None] + np.arange(3),
        e0 + e,
        e0 + e,
        e0 + me + e,
        e0 + me + e,
    ]
    vals = [
        block_m[mi, mj],
        -np.ones(k),
        data.gamma[work],
        np.full(kf, data.alpha),
        data.beta[free],
        -np.ones(kf),
        block_d[di, dj],
        -np.ones(3 * kf),
        np.ones(me),
        -np.ones(me),
        -np.ones(me),
        -np.ones(me),
    ]
    row = np.concatenate([np.ravel(x) for x in rows]).astype(np.int64)
    col = np.concatenate([np.ravel(x) for x in cols]).astype(np.int64)
    val = np.concatenate([np.ravel(x) for x in vals]).astype(float)
    order = np.lexsort((row, col))
    indptr = np.zeros(n + 1, dtype=np.int64)
    np.cumsum(np.bincount(col, minlength=n), out=indptr[1:])
    shape = (me + 2 * k + 2 * me + 4 * kf, n)
    return sparse.csc_matrix((val[order], row[order], indptr), shape=shape)


def restricted_program(data: MassData, work: np.ndarray, penalty: float) -> Any:
    """Clarabel's solution of the program on the sites ``work`` (indices into ``data``),
    with elastic slacks on the equality rows, and the layout ``(k, kf, free)``."""
    import clarabel  # the solver: imported where used (keeps import chargedesign light)

    k = len(work)
    free = work[~data.blocked[work]]
    kf = len(free)
    me = len(data.bds) + len(data.bms)
    n = k + kf + 3 * kf + 2 * me  # (w, t, sigma, e+, e-)
    A = restricted_matrix(data, work, free)
    h_lin = np.concatenate([np.zeros(k), np.ones(k), np.zeros(2 * me)])
    q = np.concatenate([data.cm[work], data.cd[free], np.zeros(3 * kf), np.full(2 * me, penalty)])
    b = np.concatenate([data.bds, data.bms, h_lin, np.zeros(4 * kf)])
    cones = [clarabel.ZeroConeT(me), clarabel.NonnegativeConeT(2 * k + 2 * me)]
    cones += [clarabel.SecondOrderConeT(4)] * kf
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = CLARABEL_TOL
    solution = clarabel.DefaultSolver(sparse.csc_matrix((n, n)), q, A, b, cones, settings).solve()
    return solution, (k, kf, free)


def whole_infeasible(data: MassData) -> bool:
    """Whether Clarabel proves the whole program (every free site, no slacks) infeasible,
    at its default tolerances (those cvxpy's whole program is solved with).

    The rows of :func:`restricted_matrix` on every site without the slacks' columns and rows:
    the same program :func:`chargedesign.designer.masses.mass_program` writes in cvxpy. Only a
    proof counts (``PrimalInfeasible`` or ``AlmostPrimalInfeasible``, which cvxpy reports as
    ``infeasible`` and ``infeasible_inaccurate``); any other outcome leaves the decision to
    the whole program through cvxpy."""
    import clarabel  # the solver: imported where used (keeps import chargedesign light)

    work = np.arange(len(data.sites))
    free = work[~data.blocked]
    k, kf = len(work), len(free)
    me = len(data.bds) + len(data.bms)
    n = k + 4 * kf
    full = restricted_matrix(data, work, free)
    lin0 = me
    rows = np.concatenate(
        [np.arange(me + 2 * k), lin0 + 2 * k + 2 * me + np.arange(4 * kf)]
    )  # the slacks' sign rows left out
    A = sparse.csc_matrix(full[rows][:, :n])
    q = np.concatenate([data.cm, data.cd[free], np.zeros(3 * kf)])
    b = np.concatenate([data.bds, data.bms, np.zeros(k), np.ones(k), np.zeros(4 * kf)])
    cones = [clarabel.ZeroConeT(me), clarabel.NonnegativeConeT(2 * k)]
    cones += [clarabel.SecondOrderConeT(4)] * kf
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    solution = clarabel.DefaultSolver(sparse.csc_matrix((n, n)), q, A, b, cones, settings).solve()
    proofs = (clarabel.SolverStatus.PrimalInfeasible, clarabel.SolverStatus.AlmostPrimalInfeasible)
    return solution.status in proofs


def _site_duals(data: MassData, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """From the equality duals ``y``: each site's mass reduced cost ``r`` and the norm ``g``
    of its dipole rows' duals."""
    md = len(data.bds)
    yd, ym = y[:md], y[md:]
    r = data.cm + data.Ams.T @ ym
    k = len(data.sites)
    g = np.linalg.norm((data.Ads.T @ yd).reshape(k, 3), axis=1) if md else np.zeros(k)
    return r, g


def prices(data: MassData, y: np.ndarray) -> np.ndarray:
    """The least value of each site's Lagrangian over its set ``S_i`` (<= 0; 0: the site
    cannot improve the program), from the equality duals ``y``."""
    r, g = _site_duals(data, y)
    p = data.cd - g
    # the rays (w, t) = (1, 0) and (alpha, 1), each to the cell's bound
    mass_ray = r / data.gamma
    magnet_ray = (data.alpha * r + p) / (data.beta + data.gamma * data.alpha)
    magnet_ray = np.where(data.blocked, 0.0, magnet_ray)
    return np.minimum(0.0, np.minimum(mass_ray, magnet_ray))


def on_face(data: MassData, y: np.ndarray, tol: float) -> np.ndarray:
    """Which sites have a zero reduced cost (within ``tol``) along a ray of their set: the
    sites an optimal solution may use (the others are zero in every one)."""
    r, g = _site_duals(data, y)
    magnet = np.abs(data.alpha * r + data.cd - g) <= tol
    return (np.abs(r) <= tol) | (magnet & ~data.blocked)


def start_set(data: MassData, seed: np.ndarray | None) -> np.ndarray:
    """The first working set: the seed's sites (candidate indices) that are free, and the
    sites that carry the least-norm solutions of the two row sets."""
    k = len(data.sites)
    size = min(k, max(4 * (len(data.bds) + len(data.bms)), 60))
    picks = []
    if len(data.bms):
        w = np.linalg.lstsq(data.Ams, data.bms, rcond=None)[0]
        picks.append(np.argsort(-w)[:size])
    if len(data.bds):
        s = np.linalg.lstsq(data.Ads, data.bds, rcond=None)[0].reshape(k, 3)
        norms = np.where(data.blocked, -1.0, np.linalg.norm(s, axis=1))
        picks.append(np.argsort(-norms)[:size])
    if seed is not None and len(seed):
        picks.append(np.flatnonzero(np.isin(data.sites, seed)))
    return np.unique(np.concatenate(picks)) if picks else np.arange(min(k, size))


def solve_by_columns(data: MassData, seed: np.ndarray | None = None) -> ColumnsSolution | None:
    """The program's optimum by column generation (None: the whole program must decide,
    because a slack stayed, the rounds ran out or Clarabel did not solve a restricted one)."""
    import clarabel  # the solver: imported where used (keeps import chargedesign light)

    k = len(data.sites)
    md = len(data.bds)
    cost_scale = max(float(np.max(data.cm, initial=1.0)), float(np.max(data.cd, initial=1.0)))
    rhs_scale = max(1.0, float(np.max(np.abs(np.concatenate([data.bds, data.bms])), initial=0.0)))
    penalty = PENALTY * cost_scale * rhs_scale
    in_work = np.zeros(k, dtype=bool)
    in_work[start_set(data, seed)] = True
    step = max(2 * (len(data.bds) + len(data.bms)), 40)
    ok = (clarabel.SolverStatus.Solved, clarabel.SolverStatus.AlmostSolved)
    for rounds in range(1, MAX_ROUNDS + 1):
        work = np.flatnonzero(in_work)
        solution, (kw, kf, free) = restricted_program(data, work, penalty)
        if solution.status not in ok:
            return None
        z = np.asarray(solution.z)
        x = np.asarray(solution.x)
        y = z[: md + len(data.bms)]
        value = prices(data, y)
        value[in_work] = 0.0
        violators = np.flatnonzero(value < -PRICE_TOL * cost_scale)
        if len(violators):
            in_work[violators[np.argsort(value[violators])][:step]] = True
            continue
        face = np.flatnonzero(~in_work & on_face(data, y, FACE_TOL * cost_scale))
        if len(face):
            # every site of the optimal face joins, and the last program is solved again: its
            # interior point then spreads the parts over the face as the whole program's does
            # (symmetric sites alike), not over the few a working set happened to hold
            in_work[face] = True
            continue
        me = md + len(data.bms)
        slack = float(np.sum(np.abs(x[-2 * me :]))) if me else 0.0
        if slack > SLACK_TOL * rhs_scale:
            return None
        mass = np.zeros(k)
        mass[work] = x[:kw]
        sigma = np.zeros((k, 3))
        sigma[free] = x[kw + kf : kw + 4 * kf].reshape(kf, 3)
        norms = np.linalg.norm(sigma[work], axis=1)
        used = work[
            (mass[work] > SEED_FRACTION * float(np.max(mass, initial=0.0)))
            | (norms > SEED_FRACTION * float(np.max(norms, initial=0.0)))
        ]
        return ColumnsSolution(sigma, mass, rounds, data.sites[used])
    return None
