"""The physical design's column routes reach the whole programs' optima.

The magnets-and-masses program by columns (:mod:`chargedesign.designer.mass_columns`) against
the same program written whole in cvxpy and solved by Clarabel at tight tolerances; the
carriers' own-field LP by columns against the whole LP (HiGHS). The optima are not unique
(the moments of a degenerate face), so the objectives are compared, and the column route's
point is checked feasible.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from physical.test_buildable import SMALL

from chargedesign.designer import charges
from chargedesign.designer.charges import design_charges, lp_charges
from chargedesign.designer.mass_columns import prices, solve_by_columns
from chargedesign.designer.masses import MASS_SEED, design_masses, mass_data, mass_program
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.scene import load_scene

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


@pytest.fixture(scope="module")
def setup():
    return physical_setup_from_scene(load_scene(SMALL))


@pytest.fixture(scope="module")
def carriers(setup):
    return design_charges(setup, 1.0).sites


def _objective(data, mass, sigma):
    return float(data.cm @ mass + data.cd @ np.linalg.norm(sigma, axis=1))


def test_masses_by_columns_reach_the_whole_programs_optimum(setup, carriers):
    import cvxpy as cp

    whole = mass_program(setup, 1.0, carriers)
    whole.problem.solve(solver=cp.CLARABEL, tol_gap_abs=1e-11, tol_gap_rel=1e-11, tol_feas=1e-11)
    assert whole.problem.status == "optimal"
    data = mass_data(setup, 1.0, carriers)
    solved = solve_by_columns(data)
    assert solved is not None
    value = _objective(data, solved.mass, solved.sigma)
    assert value == pytest.approx(whole.problem.value, rel=1e-7)
    # the column route's point meets the program's rows and sets
    norms = np.linalg.norm(solved.sigma, axis=1)
    assert np.max(np.abs(data.Ams @ solved.mass - data.bms)) < 1e-7
    assert np.max(np.abs(data.Ads @ solved.sigma.reshape(-1) - data.bds)) < 1e-7
    assert np.all(solved.mass >= data.alpha * norms - 1e-9)
    assert np.all(data.beta * norms + data.gamma * solved.mass <= 1 + 1e-9)
    assert not np.any(norms[data.blocked])


def test_the_whole_programs_duals_price_no_site_below_zero(setup, carriers):
    """The pricing rule is the whole program's dual feasibility: at its optimum no site may
    improve (the restricted program is the whole one), and a wrong sign fails."""
    data = mass_data(setup, 1.0, carriers)
    solved = solve_by_columns(data, seed=data.sites)  # every site in the first working set
    assert solved is not None and solved.rounds == 1
    assert len(solved.working) < len(data.sites)  # the seed keeps the sites that carry parts
    zero = np.zeros(len(data.bds) + len(data.bms))
    assert np.all(prices(data, zero) == 0.0)  # no dual: every site costs, none improves


def test_design_masses_seeds_its_next_working_set(setup, carriers):
    setup.warm.pop(MASS_SEED, None)
    first = design_masses(setup, 1.0, carriers)
    assert MASS_SEED in setup.warm
    again = design_masses(setup, 1.0, carriers)
    assert np.sum(again.site_masses) == pytest.approx(np.sum(first.site_masses), rel=1e-9)


def test_own_field_lp_by_columns_equals_the_whole_lp(setup, monkeypatch):
    A, b = setup.systems["charges"]
    caps = setup.charge_caps(1.0)
    cost = setup.cost("charges")
    monkeypatch.setattr(charges, "LP_COLUMNS_MIN", 10**9)
    whole = lp_charges(A, b, caps, cost)
    monkeypatch.setattr(charges, "LP_COLUMNS_MIN", 0)
    by_columns = lp_charges(A, b, caps, cost)
    assert whole is not None and by_columns is not None
    assert cost @ np.abs(by_columns) == pytest.approx(cost @ np.abs(whole), rel=1e-9)
    assert np.all(np.abs(by_columns) <= caps * (1 + 1e-9))
    scale = np.max(np.abs(A), axis=1) * np.max(caps)
    assert np.max(np.abs(A @ by_columns - b) / scale) < 1e-8


def test_own_field_lp_by_columns_refuses_what_the_whole_lp_refuses(setup, monkeypatch):
    A, b = setup.systems["charges"]
    caps = setup.charge_caps(1.0) * 1e-6  # far too small for the conditions
    monkeypatch.setattr(charges, "LP_COLUMNS_MIN", 0)
    assert lp_charges(A, b, caps, setup.cost("charges")) is None


def _plain_restricted_matrix(data, work, free):
    """The restricted program's matrix block by block through scipy.sparse (the route
    restricted_matrix replaced), for comparison."""
    from scipy import sparse

    k, kf = len(work), len(free)
    md, mm = len(data.bds), len(data.bms)
    me = md + mm
    n = k + 4 * kf + 2 * me
    t0, e0 = k, k + 4 * kf
    where_free = np.searchsorted(work, free)
    eye = sparse.identity(me, format="csr")
    sig_cols = (3 * free[:, None] + np.arange(3)).reshape(-1)
    eq = sparse.hstack(
        [
            sparse.vstack([sparse.csr_matrix((md, k)), sparse.csr_matrix(data.Ams[:, work])]),
            sparse.csr_matrix((me, kf)),
            sparse.vstack(
                [sparse.csr_matrix(data.Ads[:, sig_cols]), sparse.csr_matrix((mm, 3 * kf))]
            ),
            eye,
            -eye,
        ],
        format="csr",
    )
    r = np.arange(k)
    rows = [r, where_free, k + r, k + where_free, 2 * k + np.arange(2 * me)]
    cols = [r, t0 + np.arange(kf), r, t0 + np.arange(kf), e0 + np.arange(2 * me)]
    vals = [-np.ones(k), np.full(kf, data.alpha), data.gamma[work], data.beta[free]]
    vals.append(-np.ones(2 * me))
    lin = sparse.csr_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
        shape=(2 * k + 2 * me, n),
    )
    soc_rows = (4 * np.arange(kf)[:, None] + np.arange(4)).reshape(-1)
    soc_cols = np.column_stack(
        [t0 + np.arange(kf), k + kf + 3 * np.arange(kf)[:, None] + np.arange(3)]
    )
    soc = sparse.csr_matrix((-np.ones(4 * kf), (soc_rows, soc_cols.reshape(-1))), shape=(4 * kf, n))
    return sparse.vstack([eq, lin, soc], format="csc")


@pytest.mark.parametrize("blocked_share", [0.0, 0.3])
def test_the_restricted_matrix_is_the_block_assembly_entry_for_entry(
    setup, carriers, blocked_share
):
    """The triplet assembly gives Clarabel the same CSC arrays (the same solves, bit for
    bit) as the block-by-block one, with and without blocked sites."""
    from dataclasses import replace

    from chargedesign.designer.mass_columns import restricted_matrix

    rng = np.random.default_rng(7)
    data = mass_data(setup, 1.0, carriers)
    data = replace(data, blocked=rng.random(len(data.sites)) < blocked_share)
    for size in (3, len(data.sites) // 2, len(data.sites)):
        work = np.sort(rng.choice(len(data.sites), size=size, replace=False))
        free = work[~data.blocked[work]]
        fast, plain = (
            restricted_matrix(data, work, free),
            _plain_restricted_matrix(data, work, free),
        )
        assert plain.has_sorted_indices
        assert fast.shape == plain.shape
        assert np.array_equal(fast.indptr, plain.indptr)
        assert np.array_equal(fast.indices, plain.indices)
        assert np.array_equal(fast.data, plain.data)


@pytest.fixture(scope="module")
def magnetic():
    """The K = 0 example's setup (no carriers): its magnets do not fit above s = 4.8."""
    return physical_setup_from_scene(load_scene(EXAMPLES / "chaplygin_magnetic.toml"))


@pytest.mark.parametrize("rate", [2.0, 4.0, 5.0, 8.0])
def test_clarabels_whole_program_proof_agrees_with_cvxpys_whole_program(magnetic, rate):
    """Where the direct whole program proves infeasibility, cvxpy's says infeasible; where
    cvxpy's is solved, no proof is claimed (the K = 0 example's magnets fit up to about 4.8)."""
    import cvxpy as cp

    from chargedesign.designer.mass_columns import whole_infeasible

    none = np.zeros(0, dtype=int)
    whole = mass_program(magnetic, rate, none)
    whole.problem.solve(solver=cp.CLARABEL)
    proved = whole_infeasible(mass_data(magnetic, rate, none))
    assert proved == (whole.problem.status in ("infeasible", "infeasible_inaccurate"))
    assert proved == (rate > 4.8)
