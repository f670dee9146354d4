"""``zonal_sums`` by blocks of points gives the bits of one block (its operations are the same
on every point), at every order, with and without the value, for broadcast inputs."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign import fields
from chargedesign.fields import zonal_sums


@pytest.mark.parametrize("order", [0, 1, 2])
@pytest.mark.parametrize("want_value", [True, False])
def test_blocks_give_the_bits_of_one_block(monkeypatch, order, want_value):
    rng = np.random.default_rng(order + 3 * want_value)
    coeffs = rng.normal(size=7) * np.array([1, 0, 1, 1, 0, 1, 1])  # zeros skipped
    Z = rng.normal(size=(300, 41))
    S = Z[0] ** 2 + rng.random(41)  # broadcast along the rows
    blocked = zonal_sums(coeffs, Z, S, order, want_value=want_value)
    monkeypatch.setattr(fields, "ZONAL_BLOCK", Z.size)
    whole = zonal_sums(coeffs, Z, S, order, want_value=want_value)
    monkeypatch.setattr(fields, "ZONAL_BLOCK", 1000)  # blocks that cut the rows
    cut = zonal_sums(coeffs, Z, S, order, want_value=want_value)
    assert blocked.keys() == whole.keys() == cut.keys()
    for name, values in whole.items():
        assert values.shape == Z.shape
        np.testing.assert_array_equal(blocked[name], values)
        np.testing.assert_array_equal(cut[name], values)


def test_the_recurrence_matches_the_legendre_polynomials():
    """u_k = R^k P_k(Z/R) on the unit sphere, the value route (a check the blocks keep)."""
    theta = np.linspace(0.0, np.pi, 20001)
    Z, S = np.cos(theta), np.ones_like(theta)
    for k in range(1, 6):
        coeffs = np.zeros(k)
        coeffs[-1] = 1.0
        got = zonal_sums(coeffs, Z, S, 0)[""]
        np.testing.assert_allclose(got, np.polynomial.legendre.legval(Z, coeffs_of(k)), atol=1e-13)


def coeffs_of(k: int) -> np.ndarray:
    c = np.zeros(k + 1)
    c[k] = 1.0
    return c
