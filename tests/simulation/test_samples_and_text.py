"""Output samples as asked (or a note that says why not), the result's text and plots."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.simulation import simulate
from chargedesign.simulation.integrate import thin_step_ends
from chargedesign.simulation.result import plot_integrals, plot_poincare, summary_text

THEOREM = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


@pytest.mark.parametrize("n_steps, samples", [(3000, 2001), (2001, 2001), (10**5, 7), (50, 2)])
def test_thinning_keeps_exactly_the_samples_asked(n_steps, samples):
    times = np.cumsum(np.random.default_rng(0).uniform(0.1, 3.0, n_steps))
    keep = thin_step_ends(times, samples)
    assert len(keep) == samples
    assert np.all(np.diff(keep) > 0)
    assert keep[0] == 0 and keep[-1] == n_steps - 1


@pytest.mark.parametrize("method", ["taylor", "DOP853", "gauss-legendre"])
def test_every_method_delivers_the_samples_asked(method):
    """(DOP853 takes about 8 steps per second here: 100 s gives more steps than samples.)"""
    kwargs = {"step": 0.05} if method == "gauss-legendre" else {}
    result = simulate(THEOREM, t_end=100.0, method=method, samples=301, **kwargs)
    assert len(result.times) == 301
    assert not any(n.startswith("simulation.samples") for n in result.notes)


def test_fewer_steps_than_samples_is_said():
    result = simulate(THEOREM, t_end=5.0, method="DOP853", rtol=1e-6, atol=1e-6, samples=2001)
    assert len(result.times) < 2001
    note = [n for n in result.notes if n.startswith("simulation.samples")]
    assert len(note) == 1
    assert f"{len(result.times)} samples, not the 2001 asked" in note[0]


def test_str_is_the_text_the_command_prints():
    result = simulate(THEOREM, t_end=10.0, samples=11)
    text = str(result)
    assert text == summary_text(result.summary())
    assert text.startswith("simulated: theorem (reduced route, taylor")
    assert "I4 relative drift" in text
    assert len(repr(result)) <= 300


def test_plots_draw_into_the_users_axes(tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    result = simulate(THEOREM, t_end=50.0, samples=101, poincare="gamma1")
    _, ax = plt.subplots()
    assert plot_integrals(result, ax=ax) is ax
    assert len(ax.get_lines()) == 4  # the four integrals together
    _, axes = plt.subplots(4, 1)
    drawn = plot_integrals(result, ax=axes)
    assert all(len(a.get_lines()) == 1 for a in drawn)
    _, ax2 = plt.subplots()
    assert plot_poincare(result, ax=ax2) is ax2
    (line,) = ax2.get_lines()
    assert len(line.get_xdata()) == len(result.poincare)
    path = tmp_path / "integrals.png"
    plot_integrals(result, path)
    assert path.read_bytes()[:4] == b"\x89PNG"
    with pytest.raises(InputError, match=r"^ax: expected one Axes or a sequence of 4"):
        plot_integrals(result, ax=axes[:3])
    with pytest.raises(InputError, match=r"^coordinates: "):
        plot_poincare(result, ax=ax2, coordinates=("gamma2", "zz"))
    plt.close("all")
