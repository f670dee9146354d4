"""Integral monitors (what is reported and why) and the inertia consistency check."""

from __future__ import annotations

import numpy as np
import pytest

# a Kowalevski top (A = B = 2C = 8 kg m^2, centre of mass on the x axis), as the bench runs it
from chargedesign.bench.simulate import KOWALEVSKI_SCENE as KOWALEVSKI
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.scene import scene_from_dict
from chargedesign.simulation import simulate, taylor
from chargedesign.simulation.monitors import MONITORS, parse_monitors
from chargedesign.simulation.system import Body, body_mass_points, inertia_mismatch

PARAMS = Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9)


@pytest.mark.skipif(not taylor.available(), reason="heyoka is not installed")
def test_kowalevski_top_reports_kowalevski_and_no_i4() -> None:
    scene = scene_from_dict({**KOWALEVSKI, "simulation": {"t_end": 100.0}})
    result = simulate(scene)
    s = result.summary()
    assert any("C = 4 kg m^2 from the masses" in n for n in s["notes"])
    assert s["parameters"]["C"] == pytest.approx(4.0, rel=1e-15)
    assert s["I4_rel_drift"] is None and "I4 is no integral" in s["I4_reason"]
    kow = s["monitors"]["kowalevski"]
    assert kow["integral"] is True and kow["drift"] <= 1e-13
    assert s["monitors"]["lagrange"]["drift"] is None  # r is no integral here
    assert s["monitors"]["goriachev_chaplygin"]["reason"].startswith("the Goriachev")
    assert s["I1_rel_drift"] <= 1e-13


def test_monitors_asked_for_are_reported_with_callables() -> None:
    def spin(omega: np.ndarray, gamma: np.ndarray) -> np.ndarray:
        return omega[:, 2]

    s = simulate(
        PARAMS,
        t_end=5.0,
        initial={"gamma": [0.36, 0.48, 0.8], "level": "I3=0.5", "p": 0.6, "q": -0.4},
        monitors=["I4", "kowalevski", spin],
    ).summary()
    assert s["monitors"]["I4"]["integral"] is False and s["monitors"]["I4"]["requested"]
    assert s["I4_rel_drift"] >= 1e-3  # asked for: a number, and the reason beside it
    assert "off the level" in s["I4_reason"]
    assert s["monitors"]["kowalevski"]["drift"] > 1e-6
    assert s["monitors"]["spin"]["requested"] and s["monitors"]["spin"]["drift"] > 0.0


def test_monitor_names_are_validated() -> None:
    assert parse_monitors(["I1", "goriachev"]) == ["energy", "goriachev_chaplygin"]
    assert {"energy", "I3", "I4", "kowalevski", "lagrange"} <= set(MONITORS)
    with pytest.raises(InputError, match=r"simulation\.monitors"):
        parse_monitors(["entropy"])
    with pytest.raises(InputError, match=r"simulation\.monitors"):
        simulate(scene_from_dict({"simulation": {"monitors": "I4"}}))


def test_wrong_c_is_refused_with_a_one_line_reason() -> None:
    scene = scene_from_dict({**KOWALEVSKI, "parameters": {"C": 3.0}})
    with pytest.raises(InputError) as info:
        simulate(scene, t_end=1.0)
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("body: the masses' inertia about O is diag(8, 8, 4)")
    assert "C = 3" in message


def test_mass_points_come_through_one_function() -> None:
    body = Body(
        parameters=Parameters(C=4.0),
        mass_positions=np.array(KOWALEVSKI["body"]["masses"]["positions"], dtype=float),
        mass_values=np.array(KOWALEVSKI["body"]["masses"]["values"]),
    )
    pts, m = body_mass_points(body)
    assert pts.shape == (6, 3) and m.shape == (6,)
    assert inertia_mismatch(body) is None
    wrong = Body(parameters=Parameters(C=4.1), mass_positions=pts, mass_values=m)
    assert "relative mismatch" in str(inertia_mismatch(wrong))


def test_centre_of_mass_off_o_is_refused_when_the_design_claims_v() -> None:
    import dataclasses

    from chargedesign.body import Design

    masses = {
        "mass_positions": [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]],
        "mass_values": [0.25, 0.25, 0.25, 0.25, 0.75, 0.75],
    }
    design = Design(
        parameters=Parameters(C=1.0),
        fields={"gravity": (9.81,)},
        realises=["V", "inertia"],
        **masses,
    )
    assert simulate(design, t_end=0.5).summary()["effects"] == ["gravity"]
    # the same inertia (x-axis masses 0.3 and 0.2), the centre of mass moved to x = 0.04 m
    moved = dataclasses.replace(design, mass_values=[0.3, 0.2, 0.25, 0.25, 0.75, 0.75])
    with pytest.raises(InputError) as info:
        simulate(moved, t_end=0.5)
    message = str(info.value)
    assert "\n" not in message and message.startswith("body: V has a linear term")
    assert "gravity needs it at O" in message
