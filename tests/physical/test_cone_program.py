"""The charges' cone programs: the dense interior point against Clarabel on the same data,
infeasibility left to Clarabel, and the charges' limit by both routes."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse

# the frontier's acceptance tests' bodies (pytest puts this folder on the path)
from test_frontier_acceptance import CASES, setup_of, small

from chargedesign.designer.charges import CHARGE_RESIDUES, POLISHED_RESIDUAL, design_charges
from chargedesign.designer.cone_program import ConeProgram
from chargedesign.designer.frontier_probes import MINMAX_GAP, charges_rate_limit
from chargedesign.physical.coulomb import coulomb_kernel


def _minmax_program(seed: int, k: int = 40, m: int = 120, p: int = 4) -> ConeProgram:
    """``min t``: charges at k sites meeting p random moment conditions, the field at m
    points within t (a small copy of the charges' minmax)."""
    rng = np.random.default_rng(seed)
    sites = rng.uniform(-1, 1, (k, 3))
    points = rng.uniform(-1.5, 1.5, (m, 3))
    points *= (1.6 / np.linalg.norm(points, axis=1))[:, None]  # outside the sites' ball
    G = coulomb_kernel(sites, points, 1.0)
    A = np.hstack([rng.normal(size=(p, k)), np.zeros((p, 1))])
    b = rng.normal(size=p)
    eye = sparse.identity(k, format="csr")
    minus_t = sparse.csr_matrix(-np.ones((k, 1)))
    G_lin = sparse.vstack([sparse.hstack([eye, minus_t]), sparse.hstack([-eye, minus_t])])
    G_soc = np.zeros((m, 4, k + 1))
    G_soc[:, 0, k] = -1.0
    G_soc[:, 1:, :k] = -G
    c = np.zeros(k + 1)
    c[k] = 1.0
    return ConeProgram(c, A, b, G_lin, np.zeros(2 * k), G_soc, np.zeros((m, 4)), "test")


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_dense_interior_point_and_clarabel_agree(seed):
    program = _minmax_program(seed)
    dense = program.solve()
    judge = program.solve_clarabel()
    assert dense is not None and judge is not None
    t_dense, t_judge = float(program.c @ dense), float(program.c @ judge)
    assert t_dense == pytest.approx(t_judge, rel=1e-6)
    # the dense answer is feasible: the conditions and every cone, to the tolerance
    assert np.max(np.abs(program.A @ dense - program.b)) <= 1e-7 * np.max(np.abs(program.b))
    slack = program.h_soc - program.G_soc @ dense
    assert np.all(slack[:, 0] - np.linalg.norm(slack[:, 1:], axis=1) >= -1e-7 * t_dense)
    assert np.all(program.h_lin - program.G_lin @ dense >= -1e-7 * t_dense)


def test_an_infeasible_program_is_refused_by_clarabel_through_solve():
    """t pinned below what the conditions need: no x, and solve says None (Clarabel's
    certificate), never a wrong minimiser."""
    program = _minmax_program(3)
    k = len(program.c) - 1
    t_needed = float(program.c @ program.solve_clarabel())
    pin = sparse.csr_matrix(([1.0], ([0], [k])), shape=(1, k + 1))
    program.G_lin = sparse.vstack([program.G_lin, pin])
    program.h_lin = np.concatenate([program.h_lin, [0.5 * t_needed]])
    assert program.solve() is None


def test_the_charges_limit_is_the_same_by_clarabel(monkeypatch):
    """The small body in SF6 (its charges bind): the charges' minmax by the dense interior
    point, then with every cone program sent to Clarabel. The two solvers stop at different
    points of the degenerate minimum, so the rounds' cone points differ; each rate is
    certified to the minmax's gap (charges exist at rate / (1 + gap)), so they agree to it."""
    setup = setup_of(CASES["small in SF6, frame"])
    dense = charges_rate_limit(setup)
    monkeypatch.setattr(ConeProgram, "solve", ConeProgram.solve_clarabel)
    judge = charges_rate_limit(setup)
    assert dense.stage == judge.stage == "charges"
    assert dense.gap <= MINMAX_GAP and judge.gap <= MINMAX_GAP
    assert dense.rate == pytest.approx(judge.rate, rel=MINMAX_GAP)


def test_near_the_limit_both_solvers_design_the_same_carriers(monkeypatch):
    """The small body in air at s_c (1 - rtol / 4), where the design needs cone rounds: the
    interior points' residue (charges at 1e-9 to 1e-6 of the largest) is dropped before
    the polish, so both solvers give the same carriers and charges, and no carrier holds
    less than CHARGE_RESIDUES[0] of the largest charge."""
    setup = setup_of(small())
    # to 6 digits: Clarabel's point on the degenerate minimum moves by up to 1e-6 of the
    # largest charge when the rate moves in its last bits (seen: 5e-7 for 5e-16 relative),
    # so the rate must not carry the interior point's rounding
    s = float(f"{charges_rate_limit(setup).rate * (1 - 0.01 / 4):.6g}")
    dense = design_charges(setup, s)
    monkeypatch.setattr(ConeProgram, "solve", ConeProgram.solve_clarabel)
    judge = design_charges(setup, s)
    assert dense.cones > 0 and judge.cones > 0  # the cone programs were used
    np.testing.assert_array_equal(dense.sites, judge.sites)
    # to 1e-6 of the largest charge: the polish ends each at machine residual, and a carrier
    # holding 1e-2 of the largest keeps only that share of the agreement (seen: 2e-5 relative
    # on a 1.9e-11 C charge of a 2.6e-9 C body, 1.5e-7 of the largest)
    largest = np.max(np.abs(judge.charges))
    np.testing.assert_allclose(dense.charges, judge.charges, rtol=0, atol=1e-6 * largest)
    for charges in (dense, judge):
        smallest = np.min(np.abs(charges.charges)) / np.max(np.abs(charges.charges))
        assert smallest >= CHARGE_RESIDUES[0]
        assert charges.residual <= POLISHED_RESIDUAL
