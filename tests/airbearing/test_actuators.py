"""The actuator catalogue the testbed's window searches: its sourced figures and the choice
of the lightest actuator that covers a need."""

from __future__ import annotations

import numpy as np
import pytest

from chargedesign.airbearing.actuators import catalogue, choose, chosen
from chargedesign.airbearing.verdict import Requirement, window
from chargedesign.physical.sources import source


def by_id(ident: str):
    return next(a for a in catalogue() if a.id == ident)


def test_the_hr16_rows_are_basilisks() -> None:
    """Basilisk's simIncludeRW.py: HR16 at 50/75/100 N m s weighs 9.0/10.4/12.0 kg, 0.2 N m."""
    for momentum, mass in ((50, 9.0), (75, 10.4), (100, 12.0)):
        wheel = by_id(f"honeywell_hr16_{momentum}")
        assert (wheel.torque, wheel.momentum, wheel.mass) == (0.2, float(momentum), mass)
        assert wheel.checked and wheel.kind == "reaction_wheel"


def test_the_catalogue_holds_a_light_strong_wheel_and_a_strong_cmg() -> None:
    light = [a for a in catalogue() if a.torque >= 0.1 and a.mass < 1.5 and a.checked]
    assert light, "a sourced wheel of at least 0.1 N m under 1.5 kg"
    strong = [a for a in catalogue() if a.torque >= 0.5]
    assert strong and all(source(a.key("torque")).checked for a in strong)
    cmg = strong[0]
    assert cmg.kind == "cmg" and cmg.in_development
    assert not cmg.checked  # its momentum and mass were not read: the row says so
    assert len({a.kind for a in catalogue()}) == 2
    assert len({a.name.split()[0] for a in catalogue()}) >= 4  # several makers and classes


def test_every_actuator_writes_the_contract_entry() -> None:
    for a in catalogue():
        d = a.to_dict()
        assert {
            "name",
            "kind",
            "torque_N_m",
            "momentum_N_m_s",
            "mass_kg",
            "power_W",
            "source",
            "checked",
        } <= set(d)
        assert d["kind"] in ("reaction_wheel", "cmg")
        assert d["checked"] == all(source(k).checked for k in a.keys)


def test_the_choice_is_the_lightest_that_covers_the_need() -> None:
    """Brute force over the catalogue, need by need."""
    rng = np.random.default_rng(3)
    torques = 10.0 ** rng.uniform(-4, 0, 200)
    momenta = 10.0 ** rng.uniform(-3, 2.3, 200)
    picked = choose(torques, momenta)
    for t, h, k in zip(torques, momenta, picked, strict=True):
        fits = [a for a in catalogue() if a.torque >= t and a.momentum >= h]
        if fits:
            assert catalogue()[k].mass == min(a.mass for a in fits)
        else:
            worst = [max(t / a.torque, h / a.momentum) for a in catalogue()]
            assert max(t / catalogue()[k].torque, h / catalogue()[k].momentum) == min(worst)
    assert chosen(0.05, 0.5).id == "scirep_2024_wheel"  # 0.9 kg, not a 6 kg Honeywell wheel


def test_the_window_weighs_the_chosen_wheels_against_the_platform() -> None:
    """0.1 N m and 0.5 N m s need the 0.9 kg wheel: three of them on a 10 kg platform are
    0.27 of its mass; at 100 times the torque nothing covers the need."""
    sota = [
        Requirement("wheel_torque_N_m", "capacity", 0.1, 0.2, "N m", "s"),
        Requirement("wheel_momentum_N_m_s", "capacity", 0.5, 100.0, "N m s", "s"),
        Requirement("wheel_mass_kg", "tolerance", 10.0, 36.0, "kg", "s"),
    ]
    w = window(sota, "tabletop", None, 3)
    i, j, k, _ = w.scene_index()
    mass = w.names.index("wheel_mass_kg")
    assert w.feasible[i, j, k, 0]
    assert w.actuator_name((i, j, k, 0)) == by_id("scirep_2024_wheel").name
    assert w.margin[i, j, k, 0] == pytest.approx(
        max(0.1 / 0.1, 0.5 / by_id("scirep_2024_wheel").momentum, 2.7 / 10.0), rel=1e-9
    )
    assert 3 * 0.9 / 10.0 < 1.0 and mass >= 0
    fast = int(np.argmin(np.abs(w.rates - 10.0)))  # torque x100 = 10 N m: beyond every actuator
    assert not w.feasible[fast, j, k, 0]
    assert w.margin[fast, j, k, 0] >= 10.0 / max(a.torque for a in catalogue()) - 1e-9
