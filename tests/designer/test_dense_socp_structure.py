"""The dense SOCP's structured linear algebra against the plain formulas it replaces.

The normal matrix ``G_lin^T D^-2 G_lin + sum_i G_i^T W_i^-2 G_i`` (listed pairs of the linear
rows, the charge columns over three rows per cone, private columns as 4-vectors), the
products ``G x`` and ``G^T z`` over the present blocks, and the factor that eliminates the
charges' cost variables first: each equals the dense product or the plain Cholesky solve
to rounding. The programs have the shapes of the charges' stage (``x = (u, w)``), the
charges' minmax (``x = (u, t)``) and one epigraph variable per cone (private columns); the
whole solve agrees with Clarabel and the reference interior point's route.
"""

from __future__ import annotations

import clarabel
import numpy as np
import pytest
import scipy.sparse as sp

from chargedesign.designer.dense_socp import (
    NormalFactor,
    NormalSystem,
    as_cone_program,
    nt_scaling,
    solve_dense_socp,
)

#: agreement of the structured products with the plain ones, relative to their size
ROUNDING = 1e-12


def coulomb(k, m, seed):
    """Fields ``(m, 3, k)`` at ``m`` points of the unit sphere of ``k`` unit charges inside."""
    rng = np.random.default_rng(seed)
    places = rng.uniform(-0.5, 0.5, (k, 3))
    points = rng.standard_normal((m, 3))
    points /= np.linalg.norm(points, axis=1)[:, None]
    diff = points[:, None, :] - places[None, :, :]
    field = diff / np.linalg.norm(diff, axis=2)[:, :, None] ** 3
    return np.transpose(field, (0, 2, 1)), rng


def charges_program(k=30, m=40, p=3, seed=0):
    """``min sum w`` on ``A u = b``, ``|u| <= w``, ``|u| <= cap`` and ``|G_i u| <= h_i``."""
    G, rng = coulomb(k, m, seed)
    u0 = rng.uniform(-0.1, 0.1, k)
    A = rng.standard_normal((p, k))
    eye, zero = sp.identity(k, format="csr"), sp.csr_matrix((k, k))
    G_lin = sp.vstack(
        [
            sp.hstack([eye, -eye]),
            sp.hstack([-eye, -eye]),
            sp.hstack([eye, zero]),
            sp.hstack([-eye, zero]),
        ]
    ).tocsr()
    cap = np.full(k, 1.0)
    G_soc = np.zeros((m, 4, 2 * k))
    G_soc[:, 1:, :k] = -G
    h_soc = np.zeros((m, 4))
    h_soc[:, 0] = 0.5 + 0.5 * np.linalg.norm(G @ u0, axis=1)
    c = np.concatenate([np.zeros(k), rng.uniform(0.5, 1.5, k)])
    A_eq = np.hstack([A, np.zeros((p, k))])
    return c, A_eq, A @ u0, G_lin, np.concatenate([np.zeros(2 * k), cap, cap]), G_soc, h_soc


def minmax_program(k=30, m=40, p=3, seed=1):
    """``min t`` on ``A u = b``, ``|u_j| + own_j <= t`` and ``|G_i u| + ext_i <= t``."""
    G, rng = coulomb(k, m, seed)
    A = rng.standard_normal((p, k))
    b = A @ rng.uniform(-0.1, 0.1, k)
    eye, minus_t = sp.identity(k, format="csr"), sp.csr_matrix(-np.ones((k, 1)))
    G_lin = sp.vstack([sp.hstack([eye, minus_t]), sp.hstack([-eye, minus_t])]).tocsr()
    own = rng.uniform(0.0, 0.1, k)
    G_soc = np.zeros((m, 4, k + 1))
    G_soc[:, 0, k] = -1.0
    G_soc[:, 1:, :k] = -G
    h_soc = np.zeros((m, 4))
    h_soc[:, 0] = -rng.uniform(0.0, 0.1, m)
    c = np.zeros(k + 1)
    c[k] = 1.0
    A_eq = np.hstack([A, np.zeros((p, 1))])
    return c, A_eq, b, G_lin, np.concatenate([-own, -own]), G_soc, h_soc


def epigraph_program(k=20, m=25, p=2, seed=2):
    """``min sum t_i`` on ``A u = b``, ``|u| <= 1`` and ``|G_i u - g_i| <= t_i``: one
    private column per cone."""
    G, rng = coulomb(k, m, seed)
    A = rng.standard_normal((p, k))
    b = A @ rng.uniform(-0.5, 0.5, k)
    box = sp.hstack([sp.identity(k), sp.csr_matrix((k, m))])
    G_lin = sp.vstack([box, -box]).tocsr()
    G_soc = np.zeros((m, 4, k + m))
    G_soc[np.arange(m), 0, k + np.arange(m)] = -1.0
    G_soc[:, 1:, :k] = -G
    h_soc = np.zeros((m, 4))
    h_soc[:, 1:] = -rng.standard_normal((m, 3))
    c = np.concatenate([np.zeros(k), np.ones(m)])
    return c, np.hstack([A, np.zeros((p, m))]), b, G_lin, np.ones(2 * k), G_soc, h_soc


PROGRAMS = {"charges": charges_program, "minmax": minmax_program, "epigraph": epigraph_program}


def interior(m, rng):
    u = rng.standard_normal((m, 4))
    u[:, 0] = np.linalg.norm(u[:, 1:], axis=1) * (1.0 + rng.uniform(0.01, 3.0, m))
    return u


def random_scaling(program, seed):
    """The NT scaling of a random interior pair (spread over several orders of magnitude)."""
    rng = np.random.default_rng(seed)
    l, m = program.h_lin.size, program.h_soc.shape[0]
    s_lin, z_lin = 10.0 ** rng.uniform(-3, 3, l), 10.0 ** rng.uniform(-3, 3, l)
    s_soc = interior(m, rng) * 10.0 ** rng.uniform(-2, 2, (m, 1))
    return nt_scaling(s_lin, z_lin, s_soc, interior(m, rng))


def plain_normal_matrix(program, scaling):
    """``G_lin^T D^-2 G_lin + sum_i G_i^T W_i^-2 G_i`` by dense products."""
    G_lin = program.G_lin.toarray()
    if scaling is None:
        return G_lin.T @ G_lin + np.einsum("mkn,mkl->nl", program.G_soc, program.G_soc)
    scaled = G_lin / scaling.d[:, None]
    Y = np.matmul(scaling.matrices(inverse=True), program.G_soc)
    return scaled.T @ scaled + np.einsum("mkn,mkl->nl", Y, Y)


@pytest.mark.parametrize("name", sorted(PROGRAMS))
@pytest.mark.parametrize("seed", [None, 3, 4])
def test_the_normal_matrix_equals_the_plain_products(name, seed):
    program = as_cone_program(*PROGRAMS[name]())
    scaling = None if seed is None else random_scaling(program, seed)
    d = np.ones(program.h_lin.size) if scaling is None else scaling.d
    M = NormalSystem(program, d, scaling).M
    plain = plain_normal_matrix(program, scaling)
    np.testing.assert_allclose(M, plain, rtol=0, atol=ROUNDING * np.abs(plain).max())


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_the_products_equal_the_plain_ones(name):
    program = as_cone_program(*PROGRAMS[name]())
    rng = np.random.default_rng(5)
    x = rng.standard_normal(program.c.size)
    z_lin, z_soc = (
        rng.standard_normal(program.h_lin.size),
        rng.standard_normal((len(program.G_soc), 4)),
    )
    G_lin = program.G_lin.toarray()
    Gx_lin, Gx_soc = program.G_times(x)
    np.testing.assert_allclose(Gx_lin, G_lin @ x, rtol=ROUNDING, atol=ROUNDING)
    plain_soc = np.einsum("mkn,n->mk", program.G_soc, x)
    np.testing.assert_allclose(Gx_soc, plain_soc, rtol=0, atol=ROUNDING * np.abs(plain_soc).max())
    plain_T = G_lin.T @ z_lin + np.einsum("mkn,mk->n", program.G_soc, z_soc)
    GTz = program.GT_times(z_lin, z_soc)
    np.testing.assert_allclose(GTz, plain_T, rtol=0, atol=ROUNDING * np.abs(plain_T).max())


def test_only_the_charges_cost_variables_are_eliminated():
    charges = as_cone_program(*charges_program())
    k = charges.c.size // 2
    assert charges.split is not None
    np.testing.assert_array_equal(charges.split[1], np.arange(k, 2 * k))  # the w's
    # the minmax's t is in every cone, the epigraph variables each in one: nothing diagonal
    assert as_cone_program(*minmax_program()).split is None
    assert as_cone_program(*epigraph_program()).split is None


@pytest.mark.parametrize("seed", [3, 4])
def test_the_split_factor_solves_like_a_plain_cholesky(seed):
    program = as_cone_program(*charges_program())
    scaling = random_scaling(program, seed)
    K = NormalSystem(program, scaling.d, scaling).M + program.AtA
    rhs = np.random.default_rng(seed).standard_normal((K.shape[0], 3))
    split = NormalFactor(K.copy(), program.split).solve(rhs)
    plain = NormalFactor(K.copy(), None).solve(rhs)
    np.testing.assert_allclose(split, plain, rtol=0, atol=1e-9 * np.abs(plain).max())
    # and both solve the (slightly regularised) system
    residual = K @ split - rhs
    assert np.abs(residual).max() <= 1e-8 * np.abs(K).max() * np.abs(split).max()


def clarabel_objective(c, A, b, G_lin, h_lin, G_soc, h_soc):
    m, n = len(G_soc), c.size
    matrix = sp.vstack(
        [sp.csc_matrix(A), sp.csc_matrix(G_lin), sp.csc_matrix(G_soc.reshape(4 * m, n))],
        format="csc",
    )
    cones = [clarabel.ZeroConeT(len(b)), clarabel.NonnegativeConeT(len(h_lin))]
    cones += [clarabel.SecondOrderConeT(4)] * m
    settings = clarabel.DefaultSettings()
    settings.verbose = False
    settings.tol_gap_abs = settings.tol_gap_rel = settings.tol_feas = 1e-10
    rhs = np.concatenate([b, h_lin, h_soc.ravel()])
    solution = clarabel.DefaultSolver(
        sp.csc_matrix((n, n)), c, matrix, rhs, cones, settings
    ).solve()
    assert solution.status == clarabel.SolverStatus.Solved
    return float(c @ np.asarray(solution.x))


@pytest.mark.parametrize("name", sorted(PROGRAMS))
def test_the_structured_route_solves_like_clarabel(name):
    problem = PROGRAMS[name]()
    sol = solve_dense_socp(*problem)
    assert sol.status == "solved"
    reference = clarabel_objective(*problem)
    # both stop at relative residuals and gap 1e-8 (Clarabel here at 1e-10)
    assert sol.primal_objective == pytest.approx(reference, rel=1e-7, abs=1e-9)
