"""The default start (p, q) = (0.6, -0.4) 1/s suits the unit-scale case; a physical body
turning at micro-radians per second gets it scaled to its own rate (the embedded default was
started 1.1e5 times too fast and ran 36 million steps), and its run is a number of periods of
the motion's own rate (``simulation.periods``)."""

from __future__ import annotations

import math

import pytest

from chargedesign.errors import InputError
from chargedesign.scene import load_scene, scene_from_dict
from chargedesign.simulation.api import setup_from_source
from chargedesign.validation import motion_rate


def start_note(notes: list[str]) -> str:
    found = [x for x in notes if x.startswith("no [initial]")]
    assert len(found) == 1, notes
    return found[0]


def test_the_embedded_default_starts_at_its_own_rate() -> None:
    scene = load_scene(None)
    p = scene.parameters
    setup = setup_from_source(scene)
    rate = 2 * max(abs(p.n), abs(p.K), math.sqrt(abs(p.kappa)))  # lambda = rho = 0 here
    factor = rate / (2 * math.sqrt(0.9))
    assert setup.initial["p"] == pytest.approx(0.6 * factor, rel=1e-12)
    assert setup.initial["q"] == pytest.approx(-0.4 * factor, rel=1e-12)
    assert "scaled to this body's own rate" in start_note(setup.notes)
    # t_end: 20 periods of the motion's fastest rate (the parameters' and the start's)
    fastest = motion_rate(p, setup.initial)
    assert setup.options.t_end == pytest.approx(20 * 2 * math.pi / fastest, rel=1e-12)
    assert any(n.startswith("t_end = ") and "simulation.periods = 20" in n for n in setup.notes)


def test_the_unit_scale_keeps_the_default_start() -> None:
    unit = load_scene(None).tables
    data = {k: v for k, v in unit.items() if k not in ("initial", "simulation")}
    data["parameters"] = {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9}
    setup = setup_from_source(scene_from_dict(data, "<test>"))
    assert (setup.initial["p"], setup.initial["q"]) == (0.6, -0.4)
    assert "scaled" not in start_note(setup.notes)
    assert setup.options.t_end == 100.0  # the declared default


def test_periods_and_t_end_together_are_refused() -> None:
    data = dict(load_scene(None).tables)
    data["simulation"] = {"periods": 3.0, "t_end": 10.0}
    with pytest.raises(InputError, match="either t_end or periods"):
        _ = scene_from_dict(data, "<test>").simulation
