"""The exact certificate: the theorem's integrals, its special cases, and a counterexample."""

from __future__ import annotations

import random
from fractions import Fraction

import pytest
import sympy as sp

from chargedesign.model import certificate as cert
from chargedesign.model.case import (
    GAMMA,
    OMEGA,
    PARAMETER_SYMBOLS,
    STATE_SYMBOLS,
    C,
    g1,
    g2,
    g3,
    n,
    p,
    q,
    r,
    symbolic_case,
)
from chargedesign.model.equations import equations_of_motion, time_derivative

CHECKS = {
    "I1_conserved",
    "I2_conserved",
    "I3_conserved",
    "I4_conserved_on_level",
    "I4_multiplier_identity",
    "I4_independent",
}


@pytest.mark.parametrize("case", list(cert.CASES))
def test_certificate_holds_in_every_case_of_the_table(case: str) -> None:
    result = cert.certify(case)
    assert result.case == case
    assert set(result.checks) == CHECKS
    assert all(result.checks.values()), result.checks
    assert result.holds is True
    assert result.seconds > 0.0
    assert result.zeroed == tuple(str(s) for s in cert.CASES[case])


def test_certificate_summary_has_the_contract_keys() -> None:
    assert cert.certificate() == {
        "general": True,
        "yehia2003": True,
        "goriachev": True,
        "chaplygin": True,
    }


def test_unknown_case_is_an_input_error() -> None:
    with pytest.raises(ValueError, match="case"):
        cert.certify("kowalevski")


def test_the_reduction_detects_non_integrals() -> None:
    # the same machinery must say "no" where the claim is false
    assert cert.reduced_dI4_dt(2 * C * n) != 0  # the printed zero level
    assert cert.reduced_dI4_dt(-2 * C * n) != 0
    assert cert.reduced_dI4_dt(2 * C * n, zeroed=(n,)) == 0  # same level when n = 0
    perturbed = symbolic_case().I4 + sp.Rational(1, 1000) * p * g1
    assert cert.reduced_dI4_dt(integral=perturbed) != 0
    # a combination of the known integrals is conserved on the level too
    combo = symbolic_case().I4 + 3 * symbolic_case().I1 ** 2 - symbolic_case().I3 * p
    assert cert.reduced_dI4_dt(integral=combo) == 0


def test_level_must_be_a_multiple_of_C() -> None:
    with pytest.raises(ValueError, match="level"):
        cert.r_on_level(n)


def _random_rational(rng: random.Random) -> sp.Rational:
    return sp.Rational(rng.randint(-40, 40), rng.randint(1, 17))


def test_multiplier_identity_by_exact_evaluation_of_the_sympy_expressions() -> None:
    """Second route: dI4/dt = M I3/C + N (|gamma|^2 - 1) at random rational points,
    evaluated from the sympy expressions (not the ring), off the sphere and off the level."""
    level_multiplier, sphere_multiplier = cert.multipliers()
    case = symbolic_case()
    d_i4 = time_derivative(case.I4)
    rng = random.Random(7)
    for _ in range(3):
        values = {s: _random_rational(rng) for s in (*STATE_SYMBOLS, *PARAMETER_SYMBOLS)}
        values[C] = sp.Rational(rng.randint(1, 9), rng.randint(1, 5))
        if values[g3] == 0:
            values[g3] = sp.Rational(1, 3)
        lhs = d_i4.xreplace(values)
        rhs = (level_multiplier * case.I3 / C + sphere_multiplier * (case.I2 - 1)).xreplace(values)
        assert lhs.is_Rational and lhs == rhs
        assert lhs != 0  # a generic point: the identity is not trivially 0 = 0


def test_counterexample_is_exact_nonzero_and_reproducible() -> None:
    ce = cert.counterexample()
    values = {
        s: sp.Rational(ce["parameters"]["lambda" if s.name == "lambda" else s.name])
        for s in PARAMETER_SYMBOLS
    }
    values.update({s: sp.Rational(ce["state"][s.name]) for s in (*OMEGA, *GAMMA)})
    assert sum(values[s] ** 2 for s in GAMMA) == 1
    assert all(values[s] != 0 for s in PARAMETER_SYMBOLS)
    # second route: the sympy expressions, exact
    case = symbolic_case()
    i3 = case.I3.xreplace(values)
    assert i3 == sp.Rational(ce["I3"]) == 2 * values[C] * values[n] != 0
    d_i4 = time_derivative(case.I4).xreplace(values)
    assert d_i4 == sp.Rational(ce["dI4_dt"]) != 0
    assert ce["nonzero"] is True
    assert ce["I3_printed"] == "0"
    assert Fraction(ce["dI4_dt"]) == Fraction(int(d_i4.p), int(d_i4.q))
    assert ce["dI4_dt_float"] == pytest.approx(float(d_i4), rel=1e-15)


def test_dI4_dt_vanishes_exactly_at_a_rational_point_of_the_level() -> None:
    values = cert.rational_level_point(sp.Integer(0), ())
    case = symbolic_case()
    assert case.I3.xreplace(values) == 0
    assert time_derivative(case.I4).xreplace(values) == 0
    # and the first integrals are conserved there as everywhere
    assert time_derivative(case.I1).xreplace(values) == 0


def test_equations_are_derived_and_cached() -> None:
    eqs = equations_of_motion()
    assert eqs is equations_of_motion()
    assert eqs.shape == (6, 1)
    # Poisson equations gamma' = gamma x omega
    assert list(eqs[3:, 0]) == [g2 * r - g3 * q, g3 * p - g1 * r, g1 * q - g2 * p]
    # A = B: r' does not depend on r, and the free part of p' is (B - C)/A q r = q r / 2
    assert not eqs[2].has(r)
    zero = dict.fromkeys(PARAMETER_SYMBOLS[1:], 0)
    assert sp.expand(eqs[0].xreplace(zero)) == q * r / 2
    assert sp.expand(eqs[1].xreplace(zero)) == -p * r / 2
    assert sp.expand(eqs[2].xreplace(zero)) == 0
