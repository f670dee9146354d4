"""The dense SOCP interior-point solver against Clarabel, and its KKT conditions recomputed here.

The problems: Coulomb-like minmax problems built here (every cone row depends on every
charge, as in the charge design), a random LP, and three problems captured from the default
frontier's Clarabel calls (``dense_socp_problems.npz``: an LP with 25 equalities and two
canonicalised design SOCPs, one with 224 equality rows).
"""

from __future__ import annotations

from pathlib import Path

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp

from chargedesign.designer.dense_socp import (
    jordan_divide,
    jordan_product,
    lorentz_det,
    max_step_soc,
    nt_scaling,
    solve_dense_socp,
)

FIXTURE = Path(__file__).with_name("dense_socp_problems.npz")
#: relative agreement of the objective with Clarabel's
OBJECTIVE_RTOL = 1e-6
#: bound on the KKT residuals recomputed here, relative to the data and the point
KKT_TOL = 1e-7


# ---------------------------------------------------------------- problems


def coulomb_minmax(charges=12, points=60, seed=0, equality=True):
    """``min t`` s.t. ``||E_j q - target_j|| <= t`` at surface points ``j`` (``E_j`` the
    Coulomb field of unit charges at random places), ``|q_i| <= 1`` and (optionally)
    ``sum q = 0``. Variables ``x = (q, t)``."""
    rng = np.random.default_rng(seed)
    places = rng.uniform(-0.5, 0.5, (charges, 3))
    surface = rng.standard_normal((points, 3))
    surface /= np.linalg.norm(surface, axis=1)[:, None]
    diff = surface[:, None, :] - places[None, :, :]
    field = diff / np.linalg.norm(diff, axis=2)[:, :, None] ** 3
    n = charges + 1
    G_soc = np.zeros((points, 4, n))
    G_soc[:, 0, charges] = -1.0
    G_soc[:, 1:, :charges] = -np.transpose(field, (0, 2, 1))
    h_soc = np.zeros((points, 4))
    h_soc[:, 1:] = -rng.standard_normal((points, 3))
    box = sp.hstack([sp.eye(charges), sp.csr_matrix((charges, 1))])
    G_lin = sp.vstack([box, -box]).tocsr()
    h_lin = np.ones(2 * charges)
    c = np.zeros(n)
    c[charges] = 1.0
    A = np.zeros((1 if equality else 0, n))
    A[:, :charges] = 1.0
    return c, A, np.zeros(A.shape[0]), G_lin, h_lin, G_soc, h_soc


def random_lp(n=20, rows=5, seed=3):
    """``min c^T x`` on the box ``|x| <= 1`` with ``rows`` equalities through an inner point."""
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((rows, n))
    b = A @ rng.uniform(-0.5, 0.5, n)
    G_lin = sp.vstack([sp.eye(n), -sp.eye(n)]).tocsr()
    return (
        rng.standard_normal(n),
        A,
        b,
        G_lin,
        np.ones(2 * n),
        np.zeros((0, 4, n)),
        np.zeros((0, 4)),
    )


def captured(index):
    """A captured problem in Clarabel's form ``A x + s = b``, split into the solver's blocks."""
    with np.load(FIXTURE) as data:
        pre = f"p{index}_"
        matrix = sp.csc_matrix(
            (data[pre + "data"], data[pre + "indices"], data[pre + "indptr"]),
            shape=tuple(data[pre + "shape"]),
        ).tocsr()
        rhs, c = data[pre + "b"], data[pre + "c"]
        p, l, m = (int(v) for v in data[pre + "dims"])
    n = c.size
    G_soc = matrix[p + l :].toarray().reshape(m, 4, n)
    return (
        c,
        matrix[:p].toarray(),
        rhs[:p],
        matrix[p : p + l],
        rhs[p : p + l],
        G_soc,
        rhs[p + l :].reshape(m, 4),
    )


def clarabel_objective(c, A, b, G_lin, h_lin, G_soc, h_soc):
    """Clarabel's optimal value (tolerances 1e-8) on the same data, or its status name."""
    n, m = c.size, G_soc.shape[0]
    stacked = sp.vstack(
        [sp.csr_matrix(A), sp.csr_matrix(G_lin), sp.csr_matrix(G_soc.reshape(4 * m, n))]
    ).tocsc()
    rhs = np.concatenate([b, h_lin, h_soc.ravel()])
    cones = [clarabel.ZeroConeT(A.shape[0]), clarabel.NonnegativeConeT(h_lin.size)]
    cones += [clarabel.SecondOrderConeT(4)] * m
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-8
    solution = clarabel.DefaultSolver(sp.csc_matrix((n, n)), c, stacked, rhs, cones, settings)
    result = solution.solve()
    assert str(result.status) == "Solved"
    return result.obj_val


def with_dependent_rows(problem):
    """The problem with two more equality rows: a copy and a combination of the others."""
    c, A, b, *rest = problem
    extra = np.vstack([A[:1], A.sum(axis=0, keepdims=True)])
    return (c, np.vstack([A, extra]), np.concatenate([b, [b[0], b.sum()]]), *rest)


def cones_only(problem):
    """The problem without its linear inequalities (the charges bounded by the cones only)."""
    c, A, b, _, _, G_soc, h_soc = problem
    return c, A, b, np.zeros((0, c.size)), np.zeros(0), G_soc, h_soc


def dense_inequalities(problem):
    """The problem with ``G_lin`` as a dense array (the solver takes either)."""
    c, A, b, G_lin, *rest = problem
    return (c, A, b, G_lin.toarray(), *rest)


PROBLEMS = {
    "minmax": lambda: coulomb_minmax(),
    "minmax_no_equality": lambda: coulomb_minmax(seed=1, equality=False),
    "minmax_large": lambda: coulomb_minmax(charges=30, points=300, seed=4),
    "lp_only": lambda: random_lp(),
    "lp_dense_inequalities": lambda: dense_inequalities(random_lp(seed=8)),
    "cones_only": lambda: cones_only(coulomb_minmax(seed=7, equality=False)),
    "minmax_dependent_rows": lambda: with_dependent_rows(coulomb_minmax(seed=5)),
    "captured_lp": lambda: captured(0),
    "captured_design_224_equalities": lambda: captured(6),
    "captured_design_small": lambda: captured(11),
}


# ---------------------------------------------------------------- checks


def assert_kkt(problem, sol):
    """Primal and dual feasibility, complementarity and the objectives, recomputed."""
    c, A, b, G_lin, h_lin, G_soc, h_soc = problem
    x, y, z_lin, z_soc = sol.x, sol.y, sol.z_lin, sol.z_soc
    s_lin = h_lin - G_lin @ x
    s_soc = h_soc - np.einsum("mkn,n->mk", G_soc, x)
    size = 1.0 + np.abs(x).max()
    assert np.abs(A @ x - b).max(initial=0.0) <= KKT_TOL * (size + np.abs(b).max(initial=0.0))
    assert s_lin.min(initial=0.0) >= -KKT_TOL * size
    cone_margin = s_soc[:, 0] - np.linalg.norm(s_soc[:, 1:], axis=1)
    assert cone_margin.min(initial=0.0) >= -KKT_TOL * (size + np.abs(h_soc).max(initial=0.0))
    dual = c + A.T @ y + G_lin.T @ z_lin + np.einsum("mkn,mk->n", G_soc, z_soc)
    dual_size = 1.0 + np.abs(c).max() + np.abs(np.concatenate([y, z_lin, z_soc.ravel()])).max()
    assert np.abs(dual).max() <= KKT_TOL * dual_size
    assert z_lin.min(initial=0.0) >= 0.0
    assert (z_soc[:, 0] - np.linalg.norm(z_soc[:, 1:], axis=1)).min(initial=0.0) >= 0.0
    primal = c @ x
    dual_objective = -(b @ y + h_lin @ z_lin + np.sum(h_soc * z_soc))
    assert sol.primal_objective == pytest.approx(primal, rel=1e-12, abs=1e-12)
    assert sol.dual_objective == pytest.approx(dual_objective, rel=1e-10, abs=1e-12)
    scale = 1.0 + abs(primal)
    assert dual_objective <= primal + 1e-9 * scale
    assert primal - dual_objective <= 1e-7 * scale
    assert s_lin @ z_lin + np.sum(s_soc * z_soc) <= 1e-7 * scale


@pytest.mark.parametrize("name", sorted(PROBLEMS))
def test_solves_like_clarabel_and_satisfies_kkt(name):
    problem = PROBLEMS[name]()
    sol = solve_dense_socp(*problem)
    assert sol.status == "solved"
    assert all(np.all(np.isfinite(v)) for v in (sol.x, sol.y, sol.z_lin, sol.z_soc))
    assert max(sol.residuals.values()) <= 1e-8
    assert sol.y.shape == problem[2].shape
    reference = clarabel_objective(*problem)
    assert sol.primal_objective == pytest.approx(reference, rel=OBJECTIVE_RTOL, abs=1e-9)
    assert_kkt(problem, sol)


def unbounded_minmax():
    """Maximise ``t`` above the cones: unbounded."""
    c, *rest = coulomb_minmax(seed=2)
    return (-c, *rest)


def infeasible_equality():
    """``sum q = 100`` with 12 charges ``|q_i| <= 1``."""
    c, A, b, *rest = coulomb_minmax(seed=2)
    return (c, A, b + 100.0, *rest)


def infeasible_cone():
    """``t <= -1`` and ``t >= ||...||``."""
    c, A, b, G_lin, h_lin, G_soc, h_soc = coulomb_minmax(seed=2)
    row = sp.csr_matrix(([1.0], ([0], [c.size - 1])), shape=(1, c.size))
    return c, A, b, sp.vstack([G_lin, row]).tocsr(), np.append(h_lin, -1.0), G_soc, h_soc


def infeasible_lp():
    c, A, b, *rest = random_lp()
    return (c, A, b + 100.0, *rest)


def unbounded_lp():
    """``min -x_0`` with only ``x_0 >= -1`` bounding it."""
    n = 8
    G_lin = sp.vstack([sp.eye(n), -sp.eye(n)]).tocsr()[1:]
    c = np.zeros(n)
    c[0] = -1.0
    empty_soc = np.zeros((0, 4, n)), np.zeros((0, 4))
    return c, np.zeros((0, n)), np.zeros(0), G_lin, np.ones(2 * n - 1), *empty_soc


def inconsistent_equalities():
    c, A, b, *rest = with_dependent_rows(coulomb_minmax(seed=5))
    return (c, A, b + np.eye(b.size)[-1], *rest)


def nan_in_data():
    c, A, b, G_lin, h_lin, G_soc, h_soc = coulomb_minmax(seed=6)
    h_soc = h_soc.copy()
    h_soc[3, 1] = np.nan
    return c, A, b, G_lin, h_lin, G_soc, h_soc


def nan_in_matrix():
    c, A, b, G_lin, h_lin, G_soc, h_soc = coulomb_minmax(seed=6)
    A = A.copy()
    A[0, 2] = np.inf
    return c, A, b, G_lin, h_lin, G_soc, h_soc


@pytest.mark.parametrize(
    "make",
    [
        nan_in_matrix,
        unbounded_minmax,
        infeasible_equality,
        infeasible_cone,
        infeasible_lp,
        unbounded_lp,
        inconsistent_equalities,
        nan_in_data,
    ],
)
def test_a_problem_without_solution_is_not_solved(make):
    sol = solve_dense_socp(*make(), max_iter=40)
    assert sol.status == "not_solved"
    # given up early (stall or hopeless residuals), not at the iteration limit
    assert sol.iterations <= 15
    assert all(np.all(np.isfinite(v)) for v in (sol.x, sol.y, sol.z_lin, sol.z_soc))


def test_an_iteration_limit_gives_not_solved():
    sol = solve_dense_socp(*coulomb_minmax(), max_iter=3)
    assert sol.status == "not_solved"
    assert sol.iterations == 3


# ---------------------------------------------------------------- cone algebra


def interior_points(m, seed):
    """``m`` random points strictly inside the 4-dim Lorentz cone."""
    rng = np.random.default_rng(seed)
    u = rng.standard_normal((m, 4))
    u[:, 0] = np.linalg.norm(u[:, 1:], axis=1) * (1.0 + rng.uniform(0.01, 2.0, m))
    return u


def test_nt_scaling_maps_z_to_s():
    s, z = interior_points(50, 1), interior_points(50, 2)
    s_lin, z_lin = np.array([2.0, 0.5]), np.array([0.1, 3.0])
    scaling = nt_scaling(s_lin, z_lin, s, z)
    lam = scaling.apply(z)
    np.testing.assert_allclose(scaling.apply(s, inverse=True), lam, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(scaling.lam_soc, lam, rtol=1e-12)
    # the convention: W^2 z = s, not W^2 s = z
    np.testing.assert_allclose(scaling.apply(lam), s, rtol=1e-10, atol=1e-12)
    assert not np.allclose(scaling.apply(scaling.apply(s)), z)
    np.testing.assert_allclose(scaling.d**2 * z_lin, s_lin, rtol=1e-14)
    # the scaled pair is inside the cone and the matrices are inverse to each other
    assert np.all(lorentz_det(lam) > 0) and np.all(lam[:, 0] > 0)
    product = np.matmul(scaling.matrices(), scaling.matrices(inverse=True))
    np.testing.assert_allclose(product, np.broadcast_to(np.eye(4), product.shape), atol=1e-12)


def test_jordan_divide_inverts_the_product():
    lam, v = interior_points(40, 3), np.random.default_rng(4).standard_normal((40, 4))
    np.testing.assert_allclose(jordan_product(lam, jordan_divide(lam, v)), v, atol=1e-12)
    e = np.zeros((40, 4))
    e[:, 0] = 1.0
    np.testing.assert_allclose(jordan_product(lam, e), lam, rtol=1e-15)


def test_max_step_reaches_the_boundary_of_the_first_cone_it_leaves():
    x = interior_points(30, 5)
    dx = np.random.default_rng(6).standard_normal((30, 4)) * 5.0
    step = max_step_soc(x, dx)
    assert 0.0 < step < np.inf
    edge = x + step * dx
    margin = edge[:, 0] - np.linalg.norm(edge[:, 1:], axis=1)
    assert margin.min() == pytest.approx(0.0, abs=1e-9 * np.abs(edge).max())
    assert np.all(margin >= -1e-9 * np.abs(edge).max())
    inside = x + 0.999 * step * dx
    assert np.all(inside[:, 0] > np.linalg.norm(inside[:, 1:], axis=1))


def test_max_step_is_unbounded_along_the_cone():
    x, dx = interior_points(10, 7), interior_points(10, 8)
    assert max_step_soc(x, dx) == np.inf
