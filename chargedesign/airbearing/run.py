"""Build and run the testbed a scene describes (the stage behind ``chargedesign testbed``)."""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Mapping
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.airbearing.actuators import chosen
from chargedesign.airbearing.balance import inertia_tolerances, part_tolerances, sensitivity
from chargedesign.airbearing.bearing import (
    level_map,
    tilt_map,
)
from chargedesign.airbearing.dynamics import (
    CaseModel,
    Plant,
    case_model,
    case_singular_factors,
    model_rate_terms,
)
from chargedesign.airbearing.layout import (
    Layout,
    Plan,
    build_layout,
    plan_motions,
)
from chargedesign.airbearing.loop import STEP_FRACTION, LoopSettings, initial_state, run_loop
from chargedesign.airbearing.platform import total_com, total_inertia
from chargedesign.airbearing.requirements import requirements
from chargedesign.airbearing.result import TestbedResult
from chargedesign.airbearing.verdict import (
    SCALING,
    Requirement,
    Window,
    best_window,
    verdict,
    window,
)
from chargedesign.airbearing.wheels import planned_needs, wheel_axes, wheel_limits, wheel_needs
from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.model import evaluators
from chargedesign.params import Parameters
from chargedesign.physical.drag import AIR_VISCOSITY_KEY
from chargedesign.physical.sources import cite
from chargedesign.physical.state_of_the_art import (
    AIR_FILM,
    ATTITUDE_SENSORS,
    BALANCE,
    BEARINGS,
    FULL_SPHERE,
    GYROS,
    LOOP_RATE,
    REACTION_WHEELS,
    ROOM_AIR,
    room_air_torque,
)
from chargedesign.scene.keys import KEY
from chargedesign.scene.testbed import GYRO_GRADES, SOURCES, TestbedOptions

#: the gyro's bias is averaged at rest this long before a run (s)
BIAS_CALIBRATION_S = 60.0


def default_testbed_scene() -> Path:
    """The embedded testbed scene (the same text as examples/scenes/testbed.toml): the
    embedded default scene's SI body is far too small for a platform."""
    return Path(str(resources.files("chargedesign").joinpath("data/testbed_scene.toml")))


def testbed_from_scene(
    scene: Any,
    progress: Callable[[str], None] | None = None,
    tally: Callable[[int, int], None] | None = None,
    **overrides: Any,
) -> TestbedResult:
    """The testbed of a scene's parameters and ``[testbed]`` table (``overrides`` replace
    keys of that table). See :func:`build_testbed`."""
    options = scene.testbed  # parsed once, with the scene
    if overrides:
        table: Mapping[str, Any] = {**scene.table("testbed"), **overrides}
        options = TestbedOptions.from_table(table)
    case = scene.case
    if case is not None:
        return build_case_testbed(case, options, progress, tally=tally)
    return build_testbed(scene.parameters, options, progress, tally=tally)


def build_case_testbed(
    case: Any,
    opts: TestbedOptions,
    progress: Callable[[str], None] | None = None,
    with_requirements: bool = True,
    tally: Callable[[int, int], None] | None = None,
) -> TestbedResult:
    """:func:`build_testbed` for a case of (ep) (``[case]``, issue 34): the wheels apply the
    case's torques, the motion keeps the case's level, F is monitored in place of I4.

    A case the testbed cannot fly (its inertia, a singular V or mu: see
    :func:`chargedesign.airbearing.dynamics.flight_refusal`) or a scene without a start is
    refused in one line before any work."""
    opts.check_case(case.name, case.inertia, case_singular_factors(case))
    opts.check_case_start(case.name)
    model = case_model(case)
    return build_testbed(
        Parameters(C=float(model.inertia[2])),
        opts,
        progress,
        with_requirements,
        case=model,
        tally=tally,
    )


def build_testbed(
    params: Parameters,
    opts: TestbedOptions,
    progress: Callable[[str], None] | None = None,
    with_requirements: bool = True,
    case: CaseModel | None = None,
    tally: Callable[[int, int], None] | None = None,
) -> TestbedResult:
    """The motions that fit the bearing, the layout (wheels, ballast, mounts), the loop's
    runs, the requirements against the state of the art, the verdict and the window.

    Raises
    ------
    InputError
        Singular parameters, a start beyond the bearing's tilt limit, work past a cap, a
        torque step above the range, or a platform with ballast heavier than the bearing's
        rating (each refused by the options' own check, :mod:`chargedesign.scene.testbed`).
    InfeasibleError
        No ballast reaches the inertia, or wheels too weak for the motion.
    """
    say = progress or (lambda message: None)
    opts.check_parameters(params.singular)
    count = run_counter(tally, opts, with_requirements)  # the sampled runs, done of their total
    seconds: dict[str, float] = {}
    t0 = time.perf_counter()
    check_loop_work(params, opts, case)
    plan = plan_motions(params, opts, case)
    seconds[KEY.planned_motions] = time.perf_counter() - t0
    say(
        f"{len(plan.motions)} planned motions, largest tilt "
        f"{fmt(max(m.tilt_max_deg for m in plan.motions), PRECISE)} deg of the {opts.bearing} "
        f"bearing's {fmt(opts.tilt_limit, PLAIN)}"
    )
    t0 = time.perf_counter()
    target = np.diag([2.0 * params.C, 2.0 * params.C, params.C])
    axes = wheel_axes(opts.wheels, opts.pyramid_angle_deg)
    starts = np.array([m.start for m in plan.motions])
    planned = planned_needs(Plant(params, target, target, case), starts, axes, opts.t_end_s)
    limits = wheel_limits(planned, opts)
    layout = build_layout(params, opts, plan.axis, axes, limits[1])
    platform, ballast = layout.platform, layout.ballast
    total_mass = platform.mass_kg + ballast.total_mass
    opts.check_capacity(total_mass)
    inertia = total_inertia(platform, ballast)
    plant = Plant(params, inertia, target, case)
    x0 = starts[0]
    needs = planned.motions[0]  # motion 0: the loop's start
    seconds["layout"] = time.perf_counter() - t0
    say(
        f"ballast {fmt(ballast.total_mass, PRECISE)} kg in {len(ballast.masses)} parts on posts;"
        f" wheels sized over {len(planned.motions)} planned motions"
    )
    t0 = time.perf_counter()
    # after the wheels' and the bearing's refusals, which need only the planned motions: a
    # case's tilt map needs its own bifurcation diagram (not drawn yet)
    hosted = _hosted_tilt_map(params, plan, opts) if case is None else None
    if hosted is not None:
        seconds["tilt_map"] = time.perf_counter() - t0
    sens = sensitivity(plant, needs.times, needs.states, total_mass)
    compliance = layout.ballast_mounts.com_matrix(total_mass) + layout.wheel_mounts.com_matrix(
        total_mass
    )
    tolerances = _tolerances(sens, ballast, plant, opts, total_mass)
    base = LoopSettings(
        rate_Hz=opts.rate_Hz,
        delay_s=opts.delay_s,
        t_end_s=opts.t_end_s,
        wheel_axes=axes,
        max_torque=limits[0],
        max_momentum=limits[1],
    )
    nominal = _nominal(base, opts, total_mass, limits[2], compliance, layout)
    runs, reqs = _sampled_runs(
        plant, x0, base, nominal, opts, with_requirements, count, say, seconds
    )
    compliance_offset = float(
        layout.ballast_mounts.offset_m(total_mass) + layout.wheel_mounts.offset_m(total_mass)
    )
    sota = against_state_of_the_art(
        opts, plan, planned, layout, tolerances, runs, reqs, total_mass, compliance_offset
    )
    median = float(np.median(runs["nominal"].I4_drift))
    windows, best, check = _window_search(
        sota, opts, plan, planned, plant, starts, axes, total_mass, say, seconds
    )
    result = TestbedResult(
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
        layout=layout,
        plan=plan,
        compliance_offset_m=compliance_offset,
        state_of_the_art=sota,
        verdict=verdict(sota, median, opts.target_I4_drift),
        window=best,
        windows=windows,
        window_check=check,
        tilt_map=hosted,
        case=case,
    )
    say("verdict reached (printed with the result)")  # the verdict is said once: in the text
    return result


def _hosted_tilt_map(params: Parameters, plan: Plan, opts: TestbedOptions) -> Any:
    """The theorem's tilt map over the energies of the planned starts (up to 3 times their
    span above the lowest level)."""
    starts = np.array([m.start for m in plan.motions])
    energies = evaluators.integrals(starts, params)[:, 0]
    h_low = level_map(params)[1][0]
    return tilt_map(
        params, plan.axis, opts.tilt_limit, h_top=h_low + 3.0 * (float(energies.max()) - h_low)
    )


def _sampled_runs(
    plant: Plant,
    x0: np.ndarray,
    base: LoopSettings,
    nominal: LoopSettings,
    opts: TestbedOptions,
    with_requirements: bool,
    count: Callable[[int], None],
    say: Callable[[str], None],
    seconds: dict[str, float],
) -> tuple[dict[str, Any], Any]:
    """The loop's runs: noise-free with each command, the nominal Monte Carlo, and (with
    ``with_requirements``) the requirements' sweep; each timed into ``seconds``."""
    runs = {}
    for command in ("zoh", "predictive"):
        t0 = time.perf_counter()
        runs[f"{command}_noise_free"] = run_loop(
            plant, x0, replace(base, command=command), keep_states=command == opts.command
        )
        seconds[f"{command}_noise_free"] = time.perf_counter() - t0
        count(1)
        drift = runs[f"{command}_noise_free"].I4_drift[0]
        say(f"{command} noise-free: I4 drift {fmt(drift)}")
    t0 = time.perf_counter()
    runs["nominal"] = run_loop(plant, x0, nominal, runs=opts.seeds, seed=0, keep_states=True)
    seconds["nominal"] = time.perf_counter() - t0
    count(opts.seeds)
    say(
        f"nominal ({opts.seeds} seeds, every effect on): median I4 drift "
        f"{fmt(np.median(runs['nominal'].I4_drift))}"
    )
    reqs = None
    if with_requirements:
        t0 = time.perf_counter()
        reqs = requirements(
            plant,
            x0,
            replace(nominal, imbalance_m=0.0, drag_N_m_s=0.0, compliance=None, estimator=False),
            GYRO_GRADES,
            opts.requirement_rates_Hz,
            opts.requirement_seeds,
            opts.target_I4_drift,
            tally=count,
        )
        seconds["requirements"] = time.perf_counter() - t0
        say("requirements swept (gyro grade x loop rate, without drag, imbalance and mounts)")
    return runs, reqs


def _window_search(
    sota: list[Requirement],
    opts: TestbedOptions,
    plan: Plan,
    planned: Any,
    plant: Plant,
    starts: np.ndarray,
    axes: np.ndarray,
    total_mass: float,
    say: Callable[[str], None],
    seconds: dict[str, float],
) -> tuple[list[Any], Any, dict[str, Any]]:
    """The window of every bearing style, the best one, and that design recomputed."""
    alone = [
        {
            "bearing_tilt_deg": motion.tilt_max_deg,
            "wheel_torque_N_m": needs_k.torque,
            "wheel_momentum_N_m_s": needs_k.momentum,
        }
        for motion, needs_k in zip(plan.motions, planned.motions, strict=True)
    ]
    t0 = time.perf_counter()
    windows = [window(for_style(sota, opts, style), style, alone, len(axes)) for style in BEARINGS]
    best = best_window(windows)
    check = recompute_point(best, sota, alone, plant, starts, axes, opts, total_mass)
    seconds["window"] = time.perf_counter() - t0
    say(
        "window searched over rate, size, mass, motion and bearing style; the recommended "
        f"design recomputed: the laws agree within {fmt(check['largest_law_error'])}"
    )
    return windows, best, check


def against_state_of_the_art(
    opts: TestbedOptions,
    plan: Any,
    planned: Any,
    layout: Layout,
    tolerances: dict,
    runs: dict,
    reqs: Any,
    total_mass: float,
    compliance_offset: float,
) -> list[Requirement]:
    """Every requirement with what it needs, the best reached and the source (see
    chargedesign.airbearing.verdict)."""
    nominal = runs["nominal"]
    style = opts.style
    offset = _offset_reached(opts, nominal, compliance_offset)
    weight = total_mass * STANDARD_GRAVITY
    sensor_keys = _sensor_keys(opts)
    out = [
        Requirement(
            "bearing_tilt_deg",
            "capacity",
            max(m.tilt_max_deg for m in plan.motions),
            layout.tilt_limit_deg,
            "deg",
            layout.source,
            keys=(style.tilt_key,) if opts.tilt_limit_deg is None else (),
            origin="table" if opts.tilt_limit_deg is None else "scene",
        ),
        Requirement(
            "bearing_load_kg",
            "capacity",
            total_mass,
            opts.capacity_kg,
            "kg",
            style.source if opts.bearing_capacity_kg is None else "the scene's bearing_capacity_kg",
            keys=(style.load_key,) if opts.bearing_capacity_kg is None else (),
            origin="table" if opts.bearing_capacity_kg is None else "scene",
        ),
        *_wheel_requirements(opts, planned, layout, total_mass),
        Requirement(
            "centre_of_mass_offset_m",
            "tolerance",
            tolerances[KEY.imbalance_m],
            offset.residual + offset.mounts_part,
            "m",
            offset.source,
            parts={"estimator_or_floor_m": offset.residual, "mounts_m": offset.mounts_part},
            keys=offset.keys,
            origin=offset.origin,
        ),
        _drag_requirement(opts, tolerances),
        Requirement(
            "room_air_torque_N_m",
            "tolerance",
            weight * tolerances[KEY.imbalance_m],
            room_air_torque(opts.platform_radius_m),
            "N m",
            "; ".join(f.source for f in ROOM_AIR.values()),
            keys=tuple(f.key for f in ROOM_AIR.values()),
        ),
    ]
    if reqs is not None:
        lowest = reqs.lowest_rate_Hz.get(opts.gyro_grade)
        out.append(
            Requirement(
                "loop_rate_Hz",
                "capacity",
                lowest if lowest is not None else float(max(reqs.rates_Hz)),
                LOOP_RATE.value,
                "Hz",
                LOOP_RATE.source,
                unmet_reason=""
                if lowest is not None
                else "none of the rates tried meets the target with this gyro: the figure is the "
                "highest rate tried, and the requirement is counted as missed",
                keys=(LOOP_RATE.key, *sensor_keys),
            )
        )
    if opts.bearing == "full_sphere":
        out.append(ball_requirement(opts))
    median = float(np.median(nominal.I4_drift))
    out.append(
        Requirement(
            "nominal_I4_drift",
            "tolerance",
            opts.target_I4_drift,
            median,
            "1",
            f"this run's Monte Carlo ({opts.seeds} seeds; noise, bias, imbalance, drag, mounts, "
            "encoders all on; the sensors' figures: "
            + (", ".join(cite(k) for k in sensor_keys) or "the scene's")
            + ")",
            keys=sensor_keys,
            origin="run",
        )
    )
    return out


@dataclass(frozen=True)
class _OffsetReached:
    """The centre of mass offset the platform reaches: the estimator's residual (or the
    balancing floor), the posts' bending part, and where each figure comes from."""

    residual: float
    mounts_part: float
    source: str
    keys: tuple[str, ...]
    origin: str


def _offset_reached(opts: TestbedOptions, nominal: Any, compliance_offset: float) -> _OffsetReached:
    balance = BALANCE["automatic_horizontal_m"]
    given_offset = opts.imbalance_m != balance.value
    offset_origin = "the scene's imbalance_m" if given_offset else balance.source
    if nominal.offset_error is not None:
        residual = float(np.median(nominal.offset_error[:, -1]))
        source = (
            f"this run's online estimator (RLS of the offset, the drag and the posts' bending "
            f"{fmt(compliance_offset)} m; {opts.seeds} seeds: median residual "
            f"{fmt(residual)} m, the posts' part included); offset "
            f"before estimation {fmt(opts.imbalance_m)} m ({offset_origin})"
        )
    else:
        residual = opts.imbalance_m
        source = (
            f"balancing floor {fmt(residual)} m ({offset_origin}) + "
            f"the posts' bending ({fmt(compliance_offset)} m)"
        )
    # the estimator's residual already holds what is left of the posts' bending
    mounts_part = 0.0 if nominal.offset_error is not None else compliance_offset
    return _OffsetReached(
        residual,
        mounts_part,
        source,
        () if given_offset else (balance.key,),
        "scene" if given_offset else "table",
    )


def _wheel_requirements(
    opts: TestbedOptions, planned: Any, layout: Layout, total_mass: float
) -> list[Requirement]:
    """The wheels' torque, momentum and mass against the actuator catalogue's lightest wheel
    that covers the planned motions."""
    wheel = chosen(planned.torque, planned.momentum)
    wheels_note = (
        f"{wheel.name}, the lightest of the actuator catalogue covering the planned torque and "
        "momentum"
        if wheel.torque >= planned.torque and wheel.momentum >= planned.momentum
        else f"{wheel.name}, the catalogue's nearest: none covers the planned torque and momentum"
    )
    return [
        _wheel_requirement(
            "wheel_torque_N_m",
            planned.torque,
            opts.max_torque_N_m,
            "N m",
            wheel.torque,
            f"{wheels_note}: {wheel.source} {cite(wheel.key('torque'))}",
            wheel.key("torque"),
        ),
        _wheel_requirement(
            "wheel_momentum_N_m_s",
            planned.momentum,
            opts.max_momentum_N_m_s,
            "N m s",
            wheel.momentum,
            f"{wheel.name}: {wheel.source} {cite(wheel.key('momentum'))}",
            wheel.key("momentum"),
        ),
        Requirement(
            "wheel_mass_kg",
            "tolerance",
            total_mass,
            len(layout.wheels.masses) * wheel.mass,
            "kg",
            f"{len(layout.wheels.masses)} x {wheel.name} ({wheel.source} "
            f"{cite(wheel.key('mass'))}) within the platform's mass, which holds them",
            keys=(wheel.key("mass"),),
        ),
    ]


def _wheel_requirement(
    name: str,
    need: float,
    given: float | None,
    unit: str,
    best: float,
    source: str,
    key: str,
) -> Requirement:
    """A wheel requirement: against the scene's own wheels when it gives their limit, else
    against the catalogue actuator chosen for the planned needs."""
    if given is not None:
        key_name = KEY.max_torque_N_m if "torque" in name else KEY.max_momentum_N_m_s
        return Requirement(
            name, "capacity", need, given, unit, f"the scene's {key_name}", origin="scene"
        )
    return Requirement(name, "capacity", need, best, unit, source, keys=(key,))


def _sensor_keys(opts: TestbedOptions) -> tuple[str, ...]:
    """The sources-table keys of the gyro's and the attitude sensor's figures the loop runs
    with (none where the scene gives its own)."""
    keys: list[str] = []
    if opts.gyro_grade in GYROS:
        arw, bias = GYROS[opts.gyro_grade]
        if opts.gyro_arw_rad_per_sqrt_s is None:
            keys.append(arw.key)
        if opts.gyro_bias_rad_per_s is None:
            keys.append(bias.key)
    noise, rate = ATTITUDE_SENSORS[opts.attitude_sensor]
    if opts.attitude_noise_rad is None:
        keys.append(noise.key)
    if opts.attitude_rate_Hz is None:
        keys.append(rate.key)
    return tuple(keys)


def _drag_requirement(opts: TestbedOptions, tolerances: dict) -> Requirement:
    """The bearing's drag, taken at the air film's worst end: the thinnest film of its range
    (the most drag; drag goes as 1/h) unless the scene gives its gap or its drag."""
    name, unit = "bearing_drag_N_m_s", "N m s"
    required = tolerances["drag_max_N_m_s"]
    if opts.drag_N_m_s is not None:
        return Requirement(
            name, "tolerance", required, opts.drag, unit, "the scene's drag_N_m_s", origin="scene"
        )
    cup = "; a full sphere's film lies under the whole ball in its cup (cup_drag)"
    where = cup if opts.bearing == "full_sphere" else ""
    thin, thick = AIR_FILM["thin_m"], AIR_FILM["thick_m"]
    if opts.bearing_gap_m != thin.value:
        return Requirement(
            name,
            "tolerance",
            required,
            opts.drag,
            unit,
            f"{SOURCES[KEY.drag_N_m_s]} {cite(AIR_VISCOSITY_KEY)}, the scene's bearing_gap_m "
            f"{fmt(opts.bearing_gap_m)} m{where}",
            keys=(AIR_VISCOSITY_KEY,),
            origin="scene",
        )
    at_thick = opts.drag * thin.value / thick.value  # Couette drag goes as 1/h
    return Requirement(
        name,
        "tolerance",
        required,
        opts.drag,
        unit,
        f"{SOURCES[KEY.drag_N_m_s]} {cite(AIR_VISCOSITY_KEY)}, at the thin end of the air film's "
        f"range {fmt(thin.value)}..{fmt(thick.value)} m (the most drag; "
        f"{fmt(at_thick)} N m s at the thick end) {thin.source} {cite(thin.key)}; "
        f"{thick.source} {cite(thick.key)}{where}",
        parts={
            "film_thin_m": thin.value,
            "film_thick_m": thick.value,
            "drag_at_thick_film_N_m_s": at_thick,
        },
        keys=(AIR_VISCOSITY_KEY, thin.key, thick.key),
    )


def recompute_point(
    best: Window,
    sota: list[Requirement],
    alone: list[dict[str, float]],
    plant: Plant,
    starts: np.ndarray,
    axes: np.ndarray,
    opts: TestbedOptions,
    total_mass: float,
) -> dict[str, Any]:
    """The window's recommended design recomputed in full, not by the laws: the theorem's
    C x m L^2 with n, K x s and kappa x s^2, the platform's inertia x m L^2 and mass x m, the
    chosen motions flown s times faster (wheel needs by the ideal loop, the balance and drag
    tolerances by the linear response along motion 0, the loop's start). Each recomputed
    requirement is set beside the law's; the figures the laws alone give (loop rate, tilt,
    the bests) are not recomputed."""
    i, j, k, m = best.best_index()
    s, size, mass = float(best.rates[i]), float(best.sizes[j]), float(best.masses[k])
    scale = mass * size * size
    p = plant.params
    params = p.replace(C=p.C * scale, n=p.n * s, K=p.K * s, kappa=p.kappa * s * s)
    target = np.diag([2.0 * params.C, 2.0 * params.C, params.C])
    fast = np.concatenate([starts[:, :3] * s, starts[:, 3:]], axis=1)
    case = None if plant.case is None else plant.case.scaled(s, scale)
    model = Plant(params, target, target, case)
    chosen = fast if m == 0 else fast[m - 1 : m]
    needs = planned_needs(model, chosen, axes, opts.t_end_s / s)
    start = needs.motions[0] if m <= 1 else wheel_needs(model, fast[0], axes, opts.t_end_s / s)
    sens = sensitivity(
        Plant(params, plant.inertia * scale, target, case),
        start.times,
        start.states,
        total_mass * mass,
    )
    offset = opts.target_I4_drift / sens.imbalance_per_m
    recomputed = {
        "wheel_torque_N_m": needs.torque,
        "wheel_momentum_N_m_s": needs.momentum,
        "centre_of_mass_offset_m": offset,
        "bearing_drag_N_m_s": opts.target_I4_drift / sens.drag_per_unit,
        "room_air_torque_N_m": total_mass * mass * STANDARD_GRAVITY * offset,
        "bearing_load_kg": total_mass * mass,
    }
    law = {r.name: r for r in sota}
    rows = {}
    for name, value in recomputed.items():
        if name not in law:
            continue
        base = alone[m - 1][name] if m > 0 and name in alone[m - 1] else law[name].required
        e = SCALING[name][0]
        rows[name] = {
            "law": base * s ** e[0] * size ** e[1] * mass ** e[2],
            "recomputed": value,
        }
    return {
        "rate_factor": s,
        "size_factor": size,
        "mass_factor": mass,
        "motion": best.motions[m],
        "required": rows,
        "largest_law_error": max(abs(r["recomputed"] / r["law"] - 1.0) for r in rows.values()),
    }


def for_style(sota: list[Requirement], opts: TestbedOptions, style: str) -> list[Requirement]:
    """The requirements read for another bearing style (the window's style axis): its tilt
    limit, rated load and film drag (a full sphere's cup under the whole ball, and its ball's
    size); the planned motions, the layout and the loop's figures are the scene's."""
    if style == opts.bearing:
        return sota
    other = replace(opts, bearing=style, tilt_limit_deg=None, bearing_capacity_kg=None)
    out = []
    for r in sota:
        if r.name == "ball_diameter_m":
            continue
        if r.name == "bearing_tilt_deg":
            r = replace(
                r,
                best=180.0 if style == "full_sphere" else other.tilt_limit,
                source=BEARINGS[style].source,
                keys=(BEARINGS[style].tilt_key,),
                origin="table",
            )
        elif r.name == "bearing_load_kg":
            r = replace(
                r,
                best=other.capacity_kg,
                source=BEARINGS[style].source,
                keys=(BEARINGS[style].load_key,),
                origin="table",
            )
        elif r.name == "bearing_drag_N_m_s" and opts.drag_N_m_s is None:
            scale = other.drag / opts.drag
            parts = dict(r.parts)
            if "drag_at_thick_film_N_m_s" in parts:
                parts["drag_at_thick_film_N_m_s"] *= scale
            r = replace(r, best=other.drag, parts=parts)
        out.append(r)
    if style == "full_sphere":
        out.append(ball_requirement(opts))
    return out


def ball_requirement(opts: TestbedOptions) -> Requirement:
    """A full sphere's ball: its diameter against the largest built."""
    ball = FULL_SPHERE["largest_diameter_m"]
    return Requirement(
        "ball_diameter_m",
        "capacity",
        2.0 * opts.platform_radius_m,
        ball.value,
        "m",
        ball.source,
        keys=(ball.key,),
    )


def check_loop_work(
    params: Parameters, opts: TestbedOptions, case: CaseModel | None = None
) -> None:
    """Refuse, before any work, a loop run whose fixed integration steps pass
    ``max_loop_steps`` (the steps follow from the motion's fastest rate), naming the
    cause (the start or the parameter whose rate is fastest) and the option."""
    omega0 = np.zeros(3)
    if opts.has_start:
        assert opts.initial_gamma is not None
        gamma, p, q = (
            np.array(opts.initial_gamma),
            float(opts.initial_p or 0.0),
            float(opts.initial_q or 0.0),
        )
        omega0 = initial_state(params, gamma, p, q, case)[:3]
    terms = model_rate_terms(params, omega0, case)
    rate = max(max(terms.values()), 1e-12)
    opts.check_loop_steps(rate, max(terms, key=lambda k: terms[k]), STEP_FRACTION)


def run_counter(
    tally: Callable[[int, int], None] | None, opts: TestbedOptions, with_requirements: bool
) -> Callable[[int], None]:
    """``count(k)``: ``k`` more sampled closed-loop runs done, told to ``tally(done, total)``
    (the noise-free ZOH and predictive runs, the nominal seeds, the requirements' grid)."""
    sweep = len(GYRO_GRADES) * opts.requirement_seeds * len(opts.requirement_rates_Hz)
    total = 2 + opts.seeds + (sweep if with_requirements else 0)
    done = 0

    def count(k: int) -> None:
        nonlocal done
        done += k
        if tally is not None:
            tally(done, total)

    count(0)
    return count


def _nominal(
    base: LoopSettings,
    opts: TestbedOptions,
    mass: float,
    resolution: float,
    compliance: np.ndarray,
    layout: Layout,
) -> LoopSettings:
    """The loop as built: every effect on (noise, bias, imbalance, drag, mounts, encoders),
    the attitude fused with the gyro, the bias calibrated at rest, the estimator."""
    arw, bias = opts.gyro
    noise, frames = opts.attitude
    counts = opts.encoder_counts or REACTION_WHEELS["encoder_counts_per_turn"].value
    spin = float(layout.wheels.spin_inertia[0])
    return replace(
        base,
        command=opts.command,
        gyro_arw=arw,
        gyro_bias=bias,
        attitude_noise=noise,
        attitude_rate_Hz=frames,
        fusion=True,
        bias_calibration_s=BIAS_CALIBRATION_S,
        encoder_step=spin * 2.0 * math.pi / counts * opts.rate_Hz,
        compliance=compliance,
        motor_bandwidth_Hz=np.inf if opts.motor_bandwidth_Hz is None else opts.motor_bandwidth_Hz,
        wheel_friction_N_m=opts.wheel_friction_N_m or 0.0,
        estimator=opts.estimator == "rls",
        prior_offset_m=max(opts.imbalance_m, 1e-9),
        prior_drag_N_m_s=max(opts.drag, 1e-12),
        prior_compliance_m=float(np.abs(compliance).max()),
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
        KEY.target_I4_drift: target,
        KEY.imbalance_m: target / sens.imbalance_per_m,
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


__all__ = ["build_case_testbed", "build_testbed", "testbed_from_scene"]
