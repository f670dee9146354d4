"""The shipped evaluators are lambdify's sources, exactly; compiled from them they give
lambdify's functions' values to the last bit, and no sympy is imported to evaluate."""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp
from fresh_process import imports_module

from chargedesign.model import evaluators as ev
from chargedesign.model.case import GAMMA, PARAMETER_SYMBOLS, STATE_SYMBOLS, lam, rho

KEYS = [
    (quantity, singular, module)
    for quantity in ev.OUTPUT_WIDTH
    for singular in (False, True)
    for module in ("numpy", "math")
]


def test_the_shipped_sources_are_the_derived_ones():
    derived = ev.derived_evaluators()
    assert ev.shipped_evaluators_text() == ev.evaluators_text(derived)  # make tables
    assert json.loads(ev.shipped_evaluators_text())["format"] == ev.EVALUATORS_FORMAT
    assert ev.shipped_evaluators() == derived
    assert sorted(derived) == sorted(ev.evaluator_key(*key) for key in KEYS)


def lambdified(quantity: str, singular: bool, module: str):
    """The function lambdify makes, as the evaluators compiled it before they were shipped."""
    expressions = ev.model_expressions(quantity)
    if not singular:
        expressions = [sp.sympify(e).xreplace({lam: 0, rho: 0}) for e in expressions]
    variables = tuple(GAMMA) if quantity in ev.GAMMA_ONLY else STATE_SYMBOLS
    return sp.lambdify(variables + PARAMETER_SYMBOLS, expressions, modules=module, cse=True)


@pytest.mark.parametrize("key", KEYS, ids=lambda key: ev.evaluator_key(*key))
def test_the_shipped_functions_equal_lambdify_s_to_the_last_bit(key):
    quantity, singular, module = key
    rng = np.random.default_rng(3)
    width = 3 if quantity in ev.GAMMA_ONLY else 6
    states = rng.normal(size=(50, width))
    states[:, -3:] /= np.linalg.norm(states[:, -3:], axis=1)[:, None]
    params = rng.normal(size=(50, 8)) * [1e-3, 1, 1, 1, 1, 1, 1, 1]
    if not singular:
        params[:, 6:] = 0.0
    ours, theirs = ev.compiled(quantity, singular, module), lambdified(quantity, singular, module)
    for state, pt in zip(states, params, strict=True):
        if module == "math":
            a, b = ours(*state.tolist(), *pt.tolist()), theirs(*state.tolist(), *pt.tolist())
        else:
            a, b = ours(*state[:, None], *pt), theirs(*state[:, None], *pt)
        assert np.array_equal(np.asarray(a, dtype=float), np.asarray(b, dtype=float))


def test_without_shipped_sources_they_are_derived(monkeypatch):
    monkeypatch.setattr(ev, "shipped_evaluators", dict)
    derived = ev.compiled.__wrapped__("gyroscopic", False, "math")
    assert derived(0.1, 0.2, 0.9, 1.0, 0.3, 0.1, 0.5, 2.0, 0.0, 0.0, 0.0) == ev.compiled(
        "gyroscopic", False, "math"
    )(0.1, 0.2, 0.9, 1.0, 0.3, 0.1, 0.5, 2.0, 0.0, 0.0, 0.0)


def test_evaluating_the_model_does_not_import_sympy():
    code = (
        "import numpy as np\n"
        "from chargedesign.model import evaluators as ev\n"
        "from chargedesign.params import Parameters\n"
        "p = Parameters(C=1.0, c=0.3, d=0.1, n=0.5, K=2.0, kappa=0.2)\n"
        "g = np.array([[0.0, 0.6, 0.8], [0.6, 0.0, 0.8]])\n"
        "ev.potential(g, p), ev.gyroscopic(g, p), ev.rhs(np.hstack([g, g]), p)"
    )
    assert not imports_module(code, "sympy")
