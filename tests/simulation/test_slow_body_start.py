"""The default start (p, q) = (0.6, -0.4) 1/s suits the unit-scale case; on a physical body
turning at micro-radians per second it buries the designed torques, and simulate says so."""

from __future__ import annotations

import math
import re

from chargedesign.scene import load_scene, scene_from_dict
from chargedesign.simulation.api import setup_from_source


def slow_note(notes: list[str]) -> str | None:
    found = [x for x in notes if x.startswith("the default start turns at")]
    assert len(found) <= 1
    return found[0] if found else None


def test_the_embedded_default_gets_the_note_with_its_numbers() -> None:
    scene = load_scene(None)
    p = scene.parameters
    note = slow_note(setup_from_source(scene).notes)
    assert note is not None
    # the body's rate, recomputed: 2 max(|n|, |K|, sqrt|kappa|) (lambda = rho = 0 here)
    rate = 2 * max(abs(p.n), abs(p.K), math.sqrt(abs(p.kappa)))
    start = math.hypot(0.6, -0.4)
    assert f"|(p, q)| = {start:.3g} 1/s, {start / rate:.2g} times" in note
    assert f"own rate {rate:.3g} 1/s" in note
    ratio = float(re.search(r"about ([0-9.e+-]+) of the kinetic", note).group(1))
    assert ratio == float(f"{(rate / start) ** 2:.1g}") and ratio < 1e-9


def test_no_note_at_the_unit_scale_or_with_a_given_start() -> None:
    unit = load_scene(None).tables
    data = {k: v for k, v in unit.items() if k != "initial"}
    data["parameters"] = {"C": 1.0, "c": 0.3, "d": -0.4, "n": 0.7, "K": 0.5, "kappa": 0.9}
    assert slow_note(setup_from_source(scene_from_dict(data, "<test>")).notes) is None
    slow = {k: v for k, v in unit.items()}
    slow["initial"] = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 1e-6, "q": 0.0}
    assert slow_note(setup_from_source(scene_from_dict(slow, "<test>")).notes) is None
