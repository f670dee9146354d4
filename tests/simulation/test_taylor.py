"""The Taylor integrator (heyoka): agreement with DOP853, drift on short runs, the fallback."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.body import Design
from chargedesign.errors import SolverError
from chargedesign.params import Parameters
from chargedesign.simulation import simulate, taylor
from chargedesign.simulation.api import initial_state
from chargedesign.simulation.system import Body, RigidBodySystem

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)
START = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 0.6, "q": -0.4}

pytestmark = pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")


def _charges_design() -> Design:
    """A small body of charges and a dipole (no masses: its inertia is the given C)."""
    rng = np.random.default_rng(5)
    return Design(
        parameters=Parameters(C=0.8),
        fields={"magnetic": (1.0, 0.5), "electric": (0.0, 0.3)},
        charge_positions=rng.uniform(-0.5, 0.5, (4, 3)),
        charge_values=rng.uniform(-1.0, 1.0, 4),
        dipole_positions=[[0.1, 0.2, -0.1]],
        dipole_moments=[[0.0, 0.3, 0.1]],
    )


def test_taylor_is_the_default_and_agrees_with_dop853() -> None:
    kw = {"t_end": 20.0, "initial": START, "samples": 11}
    tay = simulate(PARAMS, **kw)
    dop = simulate(PARAMS, method="DOP853", rtol=1e-13, atol=1e-13, **kw)
    assert tay.method == "taylor" and dop.method == "DOP853"
    assert np.array_equal(tay.times, np.linspace(0.0, 20.0, 11))
    # DOP853 at 1e-13 over 20 s: its own error dominates (about 1e-11 here)
    assert np.max(np.abs(dop.gamma[-1] - tay.gamma[-1])) <= 1e-9
    assert np.max(np.abs(dop.omega[-1] - tay.omega[-1])) <= 1e-9


@pytest.mark.parametrize("route", ["reduced", "direct"])
def test_routes_on_taylor_agree_with_dop853(route: str) -> None:
    design = _charges_design()
    init = {"gamma": [0.2, -0.5, 0.8], "omega": [0.4, 0.1, -0.3]}
    kw = {"t_end": 5.0, "initial": init, "route": route, "samples": 6}
    tay = simulate(design, **kw)
    dop = simulate(design, method="DOP853", rtol=1e-13, atol=1e-13, **kw)
    assert tay.effects == ["lorentz", "electric", "magnetization"]
    assert np.max(np.abs(dop.omega[-1] - tay.omega[-1])) <= 1e-10
    assert np.max(np.abs(dop.gamma[-1] - tay.gamma[-1])) <= 1e-10
    s = tay.summary()
    assert s["I1_rel_drift"] <= 1e-14 and s["I3_max_dev"] <= 1e-14


def test_short_run_keeps_i4_and_energy_at_round_off() -> None:
    s = simulate(PARAMS, t_end=100.0, initial=START).summary()
    assert s["method"] == "taylor" and s["tol"] is None
    assert s["I4_rel_drift"] <= 3e-14
    assert s["I1_rel_drift"] <= 3e-14
    assert s["I3_max"] <= 1e-14


def test_new_body_of_the_same_structure_reuses_the_compiled_integrator() -> None:
    system = RigidBodySystem(Body(parameters=PARAMS), ["theorem"])
    other = RigidBodySystem(Body(parameters=PARAMS.replace(c=0.1, kappa=0.2)), ["theorem"])
    first = taylor.compiled_integrator(system)
    second = taylor.compiled_integrator(other)
    assert second.reused and second.ta is first.ta
    assert not np.array_equal(first.equations.pars, second.equations.pars)
    # and the runtime parameters take effect: the other body moves differently
    y0, _ = initial_state(system, START)
    a = taylor.integrate_taylor(system, y0[None], 5.0, samples=2).states[0, -1]
    b = taylor.integrate_taylor(other, y0[None], 5.0, samples=2).states[0, -1]
    assert np.max(np.abs(a - b)) > 1e-3


def test_fallback_without_heyoka(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(taylor, "heyoka_module", lambda: None)
    result = simulate(PARAMS, t_end=2.0, initial=START)
    assert result.method == "DOP853"
    assert any(n.startswith("taylor: heyoka unavailable") for n in result.notes)
    assert result.summary()["I4_rel_drift"] <= 1e-10


def test_non_finite_state_raises_a_solver_error() -> None:
    system = RigidBodySystem(Body(parameters=PARAMS), ["theorem"])
    y0 = np.array([0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 0.0])  # zero quaternion: gamma is 0/0
    with pytest.raises(SolverError, match=r"taylor \(heyoka\) stopped near t = .*err_nf_state"):
        taylor.integrate_taylor(system, y0[None], 1.0, samples=3)


def test_singular_plane_stops_the_taylor_run() -> None:
    singular = PARAMS.replace(rho=0.2)
    result = simulate(singular, t_end=50.0, initial={"gamma": [0.6, 0.0, 0.8], "omega": [0, 0, 0]})
    assert not result.completed
    event = result.events[0]
    assert event["kind"] == "singular_plane"
    assert abs(abs(event["gamma3"]) - 0.01) <= 1e-12
    assert result.times[-1] == event["t"] < 50.0
