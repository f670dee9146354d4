"""Tests of chargedesign.moments against independent definitions (direct loops)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from chargedesign.errors import InputError
from chargedesign.moments import moment_key, moment_keys, monomial_matrix
from chargedesign.validation import parse_moment_key

RNG_SEED = 7_2024


def _cloud(rng: np.random.Generator, n: int = 30) -> tuple[np.ndarray, np.ndarray]:
    pts = rng.normal(size=(n, 3)) * rng.uniform(0.2, 1.5, size=(n, 1))
    pts[0] = 0.0
    return pts, rng.uniform(-1.0, 1.0, size=n)


def test_key_helpers_unchanged() -> None:
    assert moment_key((2, 0, 1)) == "xxz"
    assert parse_moment_key("xyy") == (1, 2, 0)
    assert moment_keys(2) == ["xx", "xy", "xz", "yy", "yz", "zz"]
    with pytest.raises(InputError):
        parse_moment_key("zx")


@pytest.mark.parametrize("order", [0, 1, 2, 3, 4])
def test_monomial_moments_match_loop_definition(order: int) -> None:
    """``monomial_matrix @ w`` is ``sum_j w_j prod_a x_{j,a}`` over each key's letters."""
    rng = np.random.default_rng(RNG_SEED + order)
    pts, w = _cloud(rng)
    keys = moment_keys(order)
    assert len(keys) == (order + 1) * (order + 2) // 2
    got = monomial_matrix(pts, keys) @ w
    for key, value in zip(keys, got, strict=True):
        idx = ["xyz".index(ch) for ch in key]
        direct = sum(w[j] * math.prod(pts[j, a] for a in idx) for j in range(len(pts)))
        assert value == pytest.approx(direct, abs=1e-13 * (1 + abs(direct)))
    if order == 2:
        tensor = np.einsum("j,ja,jb->ab", w, pts, pts)
        np.testing.assert_allclose(
            got,
            [tensor[0, 0], tensor[0, 1], tensor[0, 2], tensor[1, 1], tensor[1, 2], tensor[2, 2]],
            atol=1e-14,
        )


def test_empty_point_set() -> None:
    assert monomial_matrix(np.zeros((0, 3)), moment_keys(2)).shape == (6, 0)


def test_bad_points_name_the_input() -> None:
    with pytest.raises(InputError, match=r"^points"):
        monomial_matrix(np.ones((3, 2)), ["x"])
    with pytest.raises(InputError, match=r"^points"):
        monomial_matrix([[0, 0, np.inf]], ["x"])
