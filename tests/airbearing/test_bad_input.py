"""Bad input: one line naming the input and the limit, before the work starts."""

from __future__ import annotations

import numpy as np
import pytest
from testbed_scene import EXAMPLE, SMALL

from chargedesign.airbearing.run import build_testbed
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.physical.drag import bearing_drag
from chargedesign.scene.testbed import TestbedOptions


@pytest.mark.parametrize(
    ("table", "names"),
    [
        ({"platform_mass_kg": 120.0}, "bearing_capacity_kg"),
        ({"gyro_arw_rad_per_sqrt_s": -1e-6}, "testbed.gyro_arw_rad_per_sqrt_s"),
        ({"attitude_noise_rad": -1.0}, "testbed.attitude_noise_rad"),
        ({"rate_Hz": 0.0}, "testbed.rate_Hz"),
        ({"rate_Hz": 100.0, "delay_s": 0.02}, "testbed.delay_s"),
        ({"wheels": "five"}, "testbed.wheels"),
        ({"planned_motions": 0}, "testbed.planned_motions"),
        ({"planned_motions": 2.5}, "testbed.planned_motions"),
        ({"planned_motions": True}, "testbed.planned_motions"),
        ({"planned_motions": 10_000}, "testbed.planned_motions"),
        ({"colour": "red"}, "testbed.colour"),
        ({"seeds": 0}, "testbed.seeds"),
        ({"platform_inertia_kg_m2": [[1, 0, 0], [0, 1, 0], [0, 0, 5]]}, "platform_inertia"),
        ({"requirement_rates_Hz": []}, "testbed.requirement_rates_Hz"),
        ({"initial_gamma": [0.0, 0.0, 0.0]}, "testbed.initial_gamma"),
        ({"initial_gamma": [1.0, 0.0, 0.0]}, "testbed.initial_gamma"),
        ({"seeds": 10000, "t_end_s": 100.0}, "testbed.seeds"),
        ({"t_end_s": 1e9}, "testbed.t_end_s"),
        ({"drag_feedforward": 2.0}, "testbed.drag_feedforward"),
        ({"rate_Hz": "fast"}, "testbed.rate_Hz"),
        ({"bearing": "round"}, "testbed.bearing"),
        ({"tilt_limit_deg": 0.0}, "testbed.tilt_limit_deg"),
        ({"tilt_limit_deg": 200.0}, "testbed.tilt_limit_deg"),
        ({"tilt_limit_deg": 80.0}, "testbed.tilt_limit_deg"),  # the pedestal reaches 90 deg
        ({"pedestal_radius_m": 0.05}, "testbed.pedestal_radius_m"),
        ({"pedestal_radius_m": -0.01}, "testbed.pedestal_radius_m"),
        ({"mount_material": "wood"}, "testbed.mount_material"),
        ({"attitude_sensor": "star_tracker"}, "testbed.attitude_sensor"),
        ({"attitude_rate_Hz": 0.0}, "testbed.attitude_rate_Hz"),
        ({"estimator": "kalman"}, "testbed.estimator"),
        ({"encoder_counts": 3}, "testbed.encoder_counts"),
        ({"max_loop_steps": 10}, "testbed.max_loop_steps"),
        ({"initial_p": 0.1}, "testbed.initial_gamma"),  # a start needs all three
        ({"rate_Hz": 1e6}, "testbed.rate_Hz"),
        ({"t_end_s": 1e-3}, "testbed.t_end_s"),
    ],
)
def test_table_errors_are_one_line(table: dict, names: str) -> None:
    with pytest.raises(InputError) as info:
        TestbedOptions.from_table(table)
    text = str(info.value)
    assert names in text and "\n" not in text


def test_platform_with_ballast_heavier_than_the_bearing() -> None:
    opts = TestbedOptions.from_table({**SMALL, "bearing_capacity_kg": 10.0})
    with pytest.raises(InputError, match=r"bearing_capacity_kg.*heavier than the .*bearing"):
        build_testbed(EXAMPLE, opts, with_requirements=False)


@pytest.mark.parametrize("motions", [1, 4])
def test_wheels_too_weak_for_the_motion(motions: int) -> None:
    opts = TestbedOptions.from_table({**SMALL, "max_torque_N_m": 0.01, "planned_motions": motions})
    with pytest.raises(InfeasibleError) as info:
        build_testbed(EXAMPLE, opts, with_requirements=False)
    text = str(info.value)
    assert "max_torque_N_m" in text and "needs" in text and "initial_p" in text
    assert "motion" in text and "\n" not in text


@pytest.mark.parametrize("motions", [1, 4])
def test_wheels_store_too_little(motions: int) -> None:
    opts = TestbedOptions.from_table(
        {**SMALL, "max_momentum_N_m_s": 1e-4, "planned_motions": motions}
    )
    with pytest.raises(InfeasibleError) as info:
        build_testbed(EXAMPLE, opts, with_requirements=False)
    text = str(info.value)
    assert "max_momentum_N_m_s" in text and "motion" in text and "\n" not in text


def test_too_small_wheels_name_the_motion_that_needs_the_most() -> None:
    """Limits just below the largest planned need fail naming the motion that has it."""
    sized = build_testbed(EXAMPLE, TestbedOptions.from_table(SMALL), with_requirements=False)
    planned = sized.planned
    for key, need, motion in (
        ("max_torque_N_m", planned.torque, planned.torque_motion),
        ("max_momentum_N_m_s", planned.momentum, planned.momentum_motion),
    ):
        opts = TestbedOptions.from_table({**SMALL, key: 0.999 * need})
        with pytest.raises(InfeasibleError) as info:
            build_testbed(EXAMPLE, opts, with_requirements=False)
        text = str(info.value)
        assert text.startswith(f"testbed.{key}") and f"motion {motion} " in text


def test_no_ballast_reaches_a_tiny_inertia() -> None:
    opts = TestbedOptions.from_table(SMALL)
    with pytest.raises(InfeasibleError, match="larger C"):
        build_testbed(EXAMPLE.replace(C=0.01), opts, with_requirements=False)


def test_bearing_drag_is_the_couette_torque() -> None:
    """(4 pi / 3) eta R^4 / h against a direct quadrature over the hemisphere."""
    eta, R, h = 1.8e-5, 0.05, 1e-5
    theta = np.linspace(0.0, np.pi / 2, 20001)
    integrand = (
        (eta * R * np.sin(theta) / h) * R * np.sin(theta) * 2 * np.pi * R * R * np.sin(theta)
    )
    quad = np.trapezoid(integrand, theta)
    assert abs(bearing_drag(R, h, eta) - quad) < 1e-6 * quad
