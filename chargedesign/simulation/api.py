"""Simulation scenes and the public entry :func:`simulate`.

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
"""

from __future__ import annotations

import dataclasses
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.body import Design, read_design
from chargedesign.designer import design_from_scene
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.formatting import CELL, ORDER, PLAIN, PRECISE, ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.physical.realism import typical_rate
from chargedesign.results import compact_repr
from chargedesign.scene import Scene, load_scene
from chargedesign.scene.simulation import (
    DEFAULT_INITIAL,
    SIMULATION_KEYS,
    OutputOptions,
    SimulationOptions,
    check_choice,
    parse_initial,
    parse_simulation_options,
)
from chargedesign.simulation import monitors as monitors_mod
from chargedesign.simulation.axes import resolve_axes, turning_poincare, turning_states
from chargedesign.simulation.integrate import STATE_NAMES, integrate
from chargedesign.simulation.result import SimulationResult
from chargedesign.simulation.system import (
    EFFECTS,
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
from chargedesign.validation import (
    as_array,
    as_finite_float,
    check_keys,
    check_run_caps,
    input_error,
)


@dataclass(repr=False)
class SimulationSetup:
    """Everything a run needs: the body, the initial-state spec and the options.

    Attributes
    ----------
    body : Body
        The body simulated (bare parameters until a pending design is done).
    initial : mapping or ndarray
        The initial-state spec (see :func:`parse_initial`).
    options, output : SimulationOptions, OutputOptions
    notes : list of str
    source : str
        Where the setup came from (a path, ``<default>``, ``<design>``, ...).
    design : Design or None
        The design simulated (read from a file, inline, or designed from the scene).
    design_scene : Scene or None
        A scene whose ``[body]`` region is still to be designed (see :func:`design_pending`).
    body_info : dict
        JSON-ready description of the body (``designed_from_scene``, ``origin``, ``counts``;
        for a designed body also ``shape``, ``candidates``, ``residuals``, ``realises``,
        ``design_seconds``); the result's summary reports it as ``body``.
    axes : str
        The axes the motion is written in: ``inertial`` or ``turning`` (set by
        :func:`prepare`).
    axes_rate : float
        Their rate about Z, 1/s: 0 for inertial axes, the frame reading's n for turning axes.
    case : CaseFunctions or None
        The numeric functions of the case a design carries (set by :func:`prepare`; None:
        the theorem's), built once for the refusal and the ``F`` monitor.
    """

    body: Body
    initial: Mapping[str, Any] | np.ndarray
    options: SimulationOptions = field(default_factory=SimulationOptions)
    output: OutputOptions = field(default_factory=OutputOptions)
    notes: list[str] = field(default_factory=list)
    source: str = ""
    design: Any = None
    design_scene: Any = None
    body_info: dict[str, Any] = field(default_factory=dict)
    axes: str = "inertial"
    axes_rate: float = 0.0
    case: Any = None

    @property
    def larmor(self) -> Any:
        """The simulated design's Larmor reading (None: no design or no ``larmor`` key)."""
        return getattr(self.design, "larmor", None)

    def __repr__(self) -> str:
        return compact_repr(
            "SimulationSetup",
            {
                "source": self.source,
                "charges": len(self.body.charge_values),
                "dipoles": len(self.body.dipole_moments),
                "masses": len(self.body.mass_values),
                "effects": self.options.effects,
                "t_end": self.options.t_end,
                "method": self.options.method,
                "pending_design": self.design_scene is not None,
            },
        )


def _inline_design(body: Mapping[str, Any], scene: Any) -> Any:

    def block(name: str, keys: tuple[str, str]) -> tuple[Any, Any]:
        b = body.get(name, {})
        if not isinstance(b, Mapping):
            raise input_error(f"body.{name}", "a table", b)
        check_keys(b, keys, f"body.{name}")
        return b.get(keys[0], []), b.get(keys[1], [])

    cp, cv = block("charges", ("positions", "values"))
    mp, mv = block("masses", ("positions", "values"))
    dp, dm = block("dipoles", ("positions", "moments"))
    return Design(
        parameters=scene.parameters,
        fields=dict(scene.fields),
        charge_positions=cp,
        charge_values=cv,
        mass_positions=mp,
        mass_values=mv,
        dipole_positions=dp,
        dipole_moments=dm,
    )


def _case_functions(design: Any) -> Any:
    """The numeric functions of the case a design carries (None: the theorem's)."""
    if design is None or "case" not in design.further_keys:
        return None
    from chargedesign.model.case_numeric import simulated_case_functions  # sympy: a case only

    return simulated_case_functions(design.further_keys["case"])


def setup_from_scene(scene: Any) -> SimulationSetup:
    """Read the simulation tables of a :class:`~chargedesign.scene.Scene`."""

    notes: list[str] = []
    body_table = scene.body.table if scene.body is not None else {}
    design = None
    origin = ""
    if "design" in body_table:
        if any(k in body_table for k in ("charges", "masses", "dipoles")):
            raise InputError("body: give either design = PATH or inline elements, not both")
        path_value = body_table["design"]
        if not isinstance(path_value, str) or not path_value:
            raise input_error("body.design", "a path to design.json", path_value)
        path = Path(path_value)
        if not path.is_absolute() and scene.source not in ("<default>", "<dict>"):
            path = Path(scene.source).parent / path
        design = read_design(path)
        origin = str(path)
        if scene.parameters != Parameters() and scene.parameters != design.parameters:
            notes.append("the scene's [parameters] differ from the design's; the design's are used")
    elif scene.case is not None:  # a case of (ep): masses in gravity, designed at once
        from chargedesign.designer.case_design import design_case_scene  # sympy: a case only

        design = design_case_scene(scene).design
        origin = f"[case] {scene.case.name}: masses designed on the [body] region"
    elif any(k in body_table for k in ("charges", "masses", "dipoles")):
        design = _inline_design(body_table, scene)
        origin = "inline [body] elements"
    pending = None
    if design is not None:
        body = Body.from_design(design, dict(scene.fields))
        notes += body.notes
        if body.parameters == Parameters():
            body, note = _inertia_from_masses(body)
            if note:
                notes.append(note)
        info = _body_info(body, origin)
    else:
        body = Body(parameters=scene.parameters, fields=dict(scene.fields))
        if "shape" in body_table:
            # designed when a run needs its elements (not for the theorem effect alone)
            pending = scene
            info = {"designed_from_scene": False, "origin": "[body] region, not designed yet"}
        else:
            info = _body_info(body, "none: the theorem's parameters only")
    if scene.initial is None:
        initial = parse_initial(DEFAULT_INITIAL, "initial")
        notes.append("no [initial]: gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4 on I3 = 0")
        notes += _slow_body_notes(body.parameters)
    else:
        initial = dict(scene.initial)
    return SimulationSetup(
        body=body,
        initial=initial,
        options=dataclasses.replace(scene.simulation),
        output=dataclasses.replace(scene.output),
        notes=notes,
        source=scene.source,
        design=design,
        design_scene=pending,
        body_info=info,
    )


def realised_claims(setup: SimulationSetup, system: RigidBodySystem) -> tuple[str, ...]:
    """What the simulated design claims; a massless body's inertia is the given C itself."""
    if setup.design is None:
        return ()
    out = list(setup.design.realises)
    _, m = body_mass_points(system.body)
    if "inertia" not in out and not np.any(m != 0.0):
        out.append("inertia")
    return tuple(out)


def _inertia_from_masses(body: Body) -> tuple[Body, str]:
    """A body without theorem parameters takes C from its masses (C = I_zz about O)."""
    inertia, total, _ = mass_inertia(body)
    C = float(inertia[2, 2])
    if total <= 0.0 or not C > 0.0:
        return body, ""
    body = dataclasses.replace(body, parameters=Parameters(C=C))
    return body, f"no [parameters]: C = {fmt(C, CELL)} kg m^2 from the masses (I_zz about O)"


def check_inertia(body: Body, effects: Sequence[str]) -> None:
    """Refuse a body whose masses' inertia disagrees with the given C (one-line reason).

    The theorem's reduced model alone (effects = ["theorem"]) uses C as given.
    """
    if not any(e != "theorem" for e in effects) and not body.has_elements:
        return
    reason = inertia_mismatch(body)
    if reason is not None:
        raise InputError(f"body: {reason}; give C to match the masses or fix the masses")


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


def _counts(body: Body) -> dict[str, int]:
    return {
        "charges": len(body.charge_values),
        "dipoles": len(body.dipole_moments),
        "masses": len(body.mass_values),
    }


#: a default start turning this many times faster than the body's own rate gets a note
SLOW_BODY_FACTOR = 1e3


def _slow_body_notes(params: Parameters) -> list[str]:
    """A note when the default start turns far faster than the body's own rate.

    The default start (p, q) = (0.6, -0.4) 1/s suits the unit-scale case. A physical body's
    theorem terms turn at ``2 max(|n|, |K|, sqrt|kappa|, ...)`` (micro-radians per second for
    the embedded default): started at 0.7 1/s, its designed torques are a tiny fraction of
    the kinetic terms and I4's drift tests them weakly. Said, not changed: the start is the
    user's to give.
    """

    start = math.hypot(DEFAULT_INITIAL["p"], DEFAULT_INITIAL["q"])
    rate = typical_rate(params)
    if rate == 0.0 or start < SLOW_BODY_FACTOR * rate:
        return []
    return [
        f"the default start turns at |(p, q)| = {fmt(start)} 1/s, {fmt(start / rate, ROUGH)} times"
        " this "
        f"body's own rate {fmt(rate)} 1/s (2 max(|n|, |K|, sqrt|kappa|, ...)): its designed "
        f"torques are then about {fmt((rate / start) ** 2, ORDER)} of the kinetic terms, which I4's"
        " "
        "drift tests only weakly; give [initial] (or initial=) at the body's rate"
    ]


def _body_info(body: Body, origin: str) -> dict[str, Any]:
    return {"designed_from_scene": False, "origin": origin, "counts": _counts(body)}


def _needs_elements(effects: Sequence[str] | None) -> bool:
    """True unless the effects asked for are only the theorem's reduced model."""
    if effects is None:
        return True
    return any(name != "theorem" for name in effects if name in EFFECTS)


def design_pending(
    setup: SimulationSetup, progress: Callable[[str], None] | None = None
) -> SimulationSetup:
    """Design the body of a setup whose scene gives a ``[body]`` region (once; in place).

    Runs :func:`chargedesign.designer.design_from_scene` with the scene's ``[design]`` table and
    replaces ``setup.body`` by the designed elements in the scene's fields (each kind the
    scene gives replaces the design's). Does nothing when nothing is pending.

    Parameters
    ----------
    setup : SimulationSetup
    progress : callable, optional
        ``progress(message)`` with the designer's stages.

    Returns
    -------
    SimulationSetup
        The same setup, designed.

    Raises
    ------
    InfeasibleError
        The scene's targets cannot be realised in its region (the message says how to
        simulate the reduced model instead).
    InputError, SolverError
        As :func:`~chargedesign.designer.design_from_scene`.
    """
    scene = setup.design_scene
    if scene is None:
        return setup

    t0 = time.perf_counter()
    try:
        result = design_from_scene(scene, progress=progress, frontier=False)
    except InfeasibleError as exc:
        raise InfeasibleError(
            f"{exc} (to simulate the theorem's reduced model instead: effects = ['theorem'])"
        ) from exc
    seconds = time.perf_counter() - t0
    design = result.design
    body = Body.from_design(design, dict(scene.fields))
    summary = result.summary()
    residuals = summary["residuals"]
    shape = str(scene.body.table.get("shape"))
    counts = _counts(body)
    setup.body = body
    setup.design = design
    setup.design_scene = None
    setup.body_info = {
        "designed_from_scene": True,
        "origin": f"designed from the scene's [body] (shape = {shape!r})",
        "counts": counts,
        "shape": shape,
        "candidates": len(result.candidates),
        "residuals": {
            "max_after_polish": residuals["max_after_polish"],
            "tolerance": residuals["tolerance"],
            "after_polish": dict(residuals["after_polish"]),
            "before_polish": dict(residuals["before_polish"]),
        },
        "realises": list(design.realises),
        "fields": {kind: list(coeffs) for kind, coeffs in body.fields.items()},
        "design_seconds": seconds,
    }
    setup.notes.append(
        f"body designed from the scene's [body] ({shape}, {len(result.candidates)} "
        f"candidates): {counts['charges']} charges, {counts['dipoles']} dipoles, "
        f"{counts['masses']} masses; largest relative residual "
        f"{fmt(residuals['max_after_polish'], ROUGH)} (tolerance"
        f" {fmt(residuals['tolerance'], ROUGH)}); "
        f"realises {', '.join(design.realises) or 'nothing'}"
    )
    missing = [k for k in ("mu", "V", "inertia") if k not in design.realises]
    if missing:
        setup.notes.append(
            f"the design does not realise {', '.join(missing)}: I4 is the theorem's integral "
            "only for a body that realises mu, V and inertia"
        )
    setup.notes += [f"design: {note}" for note in result.notes]
    setup.notes += body.notes
    return setup


def setup_from_source(source: Any = None) -> SimulationSetup:
    """A setup from a scene, a design, a path (.toml scene, .json design) or None (default)."""

    if source is None:
        return setup_from_scene(load_scene(None))
    if isinstance(source, SimulationSetup):
        return source
    if isinstance(source, Scene):
        return setup_from_scene(source)
    if isinstance(source, Design):
        body = Body.from_design(source)
        return SimulationSetup(
            body=body,
            initial=parse_initial(DEFAULT_INITIAL),
            notes=[
                "default initial state: gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4 on I3 = 0",
                *_slow_body_notes(body.parameters),
                *body.notes,
            ],
            source="<design>",
            design=source,
            body_info=_body_info(body, "a design"),
        )
    if isinstance(source, Parameters):
        body = Body(parameters=source)
        return SimulationSetup(
            body=body,
            initial=parse_initial(DEFAULT_INITIAL),
            source="<parameters>",
            body_info=_body_info(body, "none: the theorem's parameters only"),
        )
    if isinstance(source, (str, os.PathLike)):
        path = Path(source)
        if path.suffix.lower() == ".json":
            setup = setup_from_source(read_design(path))
            setup.source = str(path)
            setup.body_info["origin"] = f"design file {path}"
            return setup
        return setup_from_scene(load_scene(path))
    raise input_error("simulate", "a scene, a design, a path or None", source)


# --------------------------------------------------------------------------- running
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
    if isinstance(initial, Mapping):
        spec = dict(initial) if "gamma_norm" in initial else parse_initial(initial)
    else:
        arr = as_array(initial, "initial", (6,))
        spec = parse_initial({"omega": arr[:3].tolist(), "gamma": arr[3:].tolist()})
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


def with_level(initial: Any, level: float) -> dict[str, Any]:
    """An initial spec moved onto the level ``I3 = level`` (J s).

    Keeps gamma, the precession and p, q (of ``omega`` when the spec gives it); r is then
    solved from the level (:meth:`RigidBodySystem.solve_r`). Used to start off the level
    ``I3 = 0``, where the theorem's I4 is not an integral.

    Parameters
    ----------
    initial : mapping or array_like
        As for :func:`initial_state`.
    level : float
        The value of the physical I3, J s.

    Returns
    -------
    dict
        A spec as returned by :func:`parse_initial`.
    """
    value = as_finite_float(level, "level")
    if isinstance(initial, Mapping):
        spec = dict(initial) if "gamma_norm" in initial else parse_initial(initial)
    else:
        arr = as_array(initial, "initial", (6,))
        spec = parse_initial({"omega": arr[:3].tolist(), "gamma": arr[3:].tolist()})
    out = {k: spec[k] for k in ("gamma", "gamma_norm", "precession")}
    if "omega" in spec:
        omega = np.asarray(spec["omega"], dtype=float)
        out["p"], out["q"] = float(omega[0]), float(omega[1])
    else:
        out["p"], out["q"] = spec["p"], spec["q"]
    out["level"] = value
    return out


def _merge_options(base: SimulationOptions, overrides: Mapping[str, Any]) -> SimulationOptions:
    """The setup's options with the call's overrides (None keeps the setup's)."""
    table = {k: v for k, v in overrides.items() if v is not None}
    merged = {
        k: getattr(base, k)
        for k in SIMULATION_KEYS
        if getattr(base, k) is not None and not (k == "max_step" and getattr(base, k) == math.inf)
    }
    merged.update(table)
    return parse_simulation_options(merged, "simulation")


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
    options = _merge_options(setup.options, overrides)
    body_info = dict(setup.body_info)
    pending_notes: list[str] = []
    if setup.design_scene is not None:
        if _needs_elements(options.effects):
            design_pending(setup, design_progress)
            body_info = dict(setup.body_info)
        else:
            shape = setup.design_scene.body.table.get("shape")
            body_info["origin"] = (
                f"[body] region (shape = {shape!r}) not designed: the theorem effect is the "
                "reduced model"
            )
            body_info["counts"] = _counts(setup.body)
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
    skipped = coil_notes + skipped
    if any(e != "theorem" for e in effects):
        check_inertia(setup.body, effects)
    notes = list(setup.notes) + pending_notes + skipped
    if not effects:
        notes.append("no effect acts: torque-free motion")
    system = RigidBodySystem(setup.body, effects, options.route)
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
    # a case of another inertia than diag(2C, 2C, C) is refused here
    setup = dataclasses.replace(setup, case=_case_functions(setup.design))
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
        if abs(g3) <= options.gamma3_min:
            raise input_error(
                "initial.gamma", f"|gamma3| > gamma3_min = {fmt(options.gamma3_min, PLAIN)}", g3
            )
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
        section = check_choice(poincare, "poincare", STATE_NAMES)
    if section is not None and options.method == "gauss-legendre":
        notes.append("poincare: needs the taylor or a solve_ivp method; no section recorded")
        section = None
    if section in ("p", "q", "r") and setup.axes_rate != 0.0:
        notes.append(
            f"poincare: the section {section} = 0 is taken in the body's own (inertial) "
            "reading; the points are written in the turning axes"
        )
    run = integrate_with_options(system, y0[None], options, poincare=section, progress=progress)
    return _result(system, run.times, run.states[0], run, level, setup, notes, section)


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


def simulate_batch(
    source: Any,
    initial_states: Any,
    **kwargs: Any,
) -> list[SimulationResult]:
    """Simulate many trajectories of one body in a single integrator call.

    Parameters
    ----------
    source
        As for :func:`simulate`.
    initial_states : array_like, shape (m, 6)
        ``(p, q, r, gamma1, gamma2, gamma3)`` per trajectory.
    **kwargs
        ``effects``, ``t_end``, ``rtol``, ``atol``, ``method``, ``max_step``, ``step``,
        ``samples``, ``route``, ``gamma3_min``, ``progress``, ``design_progress`` as for
        :func:`simulate`.

    Notes
    -----
    With ``taylor`` (the default) the trajectories run on heyoka batch integrators: each has
    its own step size and a singular-plane event stops only its own trajectory (the others
    keep their last state after it). With the solve_ivp methods one adaptive step size serves
    all trajectories and an event on any trajectory stops the whole batch. For the summaries
    of many trajectories see :func:`chargedesign.simulation.ensemble.simulate_ensemble`.
    """
    progress = kwargs.pop("progress", None)
    states = as_array(initial_states, "initial_states", (None, 6))
    system, _, _, setup, notes = prepare(source, **kwargs)
    y0 = np.array([initial_state(system, s, setup.axes_rate)[0] for s in states])
    options = setup.options
    if system.singular:
        g3 = quaternion_gamma(y0[:, 3:])[:, 2]
        if np.any(np.abs(g3) <= options.gamma3_min):
            bad = int(np.argmin(np.abs(g3)))
            raise input_error(
                f"initial_states[{bad}]",
                f"|gamma3| > gamma3_min = {fmt(options.gamma3_min, PLAIN)}",
                g3[bad],
            )
    run = integrate_with_options(system, y0, options, progress=progress)
    return [
        _result(system, run.times, run.states[i], run, None, setup, notes, None)
        for i in range(len(y0))
    ]


def _result(
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
