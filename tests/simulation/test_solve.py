"""The integrator service (``simulation.integrate.solve``) against closed forms: every
method on the harmonic oscillator, a blow-up refused, the Taylor fallback named."""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp

from chargedesign.errors import SolverError
from chargedesign.simulation import taylor
from chargedesign.simulation.integrate import SOLVE_METHODS, Symbolic, solve

X, V = sp.symbols("x v")
OSCILLATOR = Symbolic((X, V), (V, -X))
T_END = 3.0


def oscillator(_t: float, y: np.ndarray) -> np.ndarray:
    return np.stack([y[..., 1], -y[..., 0]], axis=-1)


def exact(t: np.ndarray) -> np.ndarray:
    return np.column_stack([np.cos(t), -np.sin(t)])


@pytest.mark.parametrize("method", ["taylor", "DOP853", "RK45", "Radau"])
def test_every_adaptive_method_follows_the_closed_form(method: str) -> None:
    t = np.linspace(0.0, T_END, 31)
    out = solve(
        oscillator,
        np.array([1.0, 0.0]),
        (0.0, T_END),
        t_eval=t,
        method=method,
        symbolic=OSCILLATOR,
        rtol=1e-10,
        atol=1e-12,
    )
    assert out.method == method and np.array_equal(out.t, t)
    assert np.abs(out.y - exact(t)).max() < (1e-13 if method == "taylor" else 1e-7)


def test_taylor_runs_a_batch_of_independent_starts() -> None:
    starts = np.array([[1.0, 0.0], [2.0, 0.0]])
    t = np.linspace(0.5, T_END, 6)  # a grid not starting at t0
    out = solve(None, starts, (0.0, T_END), t_eval=t, method="taylor", symbolic=OSCILLATOR)
    assert out.y.shape == (6, 2, 2)
    assert np.abs(out.y[:, 1] - 2.0 * exact(t)).max() < 1e-13


def test_fixed_dop853_is_eighth_order() -> None:
    errors = [
        abs(
            solve(
                oscillator, np.array([1.0, 0.0]), (0.0, T_END), method="fixed-DOP853", max_step=h
            ).end[0]
            - np.cos(T_END)
        )
        for h in (0.3, 0.15)
    ]
    assert 7.0 < np.log2(errors[0] / errors[1]) < 9.5


def test_a_blow_up_is_refused_with_its_name() -> None:
    with pytest.raises(SolverError, match="blow-up: DOP853 failed near t ="):
        solve(lambda _t, y: y**2, np.array([1.0]), (0.0, 2.0), what="blow-up")


def test_taylor_without_heyoka_falls_back_and_says_so(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(taylor, "available", lambda: False)
    out = solve(
        oscillator,
        np.array([1.0, 0.0]),
        (0.0, T_END),
        method="taylor",
        symbolic=OSCILLATOR,
        rtol=1e-10,
        atol=1e-12,
    )
    assert out.method == "DOP853" and out.note is not None and "heyoka" in out.note
    assert abs(out.end[0] - np.cos(T_END)) < 1e-8


def test_bad_requests_are_refused() -> None:
    with pytest.raises(ValueError, match="symbolic"):
        solve(oscillator, np.array([1.0, 0.0]), (0.0, 1.0), method="taylor")
    with pytest.raises(ValueError, match="not one of"):
        solve(oscillator, np.array([1.0, 0.0]), (0.0, 1.0), method="euler")
    with pytest.raises(ValueError, match="max_step"):
        solve(oscillator, np.array([1.0, 0.0]), (0.0, 1.0), method="fixed-DOP853")
    assert "fixed-DOP853" in SOLVE_METHODS
