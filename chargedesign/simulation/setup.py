"""A run's setup: the body, the initial-state spec and the options, from a scene, a design,
bare parameters or a path (:func:`setup_from_source`).

The scene's tables are read and checked in :mod:`chargedesign.scene.simulation`; this module
builds the simulated :class:`~chargedesign.simulation.system.Body` from them (a design file,
inline elements, a ``[case]`` designed at once, or a ``[body]`` region left pending for
:func:`chargedesign.simulation.pending_design.design_pending`).
"""

from __future__ import annotations

import dataclasses
import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.body import Design, read_design
from chargedesign.designer.pipeline import design_from_scene
from chargedesign.formatting import CELL, ORDER, ROUGH, fmt
from chargedesign.params import Parameters
from chargedesign.physical.realism import typical_rate
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
)
from chargedesign.simulation.system import (
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
        design = design_from_scene(scene).design
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
