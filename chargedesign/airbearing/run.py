"""Build and run the testbed a scene describes (the stage behind ``chargedesign testbed``)."""

from __future__ import annotations

import time
from collections.abc import Callable, Mapping
from dataclasses import replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.airbearing.balance import inertia_tolerances, part_tolerances, sensitivity
from chargedesign.airbearing.dynamics import Plant
from chargedesign.airbearing.loop import LoopSettings, initial_state, run_loop
from chargedesign.airbearing.options import GYRO_GRADES, TestbedOptions
from chargedesign.airbearing.platform import (
    Platform,
    design_ballast,
    total_com,
    total_inertia,
)
from chargedesign.airbearing.requirements import requirements
from chargedesign.airbearing.result import TestbedResult
from chargedesign.airbearing.wheels import (
    planned_needs,
    planned_states,
    wheel_axes,
    wheel_limits,
)
from chargedesign.errors import InputError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.params import Parameters


def default_testbed_scene() -> Path:
    """The embedded testbed scene (the same text as examples/scenes/testbed.toml): the
    embedded default scene's SI body is far too small for a platform."""
    return Path(str(resources.files("chargedesign").joinpath("data/testbed_scene.toml")))


def testbed_from_scene(
    scene: Any,
    progress: Callable[[str], None] | None = None,
    **overrides: Any,
) -> TestbedResult:
    """The testbed of a scene's parameters and ``[testbed]`` table (``overrides`` replace
    keys of that table). See :func:`build_testbed`."""
    options = scene.testbed  # parsed once, with the scene
    if overrides:
        table: Mapping[str, Any] = {**scene.table("testbed"), **overrides}
        options = TestbedOptions.from_table(table)
    return build_testbed(scene.parameters, options, progress)


def build_testbed(
    params: Parameters,
    opts: TestbedOptions,
    progress: Callable[[str], None] | None = None,
    with_requirements: bool = True,
) -> TestbedResult:
    """Platform and ballast, wheels, the loop's runs and the requirements.

    Raises
    ------
    InputError
        Singular parameters, or a platform with ballast heavier than the bearing's rating.
    InfeasibleError
        No ballast reaches the inertia, or wheels too weak for the motion.
    """
    say = progress or (lambda message: None)
    if params.singular:
        raise InputError(
            "testbed: lambda and rho must be 0 (their torques are singular on gamma3 = 0)"
        )
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    platform = Platform.from_options(opts)
    ballast = design_ballast(platform, params.C, opts)
    total_mass = platform.mass_kg + ballast.total_mass
    if total_mass > opts.bearing_capacity_kg:
        raise InputError(
            "testbed.bearing_capacity_kg: the platform with its ballast"
            f" ({fmt(total_mass, PRECISE)} kg) "
            f"is heavier than the bearing's rating ({fmt(opts.bearing_capacity_kg, PLAIN)} kg)"
        )
    inertia = total_inertia(platform, ballast)
    target = np.diag([2.0 * params.C, 2.0 * params.C, params.C])
    plant = Plant(params, inertia, target)
    x0 = initial_state(params, np.array(opts.initial_gamma), opts.initial_p, opts.initial_q)
    axes = wheel_axes(opts.wheels, opts.pyramid_angle_deg)
    planned = planned_needs(
        plant, planned_states(params, x0, opts.planned_motions), axes, opts.t_end_s
    )
    needs = planned.motions[0]  # the scene's own motion: the runs' start
    limits = wheel_limits(planned, opts)
    seconds["platform_and_wheels"] = time.perf_counter() - t0
    say(
        f"ballast {fmt(ballast.total_mass, PRECISE)} kg in {len(ballast.masses)} parts; wheels"
        " sized "
        f"over {len(planned.motions)} planned motions"
    )

    sens = sensitivity(plant, needs.times, needs.states, total_mass)
    tolerances = _tolerances(sens, ballast, plant, opts, total_mass)
    base = LoopSettings(
        rate_Hz=opts.rate_Hz,
        delay_s=opts.delay_s,
        t_end_s=opts.t_end_s,
        wheel_axes=axes,
        max_torque=limits[0],
        max_momentum=limits[1],
    )
    runs = {}
    for command in ("zoh", "predictive"):
        t0 = time.perf_counter()
        runs[f"{command}_noise_free"] = run_loop(
            plant, x0, _with(base, command=command), keep_states=command == opts.command
        )
        seconds[f"{command}_noise_free"] = time.perf_counter() - t0
        drift = runs[f"{command}_noise_free"].I4_drift[0]
        say(f"{command} noise-free: I4 drift {fmt(drift)}")
    nominal = _nominal(base, opts, total_mass, limits[2])
    t0 = time.perf_counter()
    runs["nominal"] = run_loop(plant, x0, nominal, runs=opts.seeds, seed=0, keep_states=True)
    seconds["nominal"] = time.perf_counter() - t0
    say(f"nominal ({opts.seeds} seeds): median I4 drift {fmt(np.median(runs['nominal'].I4_drift))}")
    reqs = None
    if with_requirements:
        t0 = time.perf_counter()
        reqs = requirements(
            plant,
            x0,
            _with(nominal, imbalance_m=0.0, drag_N_m_s=0.0),
            GYRO_GRADES,
            opts.requirement_rates_Hz,
            opts.requirement_seeds,
            opts.target_I4_drift,
        )
        seconds["requirements"] = time.perf_counter() - t0
        say("requirements swept")
    return TestbedResult(
        parameters=params,
        options=opts,
        platform=platform,
        ballast=ballast,
        inertia_total=inertia,
        com_total=total_com(platform, ballast),
        wheel_axes=axes,
        wheel_limits=limits,
        needs=needs,
        planned=planned,
        initial_state=x0,
        runs=runs,
        requirements=reqs,
        tolerances=tolerances,
        ideal_states=needs.states,
        seconds=seconds,
    )


def _with(settings: LoopSettings, **changes: Any) -> LoopSettings:
    return replace(settings, **changes)


def _nominal(
    base: LoopSettings, opts: TestbedOptions, mass: float, resolution: float
) -> LoopSettings:
    arw, bias = opts.gyro
    return _with(
        base,
        command=opts.command,
        gyro_arw=arw,
        gyro_bias=bias,
        attitude_noise=opts.attitude_noise_rad,
        imbalance_m=opts.imbalance_m,
        drag_N_m_s=opts.drag,
        drag_feedforward_N_m_s=opts.drag_feedforward * opts.drag,
        total_mass_kg=mass,
        resolution=resolution,
    )


def _tolerances(sens: Any, ballast: Any, plant: Plant, opts: TestbedOptions, mass: float) -> dict:
    target = opts.target_I4_drift
    parts = part_tolerances(sens, ballast, plant, target, mass)
    drag_drift = (1.0 - opts.drag_feedforward) * opts.drag * sens.drag_per_unit
    return {
        "target_I4_drift": target,
        "imbalance_m": target / sens.imbalance_per_m,
        "imbalance_drift": opts.imbalance_m * sens.imbalance_per_m,
        "drag_drift": drag_drift,
        "drag_max_N_m_s": target / sens.drag_per_unit,
        "inertia": inertia_tolerances(sens, target, plant.params.C),
        "ballast_placement_m": {
            "through_inertia": parts["through_inertia_m"],
            "through_balance": parts["through_balance_m"],
            "binding": np.minimum(parts["through_inertia_m"], parts["through_balance_m"]),
        },
    }


__all__ = ["build_testbed", "testbed_from_scene"]
