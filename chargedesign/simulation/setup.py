"""A run's setup: the body, the initial-state spec and the options, from a scene, a design,
bare parameters or a path (:func:`setup_from_source`).

The scene's tables are read and checked in :mod:`chargedesign.scene.simulation`; this module
builds the simulated :class:`~chargedesign.simulation.system.Body` from them (a design file,
inline elements, a ``[case]`` designed at once, or a ``[body]`` region left pending for
:func:`design_pending`, which designs it when a run first needs its elements: a run whose
effects are only ``theorem`` (:func:`needs_elements` false) does not design it).
"""

from __future__ import annotations

import dataclasses
import os
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.body import Design, read_design
from chargedesign.errors import InfeasibleError
from chargedesign.formatting import CELL, ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.physical.realism import typical_rate
from chargedesign.readers import refuse_other_kind, sniff_kind
from chargedesign.results import compact_repr
from chargedesign.scene import Scene, load_scene
from chargedesign.scene.simulation import (
    DEFAULT_INITIAL,
    OutputOptions,
    SimulationOptions,
    design_path,
    has_inline_elements,
    inline_elements,
    parse_initial,
    resolve_periods,
)
from chargedesign.simulation.system import (
    EFFECTS,
    Body,
    RigidBodySystem,
    body_mass_points,
    mass_inertia,
)
from chargedesign.validation import input_error


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


def _inline_design(body: Mapping[str, Any], scene: Any) -> Design:
    """The design of a ``[body]`` that gives its elements inline (checked by the design)."""
    blocks = inline_elements(body)
    return Design(
        parameters=scene.parameters,
        fields=dict(scene.fields),
        charge_positions=blocks["charges"][0],
        charge_values=blocks["charges"][1],
        mass_positions=blocks["masses"][0],
        mass_values=blocks["masses"][1],
        dipole_positions=blocks["dipoles"][0],
        dipole_moments=blocks["dipoles"][1],
    )


def setup_from_scene(scene: Any) -> SimulationSetup:
    """Read the simulation tables of a :class:`~chargedesign.scene.Scene`."""

    notes: list[str] = []
    body_table = scene.body.table if scene.body is not None else {}
    design = None
    case = None
    origin = ""
    if "design" in body_table:
        path = design_path(body_table, scene.source)
        design = read_design(path)
        origin = str(path)
        if scene.parameters != Parameters() and scene.parameters != design.parameters:
            notes.append("the scene's [parameters] differ from the design's; the design's are used")
    elif "case" in scene.tables and not body_table:
        # a case of (ep) without a body: its reduced model (the case's V and l, any inertia)
        from chargedesign.model.case_numeric import simulated_functions  # sympy: a case only

        case = simulated_functions(scene.case)
        A, B, C = (float(m) for m in case.case.inertia)
        notes.append(
            f"case {case.case.name}: the reduced model of (ep), inertia diag({fmt(A, CELL)}, "
            f"{fmt(B, CELL)}, {fmt(C, CELL)}) kg m^2, its V and l (the theorem effect)"
        )
        origin = f"none: the reduced model of the [case] {case.case.name}"
    elif scene.case is not None:  # a case of (ep): masses in gravity, designed at once
        # the designer here, not at import (scipy.sparse, scipy.linalg): see design_pending
        from chargedesign.designer.pipeline import design_from_scene

        design = design_from_scene(scene).recorded_design()  # its whole record, certificate too
        origin = f"[case] {scene.case.name}: masses designed on the [body] region"
    elif has_inline_elements(body_table):
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
    elif case is not None:
        body = Body(parameters=Parameters(C=float(case.case.inertia[2])), fields=dict(scene.fields))
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
        initial, start_notes = default_initial(body.parameters)
        notes += start_notes
    else:
        initial = dict(scene.initial)
    options, period_notes = resolve_periods(scene.simulation, body.parameters, initial)
    notes += period_notes
    return SimulationSetup(
        body=body,
        initial=initial,
        options=dataclasses.replace(options),
        output=dataclasses.replace(scene.output),
        notes=notes,
        source=scene.source,
        design=design,
        design_scene=pending,
        body_info=info,
        case=case,
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


def body_counts(body: Body) -> dict[str, int]:
    return {
        "charges": len(body.charge_values),
        "dipoles": len(body.dipole_moments),
        "masses": len(body.mass_values),
    }


#: a default start turning this many times faster (or slower) than the body's own rate is
#: scaled to it
SLOW_BODY_FACTOR = 1e3
#: the rate the default start suits: the unit-scale case's (c = 0.3, d = -0.4, n = 0.7,
#: K = 0.5, kappa = 0.9; examples/scenes/unit_scale.toml), ``2 sqrt(0.9)`` 1/s
UNIT_SCALE_RATE = typical_rate(Parameters(c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9))


def default_initial(params: Parameters) -> tuple[dict[str, Any], list[str]]:
    """The start of a run that gives none, and the note that says it.

    The default start (gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4 on I3 = 0) suits the
    unit-scale case, whose terms turn at ``2 sqrt(0.9)`` 1/s. A body whose own rate
    (:func:`~chargedesign.physical.realism.typical_rate`, ``2 max(|n|, |K|, sqrt|kappa|,
    ...)``) is more than :data:`SLOW_BODY_FACTOR` away from that gets the same start with
    p and q scaled by ``rate / UNIT_SCALE_RATE``: the same motion on its own time scale (the
    embedded default, at 6.6e-6 1/s, was started 1.1e5 times too fast: 36 million steps).

    Parameters
    ----------
    params : Parameters
        The body's theorem parameters.

    Returns
    -------
    (dict, list of str)
        The spec as :func:`parse_initial` returns it, and one note.
    """
    rate = typical_rate(params)
    factor = rate / UNIT_SCALE_RATE
    table = dict(DEFAULT_INITIAL)
    if rate > 0.0 and not 1.0 / SLOW_BODY_FACTOR <= factor <= SLOW_BODY_FACTOR:
        table["p"] = DEFAULT_INITIAL["p"] * factor
        table["q"] = DEFAULT_INITIAL["q"] * factor
        note = (
            f"no [initial]: the default start (gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4 1/s "
            f"on I3 = 0) scaled to this body's own rate: p, q x {fmt(factor)} "
            f"(rate {fmt(rate)} 1/s against the unit-scale case's {fmt(UNIT_SCALE_RATE)})"
        )
    else:
        note = "no [initial]: gamma = (0.36, 0.48, 0.8), p = 0.6, q = -0.4 on I3 = 0"
    return parse_initial(table, "initial"), [note]


def needs_elements(effects: Sequence[str] | None) -> bool:
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
    # here, not at import: the designer loads scipy.sparse and scipy.linalg (about 0.4 s of
    # CPU), which a run of a written design.json never calls (tests/test_startup.py)
    from chargedesign.designer.pipeline import design_from_scene

    t0 = time.perf_counter()
    try:
        result = design_from_scene(scene, progress=progress, frontier=False)
    except InfeasibleError as exc:
        raise InfeasibleError(
            f"{exc} (to simulate the theorem's reduced model instead: effects = ['theorem'])"
        ) from exc
    seconds = time.perf_counter() - t0
    design = result.recorded_design(progress)  # written with its record, certificate too
    body = Body.from_design(design, dict(scene.fields))
    summary = result.summary()
    residuals = summary["residuals"]
    shape = str(scene.body.table.get("shape"))
    counts = body_counts(body)
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


def _body_info(body: Body, origin: str) -> dict[str, Any]:
    return {"designed_from_scene": False, "origin": origin, "counts": body_counts(body)}


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
        initial, start_notes = default_initial(body.parameters)
        return SimulationSetup(
            body=body,
            initial=initial,
            notes=[*start_notes, *body.notes],
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
        # a trajectory.csv, a bifurcation csv, a sweep file ...: one line naming both kinds
        kind = sniff_kind(path)
        if kind not in ("scene", "case"):
            refuse_other_kind(path, kind, "scene")
        return setup_from_scene(load_scene(path))
    raise input_error("simulate", "a scene, a design, a path or None", source)
