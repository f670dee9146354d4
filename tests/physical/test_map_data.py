"""The realisability map's shipped terms are what sympy derives, and read without sympy they
give the sympy route's values to the last bit (``lambdify`` of the derived coefficients)."""

from __future__ import annotations

import json

import mpmath
import numpy as np
import pytest
import sympy as sp
from fresh_process import imports_module

from chargedesign.model.case import GAMMA, C, c, d
from chargedesign.physical.map_data import (
    MAP_FILE,
    MAP_FORMAT,
    PRINTED_DIGITS,
    printed_float,
    shipped_map,
)
from chargedesign.physical.parasitics import RESPONSE_ORIENTATIONS
from chargedesign.physical.realism import (
    derived_map_terms,
    map_term_coefficients,
    map_term_values,
)
from chargedesign.sampling import fibonacci_sphere

KEYS = ("kappa", "n2", "nK", "K2", "mu_n", "mu_K")


def test_the_shipped_map_is_the_derived_one():
    derived = derived_map_terms()
    assert MAP_FILE.shipped_text() == MAP_FILE.text(derived)  # regenerate: make tables
    assert json.loads(MAP_FILE.shipped_text())["format"] == MAP_FORMAT
    assert shipped_map() == derived
    assert set(KEYS) | {"lambda", "rho"} == set(derived)
    assert derived["lambda"]["components"] is None and derived["rho"]["components"] is None


def lambdified_values(key: str, C_value: float, c_value: float, d_value: float) -> np.ndarray:
    """The sympy route the map took before its terms were shipped."""
    gammas = fibonacci_sphere(RESPONSE_ORIENTATIONS)
    values = [
        np.broadcast_to(
            sp.lambdify([C, *GAMMA], comp.subs({c: c_value, d: d_value}), "numpy")(
                C_value, *gammas.T
            ),
            len(gammas),
        )
        for comp in map_term_coefficients()[key]
    ]
    if len(values) == 1:
        return np.array(values[0], dtype=float)
    return np.array(np.max(np.linalg.norm(np.array(values), axis=0)))


def bodies() -> list[tuple[float, float, float]]:
    rng = np.random.default_rng(42)
    drawn = [
        (float(10.0 ** rng.uniform(-9, 2)), float(rng.normal()), float(rng.normal()))
        for _ in range(24)
    ]
    special = [
        (1.0, 0.0, 0.0),
        (2.5e-5, 1.0, 0.0),
        (2.5e-5, 0.0, -1.0),
        (3.0, 0.3, 0.3),
        (3.0, -0.7, 0.7),
        (0.1, 0.30000000000000004, 0.1),
        (7.0, 1e-12, 3e8),
    ]
    return special + drawn


@pytest.mark.parametrize("body", bodies())
def test_the_read_terms_equal_sympy_s_to_the_last_bit(body):
    C_value, c_value, d_value = body
    for key in KEYS:
        read = map_term_values(key, C_value, c_value, d_value)
        derived = lambdified_values(key, C_value, c_value, d_value)
        assert read.shape == derived.shape, key
        assert np.array_equal(read, derived), (key, body)


@pytest.mark.parametrize(
    "value",
    [
        1000000000000005.0,  # a tie on the 16th digit: mpmath rounds it up, not to even
        -1000000000000005.0,
        1000000000000015.0,
        0.30000000000000004,
        0.1 * 0.3,
        9.999999999999999,
        -0.99999999999999999e-300,
        5e-324,
        1.7976931348623157e308,
        0.5,
        123.0,
    ],
)
def test_floats_read_back_as_sympy_prints_them(value):
    printed = mpmath.libmp.to_str(mpmath.libmp.from_float(value), PRINTED_DIGITS)
    assert printed_float(value) == float(printed)
    assert float(str(sp.Float(value))) == float(printed)  # sympy prints with mpmath's to_str


def test_random_floats_read_back_as_sympy_prints_them():
    rng = np.random.default_rng(7)
    values = rng.normal(size=2000) * 10.0 ** rng.integers(-30, 30, size=2000)
    for value in values.tolist():
        printed = mpmath.libmp.to_str(mpmath.libmp.from_float(value), PRINTED_DIGITS)
        assert printed_float(value) == float(printed), value


def test_the_map_terms_are_read_without_sympy():
    code = (
        "from chargedesign.physical.realism import map_term_values\n"
        f"[map_term_values(k, 1.0, 0.3, 0.1) for k in {KEYS!r}]"
    )
    assert not imports_module(code, "sympy")
