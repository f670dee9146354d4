"""The public entry :func:`simulate`: a setup prepared into a system and a start, integrated,
and its result with the monitors.

A scene (TOML or :class:`~chargedesign.scene.Scene`) may add these tables to the contract's
``[parameters]`` and ``[fields.*]``::

    [body]                      # the body to simulate:
    shape = "ball"              # a candidate region (the designer's keys): designed on the fly
    radius = 1.0                #   with design_from_scene, unless effects = ["theorem"] ...
    spacing = 0.25
    # design = "out/design.json"  # ... or a design file (relative to the scene file), or inline:
    # [body.charges]  positions = [[x, y, z], ...]   values = [...]
    # [body.masses]   positions = [...]              values = [...]
    # [body.dipoles]  positions = [...]              moments = [[sx, sy, sz], ...]

    [initial]
    gamma = [0.36, 0.48, 0.8]   # unit vector of space Z in body axes (normalised if not)
    omega = [0.6, -0.4, 0.1]    # explicit angular velocity, 1/s ... or
    level = "I3=0"              # ... p and q given, r solved from the level
    p = 0.6
    q = -0.4
    precession = 0.0            # initial turn about space Z, rad (does not change the motion)

    [simulation]
    t_end = 100.0               # s
    rtol = 1e-12
    atol = 1e-12
    method = "DOP853"           # DOP853 | RK45 | RK23 | Radau | BDF | LSODA | gauss-legendre
    effects = ["lorentz", "electric", "magnetization", "gravity"]   # or ["theorem"]
    max_step = 1.0              # s (solve_ivp)
    step = 0.01                 # s (gauss-legendre fixed step)
    samples = 2001              # output samples
    route = "reduced"           # reduced | direct (force route for a designed body)
    gamma3_min = 0.01           # singular-plane event threshold (lambda or rho != 0)
    axes = "turning"            # turning | inertial: the axes the motion is written in
                                # (default turning for a frame body, inertial otherwise)

    [output]
    dir = "out/simulate"
    trajectory = true           # trajectory.npz and trajectory.csv
    plot = true                 # integrals.png
    poincare = false            # record a section and draw poincare.png
    poincare_section = "gamma1" # upward zero crossings of this state
    poincare_axes = ["gamma2", "q"]

A ``frame`` body (design.json ``larmor.reading = "frame"``) is integrated with its own physics
(n = 0) and, by default, written in axes turning at ``larmor.rate`` about Z, where it is the
theorem's motion with n (:mod:`chargedesign.simulation.axes`); ``axes = "inertial"`` writes it
as integrated. Other bodies have only the inertial reading.

Fields: the design's, each kind replaced by the scene's ``[fields.<kind>]`` when given.
Without a body only the ``theorem`` effect has a source.

A ``[body]`` with a ``shape`` (and neither ``design`` nor inline elements) is designed when a
run first needs its elements (:func:`chargedesign.designer.design_from_scene` with the scene's
``[design]``), then simulated from its own elements under every physical effect with a source
and a field. A run whose effects are only ``theorem`` does not design it. The body is designed
once per :class:`SimulationSetup`: pass the setup to :func:`simulate` again to reuse it.

The setup is read, and a pending ``[body]`` region designed, in
:mod:`chargedesign.simulation.setup` (the tables' checks in
:mod:`chargedesign.scene.simulation`), and many starts of one body run in
:mod:`chargedesign.simulation.ensemble` (:func:`~chargedesign.simulation.ensemble.simulate_batch`).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import CELL, PLAIN, PRECISE, fmt
from chargedesign.limits import MAX_SAMPLES, MAX_STEPS

# read through this module by callers of the earlier single-module layout (tolerancing)
from chargedesign.scene.simulation import DEFAULT_INITIAL as DEFAULT_INITIAL
from chargedesign.scene.simulation import (
    SimulationOptions,
    check_off_singular_plane,
    initial_spec,
    merge_options,
    with_level,
)
from chargedesign.scene.simulation import parse_initial as parse_initial
from chargedesign.simulation import monitors as monitors_mod
from chargedesign.simulation.axes import resolve_axes, turning_poincare, turning_states
from chargedesign.simulation.integrate import STATE_NAMES, integrate
from chargedesign.simulation.result import SimulationResult
from chargedesign.simulation.setup import (
    SimulationSetup,
    body_counts,
    design_pending,
    needs_elements,
    realised_claims,
    setup_from_source,
)
from chargedesign.simulation.setup import setup_from_scene as setup_from_scene
from chargedesign.simulation.system import (
    Body,
    RigidBodySystem,
    attitude_from_gamma,
    body_mass_points,
    inertia_mismatch,
    mass_inertia,
    quaternion_gamma,
    quaternion_rotation,
    rotation_quaternion,
    select_effects,
)
from chargedesign.validation import check_choice, input_error


def _case_functions(design: Any) -> Any:
    """The numeric functions of the case a design carries (None: the theorem's)."""
    if design is None or "case" not in design.further_keys:
        return None
    from chargedesign.model.case_numeric import simulated_case_functions  # sympy: a case only

    return simulated_case_functions(design.further_keys["case"], design.larmor, design.time_rate)


def reduced_case_effects(
    asked: Sequence[str] | None, skipped: list[str]
) -> tuple[list[str], list[str]]:
    """The effects of a case scene's reduced model (no body): ``theorem`` (the case's V and
    l) unless the effects asked leave it out; the theorem's own "V and mu vanish" note goes
    (the case's do not)."""
    notes = [n for n in skipped if not n.startswith("theorem:")]
    wanted = asked is None or "theorem" in asked
    return (["theorem"] if wanted else []), notes


def check_inertia(
    body: Body, effects: Sequence[str], inertia: Sequence[float] | None = None
) -> None:
    """Refuse a body whose masses' inertia disagrees with the given C, or with a case's
    ``inertia`` (A, B, C) (one-line reason).

    The theorem's reduced model alone (effects = ["theorem"]) uses C as given.
    """
    if not any(e != "theorem" for e in effects) and not body.has_elements:
        return
    reason = inertia_mismatch(body, target=inertia)
    if reason is not None:
        fix = "give C to match the masses" if inertia is None else "design the case again"
        raise InputError(f"body: {reason}; {fix} or fix the masses")


#: relative size of a linear term of V that counts as a centre of mass off O
CENTRE_RTOL = 1e-6


def check_centre(system: RigidBodySystem, realises: Sequence[str]) -> None:
    """Refuse a body that claims the theorem's V but whose V has a linear term (one line).

    The theorem's V has no term linear in gamma; under uniform gravity such a term is
    ``M g (r_cm . gamma)``, so gravity requires the centre of mass at O (unless other linear
    terms cancel it: the check is on the whole V). Only for designs that claim ``V``.
    """
    if "V" not in realises or "gravity" not in system.effects:
        return
    bank = system.polynomial_bank
    degree = bank.exponents.sum(axis=1)
    a = np.zeros(3)
    for row, e in zip(bank.coefficients, bank.exponents, strict=True):
        if int(e.sum()) == 1:
            a[int(np.argmax(e))] += row[0]
    pts, m = body_mass_points(system.body)
    g = system.body.fields.get("gravity", ())
    scale = abs(g[0]) * float(np.abs(m) @ np.linalg.norm(pts, axis=1)) if len(g) and len(m) else 0.0
    scale = max(scale, float(np.max(np.abs(bank.coefficients[degree >= 1, 0]), initial=0.0)))
    if scale == 0.0 or float(np.linalg.norm(a)) <= CENTRE_RTOL * scale:
        return
    _, total, centre = mass_inertia(system.body)
    raise InputError(
        "body: V has a linear term a . gamma with a = "
        f"({fmt(a[0])}, {fmt(a[1])}, {fmt(a[2])}) J that the theorem's V does not have (the "
        f"design claims V); the centre of mass of {fmt(total, PRECISE)} kg is at ({fmt(centre[0])},"
        " "
        f"{fmt(centre[1])}, {fmt(centre[2])}) m: gravity needs it at O"
    )


def initial_state(
    system: RigidBodySystem, initial: Any, rate: float = 0.0
) -> tuple[np.ndarray, float | None]:
    """The 7-state ``(p, q, r, w, x, y, z)`` from an initial spec, and the level if any.

    ``initial`` is a mapping as returned by :func:`parse_initial` (or a raw ``[initial]``
    mapping), or ``(p, q, r, gamma1, gamma2, gamma3)``. With ``rate = n != 0`` the spec's
    angular velocity (``omega``, or ``p`` and ``q``) is read in axes turning at n about Z and
    the returned state is the body's own (``omega + n gamma``; the level of I3 is the same in
    both readings, so r is solved from it in the body's own system).
    """
    if isinstance(initial, Mapping) and "states" in initial:
        initial = np.asarray(initial["states"], dtype=float)[0]  # the first of a set
    spec = initial_spec(initial)
    gamma = spec["gamma"]
    R0 = attitude_from_gamma(gamma, spec.get("precession", 0.0))
    quat = rotation_quaternion(R0)
    level = spec.get("level")
    g = quaternion_gamma(quat[None])[0]
    if level is not None:
        p0, q0 = spec["p"] + rate * g[0], spec["q"] + rate * g[1]
        omega = np.array([p0, q0, system.solve_r(g, p0, q0, level)])
    else:
        omega = np.asarray(spec["omega"], dtype=float) + rate * g
    return np.concatenate([omega, quat]), level


def _in_coils_field(setup: SimulationSetup) -> tuple[SimulationSetup, list[str]]:
    """The ``coils`` effect: the body's magnetic field becomes the field apparatus' own, the
    designed a1, a2 plus the coil pairs' degree >= 3 harmonics that design.json records
    (``frontier.realised.apparatus.error_legendre``, :mod:`chargedesign.physical.coils`)."""
    realised = ((getattr(setup.design, "frontier", None) or {}).get("realised")) or {}
    apparatus = realised.get("apparatus") or {}
    error = apparatus.get("error_legendre")
    if not error:
        raise InputError(
            "effects: coils needs the field apparatus design.json records (frontier.realised."
            "apparatus: a physical design with a magnetic field, `chargedesign design`)"
        )
    designed = list(setup.body.fields.get("magnetic", ()))
    size = max(len(designed), len(error))
    total = np.zeros(size)
    total[: len(designed)] += designed
    total[: len(error)] += np.asarray(error, dtype=float)
    body = dataclasses.replace(
        setup.body, fields={**setup.body.fields, "magnetic": tuple(float(v) for v in total)}
    )
    pairs = ", ".join(
        f"{p['kind']} pair of radius {fmt(p['radius_m'])} m" for p in apparatus.get("pairs", [])
    )
    note = (
        f"coils: the magnetic field is the apparatus' ({pairs}): the designed terms plus its "
        f"harmonics to degree {size} (error {fmt(apparatus.get('harmonic_error', 0.0))} of the "
        "designed field over the body region)"
    )
    return dataclasses.replace(setup, body=body), [note]


def prepare(
    source: Any = None,
    *,
    initial: Any = None,
    level: float | None = None,
    design_progress: Callable[[str], None] | None = None,
    **overrides: Any,
) -> tuple[RigidBodySystem, np.ndarray, float | None, SimulationSetup, list[str]]:
    """Build the system and initial state (see :func:`simulate` for the arguments).

    Returns the system, the initial state ``(7,)``, the level (or None), a copy of the setup
    with the merged options (a setup passed in keeps its own options; a pending design is
    done in it, once) and the notes.
    """
    setup = setup_from_source(source)
    options = merge_options(setup.options, overrides)
    body_info = dict(setup.body_info)
    pending_notes: list[str] = []
    if setup.design_scene is not None:
        if needs_elements(options.effects):
            design_pending(setup, design_progress)
            body_info = dict(setup.body_info)
        else:
            shape = setup.design_scene.body.table.get("shape")
            body_info["origin"] = (
                f"[body] region (shape = {shape!r}) not designed: the theorem effect is the "
                "reduced model"
            )
            body_info["counts"] = body_counts(setup.body)
            pending_notes.append(
                f"body: the [body] region (shape = {shape!r}) was not designed; the theorem "
                "effect is the reduced model (its V and mu), no elements"
            )

    # refused before any work when turning axes are asked of a body without a frame reading
    axes, rate = resolve_axes(options.axes, setup.larmor)
    setup = dataclasses.replace(
        setup, options=options, body_info=body_info, axes=axes, axes_rate=rate
    )
    coil_notes: list[str] = []
    asked = options.effects
    if asked is not None and not isinstance(asked, str) and "coils" in asked:
        setup, coil_notes = _in_coils_field(setup)
        asked = [e for e in asked if e != "coils"]
    effects, skipped = select_effects(setup.body, asked)
    # a case's numeric functions (a singular case is refused here), built once for the run
    case = setup.case if setup.case is not None else _case_functions(setup.design)
    inertia = None if case is None else [float(m) for m in case.case.inertia]
    if case is not None and setup.design is None:
        # the reduced model of a case scene: the theorem effect is the case's V and l
        effects, skipped = reduced_case_effects(asked, skipped)
    skipped = coil_notes + skipped
    # a case design's masses move with the case's inertia: checked even when no effect acts
    if any(e != "theorem" for e in effects) or (inertia is not None and setup.design is not None):
        check_inertia(setup.body, effects, inertia)
    notes = list(setup.notes) + pending_notes + skipped
    if not effects:
        notes.append("no effect acts: torque-free motion")
    system = RigidBodySystem(setup.body, effects, options.route, inertia=inertia, case=case)
    if system.dissipative and options.method == "taylor":
        # heyoka's compiled route takes polynomial torques only: the eddy torque runs on scipy
        options = dataclasses.replace(options, method="DOP853")
        setup = dataclasses.replace(setup, options=options)
        notes.append(
            "method: DOP853 (solve_ivp) instead of taylor, which does not take the eddy "
            f"torque; rtol {fmt(options.rtol, PLAIN)}, atol {fmt(options.atol, PLAIN)}"
        )
    if setup.design is not None and "case" not in setup.design.further_keys:
        check_centre(system, setup.design.realises)  # a case's V may have a linear term
    setup = dataclasses.replace(setup, case=case)
    if "theorem" in effects and options.route == "direct":
        notes.append("theorem: the reduced model has one route (the evaluators)")
    spec = setup.initial if initial is None else initial
    if level is not None:
        spec = with_level(spec, level)
        notes.append(
            f"start moved to the level I3 = {fmt(float(level), PLAIN)} J s (r solved from it)"
            + ("" if float(level) == 0.0 else "; off I3 = 0 the theorem's I4 is no integral")
        )
    y0, start_level = initial_state(system, spec, setup.axes_rate)
    if system.singular:
        g3 = float(quaternion_gamma(y0[None, 3:])[0, 2])
        check_off_singular_plane(g3, options.gamma3_min, "initial.gamma")
    return system, y0, start_level, setup, notes


def simulate(
    source: Any = None,
    *,
    effects: Sequence[str] | None = None,
    t_end: float | None = None,
    initial: Any = None,
    rtol: float | None = None,
    atol: float | None = None,
    method: str | None = None,
    max_step: float | None = None,
    step: float | None = None,
    samples: int | None = None,
    route: str | None = None,
    gamma3_min: float | None = None,
    poincare: str | bool | None = None,
    level: float | None = None,
    tol: float | None = None,
    monitors: Sequence[Any] | None = None,
    axes: str | None = None,
    progress: Callable[[float], None] | None = None,
    design_progress: Callable[[str], None] | None = None,
) -> SimulationResult:
    """Simulate one trajectory of a scene or design under the effects it calls for.

    Parameters
    ----------
    source : Scene, Design, Parameters, SimulationSetup, str, PathLike or None
        A scene (TOML path or :class:`~chargedesign.scene.Scene`), a design (``.json`` path
        or :class:`~chargedesign.body.Design`), bare theorem parameters, a setup from
        :func:`setup_from_source` (reused: its body is designed at most once), or None for
        the embedded default scene, whose ``[body]`` region is designed on the fly.
    effects : sequence of str, optional
        Among ``lorentz``, ``electric``, ``magnetization``, ``gravity``, ``theorem``. Default:
        the scene's ``simulation.effects``, else every physical effect with a source for a
        body (a scene's ``[body]`` region is designed for it), else ``theorem``. Effects
        without a source are skipped with a note; ``["theorem"]`` alone designs nothing.
    t_end : float, optional
        Duration, s (default 100).
    initial : mapping or array_like, optional
        Like ``[initial]`` (``omega`` and ``gamma``, or ``level = "I3=0"`` with ``gamma``,
        ``p``, ``q``), or ``(p, q, r, gamma1, gamma2, gamma3)``.
    rtol, atol, method, max_step, step, samples, route, gamma3_min, tol
        As the ``[simulation]`` keys (``method`` default ``taylor``; ``tol`` its tolerance,
        default machine epsilon; ``rtol``/``atol`` for the solve_ivp methods).
    monitors : sequence of str or callable, optional
        Integrals to monitor (:data:`chargedesign.simulation.monitors.MONITORS`), or callables
        ``f(omega (T, 3), gamma (T, 3)) -> (T,)``; their drifts are reported even where they
        are no integrals.
    poincare : str or bool, optional
        Record upward zero crossings of this state (True: the scene's section, default
        ``gamma1``).
    level : float, optional
        Start on ``I3 = level`` (J s) instead of the initial spec's level: same gamma, p and
        q, r solved from the level (see :func:`with_level`).
    axes : {"turning", "inertial"}, optional
        The axes the motion is written in (the scene's ``simulation.axes``): ``turning`` (the
        default for a ``frame`` body) reads the body's own motion (n = 0) in axes turning at
        its ``larmor.rate`` about Z, with the integrals (I1, I3, I4) of the theorem with that
        n; ``inertial`` writes it as integrated (integrals with the body's n = 0). A body
        without a frame reading has only ``inertial`` (``turning`` is refused). The initial
        state is given in the axes the motion is written in.
    progress : callable, optional
        ``progress(fraction)`` during the integration.
    design_progress : callable, optional
        ``progress(message)`` while a scene's ``[body]`` region is designed.

    Returns
    -------
    SimulationResult

    Raises
    ------
    InputError
        Bad scene keys or arguments.
    SolverError
        The integrator failed.
    """
    system, y0, level, setup, notes = prepare(
        source,
        initial=initial,
        effects=None if effects is None else list(effects),
        t_end=t_end,
        rtol=rtol,
        atol=atol,
        method=method,
        max_step=max_step,
        step=step,
        samples=samples,
        route=route,
        gamma3_min=gamma3_min,
        tol=tol,
        monitors=None if monitors is None else list(monitors),
        axes=axes,
        level=level,
        design_progress=design_progress,
    )
    options = setup.options
    section = None
    if poincare is True or (poincare is None and setup.output.poincare):
        section = setup.output.poincare_section
    elif isinstance(poincare, str):
        check_choice(poincare, STATE_NAMES, "poincare")
        section = poincare
    if section is not None and options.method == "gauss-legendre":
        notes.append("poincare: needs the taylor or a solve_ivp method; no section recorded")
        section = None
    if section in ("p", "q", "r") and setup.axes_rate != 0.0:
        notes.append(
            f"poincare: the section {section} = 0 is taken in the body's own (inertial) "
            "reading; the points are written in the turning axes"
        )
    run = integrate_with_options(system, y0[None], options, poincare=section, progress=progress)
    return trajectory_result(system, run.times, run.states[0], run, level, setup, notes, section)


def integrate_with_options(
    system: RigidBodySystem,
    y0: np.ndarray,
    options: SimulationOptions,
    *,
    poincare: Any = None,
    progress: Any = None,
) -> Any:
    """:func:`integrate` with the scene's integration options (one place for both entries)."""

    check_run_caps(
        options.t_end, step=options.step, max_step=options.max_step, samples=options.samples
    )
    return integrate(
        system,
        y0,
        options.t_end,
        method=options.method,
        tol=options.tol,
        rtol=options.rtol,
        atol=options.atol,
        max_step=options.max_step,
        step=options.step,
        samples=options.samples,
        gamma3_min=options.gamma3_min if system.singular else None,
        poincare=poincare,
        progress=progress,
    )


def trajectory_result(
    system: RigidBodySystem,
    times: np.ndarray,
    states: np.ndarray,
    run: Any,
    level: float | None,
    setup: SimulationSetup,
    notes: list[str],
    section: str | None,
) -> SimulationResult:
    rate = setup.axes_rate
    poincare_points = run.poincare
    if rate != 0.0:
        states = turning_states(times, states, rate)
        poincare_points = turning_poincare(poincare_points, rate)
    omega = states[:, :3]
    quats = states[:, 3:]
    events = [dict(e) for e in run.events]
    all_notes = list(notes)
    for e in events:
        if e["kind"] == "singular_plane":
            all_notes.append(
                f"stopped at t = {fmt(e['t'], CELL)} s: |gamma3| = {fmt(abs(e['gamma3']))} reached"
                " the "
                f"singular plane threshold {fmt(e['threshold'], PLAIN)} (lambda or rho != 0)"
            )
    integrals = system.integrals(states, rate=rate)
    kinetic = 0.5 * np.einsum("ij,ij->i", omega * system.inertia_diagonal(), omega)
    opts = setup.options
    extra = dict(getattr(run, "extra", {}) or {})
    all_notes.extend(extra.get("notes", ()))
    gamma = quaternion_gamma(quats)
    omega_scale = float(np.max(np.abs(omega[0]))) if len(omega) else 0.0
    ctx = monitors_mod.Context(
        system=system,
        level=level,
        I3_start=float(integrals[0, 2]),
        I3_scale=max(system.C * max(omega_scale, 1.0), float(np.max(np.abs(integrals[:, 2])))),
        realises=realised_claims(setup, system),
        axes_rate=rate,
        case=setup.case,
    )
    monitor_table = monitors_mod.evaluate(ctx, omega, gamma, integrals, kinetic, opts.monitors)
    method = str(extra.get("method", opts.method))
    return SimulationResult(
        times=times,
        omega=omega.copy(),
        gamma=gamma,
        rotation=quaternion_rotation(quats),
        quaternion=quats.copy(),
        integrals=integrals,
        kinetic=kinetic,
        effects=list(system.effects),
        notes=all_notes,
        events=events,
        # the parameters the integrals were evaluated with: n = the axes' rate when turning
        parameters=dataclasses.replace(system.parameters, n=rate) if rate else system.parameters,
        route=system.route,
        method=method,
        rtol=opts.rtol,
        atol=opts.atol,
        tol=opts.tol if method == "taylor" else None,
        monitors=monitor_table,
        compile_seconds=float(extra.get("compile_seconds", 0.0)),
        t_end=opts.t_end,
        steps=run.steps,
        rhs_evaluations=run.rhs_evaluations,
        seconds=run.seconds,
        level=level,
        poincare=poincare_points,
        poincare_section=section,
        source=setup.source,
        body=dict(setup.body_info),
        axes=setup.axes,
        axes_rate=rate,
        larmor=None if setup.larmor is None else setup.larmor.to_dict(),
    )


def check_run_caps(
    t_end: float, *, step: float | None = None, max_step: float | None = None, samples: int = 2
) -> None:
    """Caps on a simulation's requested work (chargedesign.limits): output samples and the
    fixed-step count ``t_end / step`` (also ``t_end / max_step``); one-line errors."""
    if isinstance(samples, (int, np.integer)) and samples > MAX_SAMPLES:
        raise input_error(
            "simulation.samples", f"at most {MAX_SAMPLES} output samples (--samples)", samples
        )
    for name, value in (("step", step), ("max_step", max_step)):
        if value is None or not math.isfinite(value) or value <= 0:
            continue
        if t_end / value > MAX_STEPS:
            raise InputError(
                f"simulation.{name}: t_end / {name} = {fmt(t_end / value)} steps exceeds the cap "
                f"of {fmt(MAX_STEPS, PLAIN)} (chargedesign.limits.MAX_STEPS); give a larger {name}"
                " or a "
                "shorter t_end"
            )
