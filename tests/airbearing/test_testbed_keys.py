"""The ``[testbed]`` table declared once (chargedesign.scene.keys.TESTBED): the typed options,
their defaults, the refusals and testbed.json's sources all follow from the declarations."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from chargedesign.airbearing.loop import initial_state
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.physical.drag import bearing_drag, cup_drag
from chargedesign.scene.keys import KEY, TESTBED, declared, key_names
from chargedesign.scene.testbed import SOURCES, TestbedOptions


def test_the_options_are_the_declared_keys_in_their_order():
    assert tuple(f.name for f in dataclasses.fields(TestbedOptions)) == key_names("testbed")


def test_the_options_hold_the_declared_defaults_and_none_where_derived():
    options = TestbedOptions()
    for key in TESTBED:
        value = getattr(options, key.name)
        assert value == (key.default if key.has_default else None), key.name
        assert key.source or key.name in (KEY.wheels,), f"{key.name}: a default without source"


def test_a_table_of_every_declared_default_reads_as_the_empty_table():
    given = {
        k.name: list(k.default) if isinstance(k.default, tuple) else k.default for k in TESTBED
    }
    given = {k: v for k, v in given.items() if declared("testbed", k).has_default}
    assert TestbedOptions.from_table(given) == TestbedOptions.from_table({})


@pytest.mark.parametrize(
    ("table", "message"),
    [
        # a rate is positive first, then within the declared range
        ({"rate_Hz": 0}, "testbed.rate_Hz: expected a number > 0, got 0"),
        ({"rate_Hz": 0.05}, "testbed.rate_Hz: expected a control rate in 0.1..100000 Hz, got 0.05"),
        (
            {"tilt_limit_deg": 0},
            "testbed.tilt_limit_deg: expected a tilt limit in (0, 180] deg, got 0",
        ),
        ({"wheel_margin": 0}, "testbed.wheel_margin: expected a margin >= 1, got 0"),
        ({"imbalance_m": -1}, "testbed.imbalance_m: expected a number >= 0, got -1"),
        ({"t_end_s": 0}, "testbed.t_end_s: expected a number > 0, got 0"),
        ({"encoder_counts": 3}, "testbed.encoder_counts: expected an integer >= 16, got 3"),
        ({"seeds": 10_001}, "testbed.seeds: expected an integer <= 10000, got 10001"),
        ({"seeds": 2.5}, "testbed.seeds: expected an integer, got 2.5"),
        (
            {"requirement_rates_Hz": [0.01]},
            "testbed.requirement_rates_Hz: expected 1 to 12 rates in 0.1..100000 Hz, got [0.01]",
        ),
        (
            {"platform_inertia_kg_m2": [[1, 2, 0], [0, 1, 0], [0, 0, 1]]},
            "testbed.platform_inertia_kg_m2: expected a symmetric 3x3 inertia matrix (kg m^2), "
            "got [[1, 2, 0], [0, 1, 0], [0, 0, 1]]",
        ),
        ({"wheels": "five"}, "testbed.wheels: expected one of orthogonal, pyramid, got 'five'"),
    ],
)
def test_the_refusals_are_the_declared_ones(table: dict, message: str):
    with pytest.raises(InputError) as info:
        TestbedOptions.from_table(table)
    assert str(info.value) == message


def test_the_sources_are_the_declared_ones():
    assert SOURCES[KEY.drag_N_m_s] == declared("testbed", KEY.drag_N_m_s).source
    assert SOURCES["platform"] == declared("testbed", KEY.platform_mass_kg).source
    assert SOURCES["wheels"] == declared("testbed", KEY.max_torque_N_m).source
    assert all(text for text in SOURCES.values())


def test_the_derived_drag_is_the_film_s():
    options = TestbedOptions()
    assert options.drag == bearing_drag(options.bearing_radius_m, options.bearing_gap_m)
    sphere = TestbedOptions.from_table({KEY.bearing: "full_sphere", KEY.platform_mass_kg: 3.0})
    assert sphere.drag == cup_drag(sphere.platform_radius_m, sphere.bearing_gap_m)
    # the cup covers part of the ball: its drag is below a hemisphere's of the same radius
    assert 0.0 < sphere.drag < bearing_drag(sphere.platform_radius_m, sphere.bearing_gap_m)
    assert math.isfinite(sphere.drag)


def test_a_start_on_the_singular_plane_is_refused_at_reading_and_misuse_below():
    """gamma3 = 0 is the user's error when the scene is read (one line naming the key); the
    loop's ``initial_state`` trusts its caller and raises a plain ValueError."""
    with pytest.raises(InputError) as info:
        TestbedOptions.from_table(
            {KEY.initial_gamma: [1.0, 0.0, 0.0], KEY.initial_p: 0.1, KEY.initial_q: 0.1}
        )
    assert str(info.value) == (
        "testbed.initial_gamma: expected a vector with gamma3 != 0 (r is solved from I3 = 0), "
        "got [1.0, 0.0, 0.0]"
    )
    with pytest.raises(ValueError) as misuse:
        initial_state(Parameters(C=0.5), np.array([1.0, 0.0, 0.0]), 0.1, 0.1)
    assert not isinstance(misuse.value, InputError)
