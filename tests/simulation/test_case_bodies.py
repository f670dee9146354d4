"""``simulate`` of a case of (ep) of any inertia: the reduced model of a case scene (no body).

Independent routes:
- heyoka's Taylor route integrates the torque derived from the Lagrangian
  (:func:`chargedesign.model.case_numeric.lagrangian_torque`); scipy's DOP853 integrates the
  NumPy route's ``gamma x grad V + mu x omega`` with mu by the paper's (mu) formula;
- the equations derived from the Lagrangian are compared exactly with the theorem's own
  (:func:`chargedesign.model.equations.equations_of_motion`) and with (ep) of every
  catalogue case;
- the simulation's right-hand side is compared with the symbolic equations at random states.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import sympy as sp
from case_tables import kowalevski_table

from chargedesign.errors import InputError
from chargedesign.model import case as model_case
from chargedesign.model.case import GAMMA, OMEGA
from chargedesign.model.case_file import case_equations as ep_equations
from chargedesign.model.case_numeric import case_functions, lagrangian_torque
from chargedesign.model.catalogue import catalogue_cases
from chargedesign.model.equations import equations_of_motion
from chargedesign.params import Parameters
from chargedesign.scene import load_scene
from chargedesign.simulation import simulate
from chargedesign.simulation.system import Body, RigidBodySystem, quaternion_gamma

#: the three cases of the brief, each with a start (on its level for a conditional claim)
KOWALEVSKI = kowalevski_table("kowalevski-k", 0.3, 2.5)
LAGRANGE = """
[case]
name = "lagrange-2-2-1.5"
inertia = [2, 2, 1.5]
V = "3*gamma3"
l = ["0", "0", "0"]
integral = "r"
level = "general"
"""
#: Goriachev-Chaplygin (A = B = 4C, V linear, F cubic on I3 = 0): polynomial, non-singular
GORIACHEV_CHAPLYGIN = """
[case]
name = "goriachev-chaplygin-k"
inertia = ["4*C", "4*C", "C"]
V = "C*a*gamma1"
l = ["0", "0", "0"]
integral = "r*(p**2 + q**2) - a*p*gamma3"
level = 0
[case.parameters]
C = 1.5
a = 0.7
"""
#: Sretensky's gyrostat (l along the axis) on I3 = 0: a case with l != 0
SRETENSKY = """
[case]
name = "sretensky-k"
inertia = ["4*C", "4*C", "C"]
V = "C*a*gamma1"
l = ["0", "0", "C*k"]
integral = "(r - k)*(p**2 + q**2) - a*p*gamma3"
level = 0
[case.parameters]
C = 1.5
a = 0.7
k = 0.4
"""
GENERAL_START = (
    "\n[initial]\ngamma = [0.3, 0.4, 0.866]\nomega = [0.5, -0.3, 0.8]\n[simulation]\nt_end = 10\n"
)
LEVEL_START = (
    '\n[initial]\ngamma = [0.3, 0.4, 0.866]\nlevel = "I3=0"\np = 0.5\nq = -0.3\n'
    "[simulation]\nt_end = 10\n"
)
CASES = {
    "kowalevski": KOWALEVSKI + GENERAL_START,
    "lagrange": LAGRANGE + GENERAL_START,
    "goriachev-chaplygin": GORIACHEV_CHAPLYGIN + LEVEL_START,
    "sretensky": SRETENSKY + LEVEL_START,
}
#: DOP853's tolerances for the reference run
RK_TOL = 1e-13


def _scene(tmp_path: Path, text: str, name: str = "case.toml") -> object:
    path = tmp_path / name
    path.write_text(text, "utf-8")
    return load_scene(path)


@pytest.mark.parametrize("name", sorted(CASES))
def test_taylor_and_runge_kutta_agree_and_conserve_the_cases_integrals(
    tmp_path: Path, name: str
) -> None:
    scene = _scene(tmp_path, CASES[name])
    taylor = simulate(scene, samples=201)
    rk = simulate(scene, method="DOP853", rtol=RK_TOL, atol=RK_TOL, samples=201)
    assert taylor.effects == ["theorem"] and taylor.method == "taylor"
    # DOP853 reports its step ends: the runs are compared at t_end
    assert taylor.times[-1] == rk.times[-1] == 10.0
    # the two routes (Lagrangian torque in heyoka, (mu) torque in NumPy) agree over 10 s
    # (measured here: 1.5e-13 to 2.8e-12)
    assert np.max(np.abs(taylor.omega[-1] - rk.omega[-1])) < 1e-10
    assert np.max(np.abs(taylor.gamma[-1] - rk.gamma[-1])) < 1e-10
    for run, bound in ((taylor, 1e-13), (rk, 1e-11)):
        monitors = run.monitors
        assert monitors["F"]["integral"] is True
        assert monitors["F"]["drift"] <= bound, (name, run.method, monitors["F"])
        assert monitors["energy"]["drift"] <= bound
        assert monitors["I3"]["drift"] <= bound
        assert monitors["I4"]["integral"] is False
    # the motion is not trivial: omega moves by order one
    assert np.ptp(taylor.omega, axis=0).max() > 0.1


def test_the_inertia_is_the_cases_not_the_theorems(tmp_path: Path) -> None:
    """Lagrange's top diag(2, 2, 1.5): r is conserved (A = B) and the kinetic energy uses the
    case's moments (a diag(2C, 2C, C) body would make r move)."""
    run = simulate(_scene(tmp_path, CASES["lagrange"]), samples=101)
    assert np.ptp(run.omega[:, 2]) < 1e-13
    kinetic = 0.5 * np.einsum("ij,j,ij->i", run.omega, [2.0, 2.0, 1.5], run.omega)
    np.testing.assert_allclose(run.kinetic, kinetic, rtol=1e-15)
    assert run.monitors["lagrange"]["integral"] is False  # the theorem effect: F says it


def test_a_false_claim_drifts_where_the_true_one_holds(tmp_path: Path) -> None:
    """Kowalevski's integral with a = 2 where V has a = 2.5: the same motion, F drifts."""
    wrong = KOWALEVSKI.replace("a*gamma1)**2", "2*gamma1)**2").replace("a*gamma2)", "2*gamma2)")
    assert wrong != KOWALEVSKI
    true = simulate(_scene(tmp_path, KOWALEVSKI + GENERAL_START), samples=101)
    false = simulate(_scene(tmp_path, wrong + GENERAL_START, "wrong.toml"), samples=101)
    np.testing.assert_array_equal(true.omega, false.omega)
    assert true.monitors["F"]["drift"] <= 1e-13
    assert false.monitors["F"]["drift"] > 1e-2


def test_a_conditional_integral_off_its_level_is_no_integral_and_drifts(tmp_path: Path) -> None:
    off = GORIACHEV_CHAPLYGIN + LEVEL_START.replace('"I3=0"', '"I3=0.5"')
    run = simulate(_scene(tmp_path, off), samples=101)
    F = run.monitors["F"]
    assert F["integral"] is False and "I3 = 0" in F["reason"]
    values = run.monitors["F"]
    assert values["drift"] is None or values["drift"] > 1e-3
    # measured on the motion itself: the cubic changes by order one off the level
    functions = case_functions(_scene(tmp_path, off, "off.toml").case)
    series = functions.integral(np.column_stack([run.omega, run.gamma]))
    assert np.ptp(series) > 1e-2 * np.max(np.abs(series))
    assert run.monitors["energy"]["drift"] <= 1e-13


def test_a_singular_case_is_refused_in_one_line(tmp_path: Path) -> None:
    text = (
        '[case]\nname = "goriachev"\ninertia = ["4*C", "4*C", "C"]\n'
        'V = "C*(a*gamma1 + b/gamma3**2)"\nl = ["0", "0", "0"]\n'
        'integral = "r*(p**2 + q**2) - a*p*gamma3 + 2*b*q*gamma2/gamma3**2"\nlevel = 0\n'
        "[case.parameters]\nC = 1\na = 1\nb = 1\n" + LEVEL_START
    )
    with pytest.raises(InputError) as caught:
        simulate(_scene(tmp_path, text))
    message = str(caught.value)
    assert "singular where gamma3 = 0" in message and "\n" not in message


def _theorem_parameters(case: object) -> dict[sp.Symbol, sp.Rational]:
    names = {"C": model_case.C, "c": model_case.c, "d": model_case.d, "n": model_case.n}
    names |= {"K": model_case.K, "kappa": model_case.kappa, "lambda": model_case.lam}
    names |= {"rho": model_case.rho}
    return {names[k]: v for k, v in case.parameters.items()}  # type: ignore[attr-defined]


def case_equations(case: object) -> sp.Matrix:
    """``(p', q', r', gamma1', gamma2', gamma3')`` (6, 1) from the case's Lagrangian: ``I omega'
    = (I omega) x omega + N`` with :func:`lagrangian_torque`'s ``N`` (the route the Taylor
    method integrates), against model/case_file.py's (ep) from the paper's (mu)."""
    inertia = [sp.sympify(m) for m in case.inertia]  # type: ignore[attr-defined]
    I_omega = sp.Matrix([m * w for m, w in zip(inertia, OMEGA, strict=True)])
    kinetic, N = I_omega.cross(OMEGA), lagrangian_torque(case)
    omega_dot = [sp.expand((kinetic[i] + N[i]) / inertia[i]) for i in range(3)]
    return sp.Matrix(omega_dot + [sp.expand(e) for e in GAMMA.cross(OMEGA)])


def test_the_lagrangian_equations_are_the_theorems_for_the_theorems_case() -> None:
    """The paper's case entered as a case file: the equations derived from its L agree
    exactly with the model's own equations of motion at the file's parameters."""
    (case,) = [c for c in catalogue_cases() if c.name == "yehia-elmandouh"]
    derived = case_equations(case)
    theorem = equations_of_motion().xreplace(_theorem_parameters(case))
    assert derived.shape == theorem.shape == (6, 1)
    for a, b in zip(derived, theorem, strict=True):
        assert sp.cancel(sp.together(a - b)) == 0


def test_the_lagrangian_equations_are_ep_for_every_catalogue_case() -> None:
    """Derived from L (Euler-Poincare) against (ep) with the paper's (mu), case by case."""
    cases = catalogue_cases()
    assert len(cases) >= 10
    for case in cases:
        difference = case_equations(case) - ep_equations(case)
        assert all(sp.cancel(sp.together(e)) == 0 for e in difference), case.name


def test_the_right_hand_side_is_the_symbolic_one_at_random_states(tmp_path: Path) -> None:
    """The NumPy route of a general inertia (Sretensky's gyrostat, diag(6, 6, 1.5), l != 0)
    at random states against the equations derived from L."""
    scene = _scene(tmp_path, CASES["sretensky"])
    functions = case_functions(scene.case)
    A, B, C = (float(m) for m in functions.case.inertia)
    system = RigidBodySystem(
        Body(parameters=Parameters(C=C)), ["theorem"], inertia=[A, B, C], case=functions
    )
    assert system.general_inertia and (A, B, C) == (6.0, 6.0, 1.5)
    rhs = sp.lambdify((*OMEGA, *GAMMA), list(case_equations(functions.case)), "numpy")
    rng = np.random.default_rng(7)
    quats = rng.normal(size=(50, 4))
    states = np.hstack([rng.normal(size=(50, 3)), quats])
    gamma = quaternion_gamma(quats)
    got = system.derivatives(states)
    want = np.array([rhs(*s[:3], *g) for s, g in zip(states, gamma, strict=True)], dtype=float)
    np.testing.assert_allclose(got[:, :3], want[:, :3], rtol=1e-13, atol=1e-13)
