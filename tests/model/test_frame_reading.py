"""The frame reading of any case (model/frame.py): the exact theorem for symbolic inertia,
the theorem's n as its special case (today's Larmor certificate), and a numeric run in
turning axes against the read case."""

from __future__ import annotations

import json

import numpy as np
import pytest
import sympy as sp

from chargedesign.cli import main
from chargedesign.model.case import GAMMA, STATE_SYMBOLS, symbolic_case
from chargedesign.model.case_file import case_equations
from chargedesign.model.equations import equations_of_motion
from chargedesign.model.frame import (
    FRAME_CHECKS,
    N,
    certify_frame,
    frame_reading,
    prove_frame_reading,
)
from chargedesign.model.larmor import certify_larmor
from chargedesign.scene.case_file import Case, case_from_table, mu_from_l
from chargedesign.simulation.integrate import Symbolic, solve

#: a Kowalevski gyrostat: the top with a constant l along its symmetry axis (l.gamma is
#: not constant on the sphere, so the reading's - n l.gamma term is exercised)
GYROSTAT = {
    "name": "kowalevski_gyrostat",
    "inertia": [2, 2, 1],
    "V": "a*gamma1",
    "l": ["0", "0", "k"],
    "integral": "(p**2 - q**2 - a*gamma1)**2 + (2*p*q - a*gamma2)**2",
    "level": "general",
    "parameters": {"a": 1.5, "k": 0.4},
}


def test_the_theorem_holds_for_any_inertia_and_needs_its_l_gamma_term() -> None:
    proof = prove_frame_reading()
    assert proof["diagonal"] and proof["symmetric"]
    assert not proof["without_l_gamma_term"]  # the control fails: the check can fail


def test_the_theorem_n_is_the_frame_reading_of_its_n_zero_case() -> None:
    theorem = symbolic_case()
    at_zero = {N: 0}
    l0 = theorem.l.xreplace(at_zero)
    case0 = Case(
        name="theorem at n = 0",
        inertia=tuple(theorem.inertia[i, i] for i in range(3)),
        V=sp.expand(theorem.V.xreplace(at_zero)),
        l=l0,
        mu=mu_from_l(l0),
        integral=sp.expand(theorem.I4.xreplace(at_zero)),
        level=sp.Integer(0),
    )
    read = frame_reading(case0, N)
    assert (read.l - theorem.l).applyfunc(sp.expand) == sp.zeros(3, 1)
    # V differs by - n^2 C |gamma|^2: a constant on the sphere, no torque
    C = theorem.inertia[2, 2]
    gamma_sq = GAMMA.dot(GAMMA)
    assert sp.cancel(read.V - theorem.V + N**2 * C * gamma_sq) == 0
    # the read case's equations and integral are the theorem's with n, identically
    eqs = case_equations(read)
    assert all(sp.cancel(eqs[i] - equations_of_motion()[i]) == 0 for i in range(6))
    assert sp.cancel(read.integral - theorem.I4) == 0
    certificate = certify_frame(case0)
    assert certificate.holds, certificate.checks
    assert certify_larmor().holds  # today's certificate of the same statement


def test_a_wrong_reading_fails_the_certificate() -> None:
    case = case_from_table(GYROSTAT)
    read = frame_reading(case, sp.Rational(7, 10))
    wrong = frame_reading(case, -sp.Rational(7, 10))
    # the right reading holds; the opposite rate read as this one does not
    assert certify_frame(case, sp.Rational(7, 10)).holds
    assert read.V != wrong.V


@pytest.mark.parametrize("n", [0.7, -1.3])
def test_a_run_in_turning_axes_is_the_read_case(n: float) -> None:
    case = case_from_table(GYROSTAT)
    read = frame_reading(case, n)
    gamma = np.array([0.3, -0.5, 0.8])
    gamma /= np.linalg.norm(gamma)
    x0 = np.array([0.4, -0.2, 0.9, *gamma])
    x1 = np.concatenate([x0[:3] - n * gamma, gamma])
    t = np.linspace(0.0, 10.0, 201)
    fixed, turning = (motion(c, x, t) for c, x in ((case, x0), (read, x1)))
    read_back = fixed[:, :3] - n * fixed[:, 3:]
    assert np.abs(turning[:, :3] - read_back).max() < 1e-10
    assert np.abs(turning[:, 3:] - fixed[:, 3:]).max() < 1e-10


def motion(case: Case, x0: np.ndarray, t: np.ndarray) -> np.ndarray:
    """The case's motion at ``t`` by the integrator service (heyoka, DOP853 without it)."""
    equations = tuple(case_equations(case))
    f = sp.lambdify(STATE_SYMBOLS, list(equations), "math")
    return solve(
        lambda _t, y: np.array(f(*y)),
        x0,
        (0.0, float(t[-1])),
        t_eval=t,
        method="taylor",
        symbolic=Symbolic(tuple(STATE_SYMBOLS), equations),
        rtol=1e-13,
        atol=1e-14,
    ).y


def test_verify_case_json_carries_the_frame_reading(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify", "examples/scenes/kowalevski_case.toml", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["case"]["holds"] is True  # the contract's key, unchanged
    frame = data["frame"]
    assert frame["holds"] is True and frame["rate"] == "n"
    assert set(frame["checks"]) == set(FRAME_CHECKS) and all(frame["checks"].values())
