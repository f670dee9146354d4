"""The time rate of any case (``model.frame.time_rescaled``): ``(I, V, l) -> (I, s^2 V, s l)``.

Two independent routes to the same body: the theorem's rate family, written by its parameters
(n, K x s; kappa, lambda, rho x s^2: ``designer.assembly.scaled_parameters``, the frontier's),
and the rescaling of its case, written by the map alone. They must be the same case, exactly;
its claimed integral the same up to the constant factor s^4 (I4 is of weight four in the
rates). And the rescaled case's claim is certified again (a time rescaling keeps an integral).
"""

from __future__ import annotations

from dataclasses import replace

import sympy as sp

from chargedesign.designer.assembly import scaled_parameters
from chargedesign.model.case_file import certify_case
from chargedesign.model.catalogue import theorem_case
from chargedesign.model.frame import time_rescaled
from chargedesign.params import Parameters
from chargedesign.scene.case_file import OMEGA

THEOREM = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9, lam=0.2, rho=0.1)


def test_the_theorems_rate_family_is_the_time_rescaling_of_its_case() -> None:
    s = 2.0  # a power of two: the parameters' float products are their exact decimals
    rescaled = time_rescaled(theorem_case(THEOREM).at_values(), s)
    direct = theorem_case(scaled_parameters(THEOREM, s)).at_values()
    assert rescaled.inertia == direct.inertia
    assert sp.simplify(rescaled.V - direct.V) == 0
    assert all(sp.simplify(a - b) == 0 for a, b in zip(rescaled.mu, direct.mu, strict=True))
    assert sp.simplify(direct.integral - 16 * rescaled.integral) == 0  # s^4 = 16
    assert rescaled.level == direct.level == 0


def test_a_rescaled_case_keeps_its_integral_and_scales_its_level() -> None:
    """The theorem's case at s = 2: its F(omega / s, gamma) is certified again, exactly."""
    case = theorem_case(THEOREM).at_values()
    rescaled = time_rescaled(case, 2.0)
    assert certify_case(rescaled).holds
    # omega -> omega / s in the integral, gamma unchanged
    p, _, _ = OMEGA
    assert rescaled.integral == sp.expand(case.integral.xreplace({w: w / 2 for w in OMEGA}))
    assert p in rescaled.integral.free_symbols
    # I3 = (I omega + l).gamma goes to s I3: a level L to s L
    leveled = replace(case, level=sp.Rational(1, 3))
    assert time_rescaled(leveled, 2.0).level == sp.Rational(2, 3)
