"""Compiled numeric evaluators against exact values of the symbolic model."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

from chargedesign.errors import InputError
from chargedesign.model import evaluators as ev
from chargedesign.model.case import GAMMA, PARAMETER_SYMBOLS, STATE_SYMBOLS, symbolic_case
from chargedesign.model.certificate import to_ring
from chargedesign.model.equations import equations_of_motion
from chargedesign.params import Parameters

DATA = Path(__file__).parent / "data"
EPS = np.finfo(float).eps
#: rounding error allowed, in units of the expanded expression's sum |terms| at the point
TOL = 8 * EPS

_spec = importlib.util.spec_from_file_location("make_golden", DATA / "make_golden.py")
assert _spec is not None and _spec.loader is not None
make_golden = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(make_golden)

GOLDEN = json.loads((DATA / "golden_model.json").read_text())
QUANTITIES = list(ev.OUTPUT_WIDTH)


def _call(quantity: str, states: np.ndarray, params: Parameters) -> np.ndarray:
    arg = states[..., 3:] if quantity in ev.GAMMA_ONLY else states
    return np.asarray(getattr(ev, quantity)(arg, params))


@pytest.mark.parametrize("case", GOLDEN["cases"], ids=lambda c: c["name"])
def test_against_golden_values(case: dict) -> None:
    params = Parameters.from_mapping(case["parameters"])
    states = np.array(case["states"])
    for quantity in QUANTITIES:
        gold = np.array(case["values"][quantity])
        scale = np.array(case["scales"][quantity])
        batch = _call(quantity, states, params).reshape(gold.shape)
        assert np.all(np.isfinite(batch))
        assert np.all(np.abs(batch - gold) <= TOL * scale), (quantity, case["name"])
        for i in range(len(states)):  # the single-item path (pure Python floats)
            one = _call(quantity, states[i], params).reshape(gold[i].shape)
            assert np.all(np.abs(one - gold[i]) <= TOL * scale[i]), (quantity, i)


def test_golden_covers_the_hard_regimes() -> None:
    names = {c["name"] for c in GOLDEN["cases"]}
    assert {"scale_1e-06_singular", "scale_1e+06_singular", "unit"} <= names
    near_plane = [
        c
        for c in GOLDEN["cases"]
        if c["parameters"]["rho"] != 0 and any(abs(s[5]) == 1e-3 for s in c["states"])
    ]
    assert len(near_plane) >= 5


@pytest.fixture(scope="module")
def rings() -> dict[str, list]:
    case = symbolic_case()
    exprs = {
        "potential": [case.V],
        "potential_gradient": [sp.diff(case.V, x) for x in GAMMA],
        "gyroscopic": list(case.mu),
        "angular_potential": list(case.l),
        "rhs": list(equations_of_motion()),
        "integrals": [case.I1, case.I2, case.I3, case.I4],
    }
    return {k: [to_ring(e) for e in v] for k, v in exprs.items()}


finite = st.floats(-2.0, 2.0, allow_nan=False)


@settings(max_examples=25, deadline=None)
@given(
    omega=st.tuples(finite, finite, finite),
    direction=st.tuples(finite, finite, finite).filter(lambda v: 0.1 < np.linalg.norm(v)),
    params=st.tuples(*[finite] * 7),
    C=st.floats(0.01, 100.0),
    scale_exp=st.integers(-6, 6),
)
def test_random_points_against_exact_symbolic_values(
    rings: dict[str, list], omega, direction, params, C, scale_exp
) -> None:
    s = 10.0**scale_exp
    gamma = np.array(direction) / np.linalg.norm(direction)
    if abs(gamma[2]) < 1e-3:
        gamma[2] = 1e-3
    state = np.concatenate([s * np.array(omega), gamma])
    c, d, n, K, kappa, lam, rho = params
    pars = Parameters(
        C=C, c=c, d=d, n=n * s, K=K * s, kappa=kappa * s * s, lam=lam * s * s, rho=rho * s * s
    )
    point = {sym: make_golden.exact(v) for sym, v in zip(STATE_SYMBOLS, state, strict=True)}
    point.update(
        {
            sym: make_golden.exact(v)
            for sym, v in zip(PARAMETER_SYMBOLS, ev.parameter_tuple(pars), strict=True)
        }
    )
    for quantity in QUANTITIES:
        exact = [make_golden.evaluate(e, point) for e in rings[quantity]]
        gold = np.array([v for v, _ in exact])
        scale = np.array([sc for _, sc in exact])
        if quantity == "rhs":
            # omega x (omega I) cancels exactly in exact arithmetic but not in floats: its
            # terms (size |omega|^2) belong to the rounding scale of omega'
            scale[:3] += np.sum(np.abs(state[:3])) ** 2
        value = _call(quantity, state, pars).reshape(-1)
        assert np.all(np.abs(value - gold) <= TOL * scale + 1e-300), quantity


def test_single_and_batch_shapes_agree() -> None:
    params = Parameters(C=2.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9, lam=0.2, rho=0.1)
    rng = np.random.default_rng(3)
    states = rng.normal(size=(5, 6))
    states[:, 3:] /= np.linalg.norm(states[:, 3:], axis=1, keepdims=True)
    for quantity, width in ev.OUTPUT_WIDTH.items():
        batch = _call(quantity, states, params)
        assert batch.shape == ((5,) if width == 1 else (5, width))
        single = np.array([_call(quantity, s, params) for s in states])
        assert np.allclose(single, batch, rtol=4 * EPS, atol=0.0)
        assert _call(quantity, states[0], params).shape == (() if width == 1 else (width,))


def test_unchecked_fast_paths_match_the_checked_one() -> None:
    params = Parameters(C=1.5, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
    rng = np.random.default_rng(4)
    states = rng.normal(size=(4, 6))
    checked = ev.rhs(states, params)
    pt = ev.parameter_tuple(params)
    assert np.array_equal(ev.rhs_unchecked(states.ravel(), pt), checked.ravel())
    assert np.allclose(ev.rhs_unchecked(states[1], pt), checked[1], rtol=4 * EPS, atol=0)
    fun = ev.rhs_function(params)
    assert np.allclose(fun(0.0, states[2]), checked[2], rtol=4 * EPS, atol=0)
    fun4 = ev.rhs_function(params, batch=4)
    assert np.array_equal(fun4(0.0, states.ravel()), checked.ravel())


def test_regular_parameters_are_finite_on_the_plane_gamma3_zero() -> None:
    params = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
    state = np.array([0.1, -0.2, 0.3, 0.6, 0.8, 0.0])
    assert np.all(np.isfinite(ev.rhs(state, params)))
    assert np.all(np.isfinite(ev.integrals(state, params)))


def test_invalid_inputs_raise_input_errors() -> None:
    params = Parameters(C=1.0, lam=0.1)
    with pytest.raises(InputError, match="gamma3 != 0"):
        ev.potential([0.6, 0.8, 0.0], params)
    with pytest.raises(InputError, match="finite"):
        ev.rhs([0.1, np.nan, 0.0, 0.0, 0.0, 1.0], params)
    with pytest.raises(InputError, match="shape"):
        ev.gyroscopic(np.zeros((4, 2)), params)
    with pytest.raises(InputError, match="shape"):
        ev.integrals([[0.0] * 6, [0.0] * 5], params)
    with pytest.raises(InputError, match="Parameters"):
        ev.potential([0.0, 0.0, 1.0], {"C": 1.0})  # type: ignore[arg-type]
    with pytest.raises(InputError, match="overflows"):
        ev.integrals([1e200, 0.0, 0.0, 0.0, 0.6, 0.8], Parameters(C=1.0))
    with pytest.raises(InputError, match="overflows"):
        ev.integrals([[1e200, 0.0, 0.0, 0.0, 0.6, 0.8]] * 2, Parameters(C=1.0))
