"""The physical design's column routes reach the whole programs' optima.

The magnets-and-masses program by columns (:mod:`chargedesign.designer.mass_columns`) against
the same program written whole in cvxpy and solved by Clarabel at tight tolerances; the
carriers' own-field LP by columns against the whole LP (HiGHS). The optima are not unique
(the moments of a degenerate face), so the objectives are compared, and the column route's
point is checked feasible.
"""

from __future__ import annotations

import numpy as np
import pytest
from physical.test_buildable import SMALL

from chargedesign.designer import charges
from chargedesign.designer.charges import design_charges, lp_charges
from chargedesign.designer.mass_columns import prices, solve_by_columns
from chargedesign.designer.masses import MASS_SEED, design_masses, mass_data, mass_program
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.scene import load_scene


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
