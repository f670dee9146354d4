"""The frontier command's two scipy-free kernels, against the scipy routes they replace:
the LPs by HiGHS through ``highspy`` (designer/linear_program.py) against
``scipy.optimize.linprog(method="highs")``, and the candidates' nearest neighbours by blocks
(candidates.nearest_distances) against ``scipy.spatial.cKDTree``. Both must give
the same bits: the designs, frontiers and windows built on them are compared to the last digit
by tools/compare_outputs.py."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import sparse
from scipy.optimize import linprog
from scipy.spatial import cKDTree

from chargedesign.candidates import NEAREST_BY_BLOCKS_MAX, nearest_distances
from chargedesign.designer.linear_program import linprog_highs


def _random_lp(rng: np.random.Generator, trial: int) -> dict:
    m, n = int(rng.integers(2, 15)), int(rng.integers(5, 60))
    A = rng.normal(size=(m, n))
    if trial % 3 == 0:
        A = np.round(A)  # integer rows: degenerate vertices, ties between bases
    x0 = rng.uniform(0.0, 1.0, size=n)
    lp: dict = {"c": rng.uniform(0.0, 1.0, n) if trial % 2 else np.ones(n), "A_eq": A}
    lp["b_eq"] = A @ x0
    if trial % 4 == 0:
        lp["A_ub"] = rng.normal(size=(3, n))
        lp["b_ub"] = lp["A_ub"] @ x0 + 0.1
    lp["bounds"] = [(0.0, 1.5)] * n if trial % 5 else (0, None)
    if trial % 7 == 0:
        lp["A_eq"] = sparse.csr_matrix(A)
    return lp


@pytest.mark.parametrize("trial", range(120))
def test_highs_lp_is_linprogs_to_the_bit(trial):
    lp = _random_lp(np.random.default_rng(trial), trial)
    theirs = linprog(method="highs", **lp)
    ours = linprog_highs(**lp)
    assert ours.status == theirs.status == 0
    assert ours.x is not None and ours.eq_duals is not None
    assert np.array_equal(ours.x, theirs.x)
    assert np.array_equal(ours.eq_duals, theirs.eqlin.marginals)


def test_highs_lp_bounds_as_an_array_and_its_options():
    rng = np.random.default_rng(5)
    A = rng.normal(size=(4, 20))
    b = A @ rng.uniform(0.0, 1.0, 20)
    upper = rng.uniform(0.5, 2.0, 20)
    c = rng.uniform(0.0, 1.0, 20)
    options = {"primal_feasibility_tolerance": 1e-10, "dual_feasibility_tolerance": 1e-10}
    theirs = linprog(
        c,
        A_eq=A,
        b_eq=b,
        bounds=list(zip(0 * upper, upper, strict=True)),
        method="highs",
        options=options,
    )
    for bounds in (np.column_stack([0 * upper, upper]), list(zip(0 * upper, upper, strict=True))):
        ours = linprog_highs(c, A_eq=A, b_eq=b, bounds=bounds, options=options)
        assert np.array_equal(ours.x, theirs.x)


def test_highs_lp_statuses_are_linprogs():
    one_row = np.array([[1.0, 1.0]])
    infeasible = {"c": np.ones(2), "A_eq": one_row, "b_eq": np.array([-1.0])}
    unbounded = {"c": -np.ones(2), "A_eq": np.array([[1.0, -1.0]]), "b_eq": np.array([0.0])}
    for lp, status in ((infeasible, 2), (unbounded, 3)):
        ours = linprog_highs(**lp)
        assert ours.status == linprog(method="highs", **lp).status == status
        assert ours.x is None


def _lattice(spacing: float, radius: float) -> np.ndarray:
    axis = np.arange(-radius, radius + spacing / 2, spacing)
    grid = np.stack(np.meshgrid(axis, axis, axis, indexing="ij"), -1).reshape(-1, 3)
    return grid[np.linalg.norm(grid, axis=1) <= radius]


@pytest.mark.parametrize(
    "points",
    [
        np.array([[0.0, 0.0, 0.0], [0.0, 0.0, 0.01]]),
        _lattice(0.0083, 0.05),  # the default scene's 257 candidates' lattice
        np.random.default_rng(3).normal(scale=0.02, size=(NEAREST_BY_BLOCKS_MAX, 3)),
        np.random.default_rng(4).normal(scale=0.02, size=(NEAREST_BY_BLOCKS_MAX + 1, 3)),
    ],
    ids=["two", "lattice", "blocks-largest", "tree-smallest"],
)
def test_nearest_distances_are_the_kd_trees_to_the_bit(points):
    dist, _ = cKDTree(points).query(points, k=2)
    assert np.array_equal(nearest_distances(points), dist[:, 1])
    # a sample of the points against all of them (the median spacing of a point file)
    sample = np.arange(0, len(points), 3)
    assert np.array_equal(nearest_distances(points, sample), dist[sample, 1])
