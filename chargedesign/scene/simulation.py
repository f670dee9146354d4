"""The simulation's scene tables: ``[simulation]``, ``[output]`` and ``[initial]`` parsed
into typed options (the keys are documented in :mod:`chargedesign.simulation.api`).

Part of the scene, so that the scene is parsed once without loading the integrator: the
method, route, monitor and state names are the vocabulary's.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.scene.keys import DECLARED, KEY, check_value, default_of, key_names
from chargedesign.scene.states import load_states, parse_states
from chargedesign.validation import (
    as_array,
    as_finite_float,
    check_keys,
    input_error,
    motion_rate,
)
from chargedesign.vocabulary import (
    EFFECTS,
    MONITOR_ALIASES,
    MONITOR_NAMES,
    STATE_NAMES,
)

# the tables' keys are the scene's declaration (the JSON Schema is generated from it too)
SIMULATION_KEYS = key_names("simulation")
INITIAL_KEYS = key_names("initial")
OUTPUT_KEYS = key_names("output")

#: the initial state when a scene has no [initial]: on I3 = 0, omega of order 1
DEFAULT_INITIAL: dict[str, Any] = {"gamma": [0.36, 0.48, 0.8], "level": "I3=0", "p": 0.6, "q": -0.4}


@dataclass
class SimulationOptions:
    """Validated ``[simulation]`` settings (see the module docstring for the keys)."""

    t_end: float = default_of("simulation", KEY.t_end)
    #: the run's length in periods of its fastest rate (None: t_end); the setup turns it into
    #: t_end once the body and the start are known (:func:`resolve_periods`)
    periods: float | None = None
    rtol: float = default_of("simulation", "rtol")
    atol: float = default_of("simulation", "atol")
    method: str = default_of("simulation", "method")
    effects: list[str] | None = None
    max_step: float = math.inf
    step: float | None = None
    samples: int = default_of("simulation", "samples")
    route: str = default_of("simulation", "route")
    gamma3_min: float = default_of("simulation", "gamma3_min")
    #: tolerance of the taylor method (None: machine epsilon)
    tol: float | None = None
    #: monitors asked for (names of :data:`.monitors.MONITORS` or callables)
    monitors: list[Any] | None = None
    #: axes the motion is written in (None: turning for a frame body, else inertial)
    axes: str | None = None


@dataclass
class OutputOptions:
    """Validated ``[output]`` settings."""

    dir: str | None = None
    trajectory: bool = default_of("output", "trajectory")
    plot: bool = default_of("output", "plot")
    poincare: bool = default_of("output", "poincare")
    poincare_section: str = default_of("output", "poincare_section")
    poincare_axes: tuple[str, str] = default_of("output", "poincare_axes")


def check_effect_names(requested: Any) -> list[str]:
    """The effects asked for (``simulation.effects`` or ``effects=``), each once, in order;
    one line naming a value that is no list of effect names."""
    if isinstance(requested, str) or not isinstance(requested, Sequence):
        raise input_error("simulation.effects", "a list of effect names", requested)
    for name in requested:
        if name not in EFFECTS:
            raise input_error("simulation.effects", "names among " + ", ".join(EFFECTS), name)
    return list(dict.fromkeys(requested))


def parse_simulation_options(
    table: Mapping[str, Any], where: str = "simulation"
) -> SimulationOptions:
    """Validate a ``[simulation]`` table (one-line errors naming the key)."""
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, SIMULATION_KEYS, where)
    opts = SimulationOptions()
    # the numbers (each > 0; an infinite max_step is the unbounded default)
    for key in (k.name for k in DECLARED["simulation"] if k.schema.get("type") == "number"):
        if key in table:
            value = table[key]
            if key == KEY.max_step and value == math.inf:
                continue
            setattr(opts, key, check_value("simulation", key, value, f"{where}.{key}"))
    if "periods" in table and KEY.t_end in table:
        raise InputError(f"{where}: give either t_end or periods, not both")
    for key in ("method", "route", "samples"):
        if key in table:
            setattr(opts, key, check_value("simulation", key, table[key], f"{where}.{key}"))
    if "effects" in table:
        effects = table["effects"]
        if not isinstance(effects, (list, tuple)) or not all(isinstance(e, str) for e in effects):
            raise input_error(f"{where}.effects", "a list of effect names", effects)
        opts.effects = list(effects)
    if "monitors" in table and table["monitors"] is not None:
        opts.monitors = parse_monitors(table["monitors"], f"{where}.monitors")
    if "axes" in table and table["axes"] is not None:
        opts.axes = check_value("simulation", "axes", table["axes"], f"{where}.axes")
    return opts


def parse_output_options(table: Mapping[str, Any], where: str = "output") -> OutputOptions:
    """Validate an ``[output]`` table."""
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, OUTPUT_KEYS, where)
    out = OutputOptions()
    if "dir" in table:
        if not isinstance(table["dir"], str) or not table["dir"]:
            raise input_error(f"{where}.dir", "a directory path", table["dir"])
        out.dir = table["dir"]
    for key in ("trajectory", "plot", "poincare", "poincare_section"):
        if key in table:
            setattr(out, key, check_value("output", key, table[key], f"{where}.{key}"))
    if "poincare_axes" in table:
        axes = table["poincare_axes"]
        if (
            not isinstance(axes, (list, tuple))
            or len(axes) != 2
            or any(a not in STATE_NAMES for a in axes)
        ):
            raise input_error(
                f"{where}.poincare_axes", "two names among " + ", ".join(STATE_NAMES), axes
            )
        out.poincare_axes = (str(axes[0]), str(axes[1]))
    return out


def parse_initial(
    table: Mapping[str, Any], where: str = "initial", base: Path | None = None
) -> dict[str, Any]:
    """Validate an ``[initial]`` table; returns a normalised mapping.

    Either ``omega`` and ``gamma`` (explicit state), or ``level = "I3=<value>"`` with
    ``gamma``, ``p`` and ``q`` (r solved from the level). ``precession`` is optional. Or a set
    of states: ``states = [[p, q, r, gamma1, gamma2, gamma3], ...]`` or ``file = PATH``
    (.csv or .npy, relative to ``base``), returned as ``{"states": ndarray (m, 6)}``.
    """
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, INITIAL_KEYS, where)
    if "states" in table or "file" in table:
        if "states" in table and "file" in table:
            raise InputError(f"{where}: give either states or file, not both")
        others = sorted(set(table) - {"states", "file"})
        if others:
            raise InputError(f"{where}.{others[0]}: not used with a set of states")
        if "states" in table:
            return {"states": parse_states(table["states"], f"{where}.states")}
        value = table["file"]
        if not isinstance(value, str) or not value:
            raise input_error(f"{where}.file", "a path to a .csv or .npy file", value)
        path = Path(value)
        if base is not None and not path.is_absolute():
            path = base / path
        return {"states": load_states(path, f"{where}.file")}
    if "gamma" not in table:
        raise InputError(f"{where}: missing key 'gamma'")
    gamma = as_array(table["gamma"], f"{where}.gamma", (3,))
    norm = float(np.linalg.norm(gamma))
    if norm < 1e-12:
        raise input_error(f"{where}.gamma", "a non-zero vector", table["gamma"])
    out: dict[str, Any] = {"gamma": gamma / norm, "gamma_norm": norm}
    out["precession"] = check_value(
        "initial", "precession", table.get("precession", 0.0), f"{where}.precession"
    )
    if "level" in table:
        if "omega" in table:
            raise InputError(f"{where}: give either omega or level with p and q, not both")
        level = table["level"]
        match = re.fullmatch(r"\s*I3\s*=\s*(\S+)\s*", level) if isinstance(level, str) else None
        value = None
        if match:
            try:
                value = float(match.group(1))
            except ValueError:
                value = None
        if value is None or not math.isfinite(value):
            raise input_error(f"{where}.level", "a level such as 'I3=0'", level)
        for key in ("p", "q"):
            if key not in table:
                raise InputError(f"{where}: level needs key '{key}'")
        out["level"] = value
        out["p"] = check_value("initial", "p", table["p"], f"{where}.p")
        out["q"] = check_value("initial", "q", table["q"], f"{where}.q")
    else:
        if "omega" not in table:
            raise InputError(f"{where}: give omega, or level = 'I3=0' with p and q")
        for key in ("p", "q"):
            if key in table:
                raise InputError(f"{where}.{key}: only used with level; omega is given")
        out["omega"] = as_array(table["omega"], f"{where}.omega", (3,))
    return out


def parse_monitors(value: Any, where: str = "simulation.monitors") -> list[Any]:
    """Validate monitor requests: names of :data:`~chargedesign.vocabulary.MONITOR_NAMES` (or
    their aliases) or callables."""
    if isinstance(value, str) or not isinstance(value, Sequence):
        raise input_error(where, "a list of monitor names", value)
    out: list[Any] = []
    for item in value:
        if callable(item):
            out.append(item)
            continue
        if not isinstance(item, str):
            raise input_error(where, "names among " + ", ".join(MONITOR_NAMES), item)
        name = MONITOR_ALIASES.get(item, item)
        if name not in MONITOR_NAMES:
            raise input_error(where, "names among " + ", ".join(MONITOR_NAMES), item)
        if name not in out:
            out.append(name)
    return out


# ------------------------------------------------------------------ the simulated body
#: the kinds of element a ``[body]`` table may give inline, with their two keys
INLINE_BLOCKS: dict[str, tuple[str, str]] = {
    "charges": ("positions", "values"),
    "masses": ("positions", "values"),
    "dipoles": ("positions", "moments"),
}


def has_inline_elements(body_table: Mapping[str, Any]) -> bool:
    """True when a ``[body]`` table gives elements inline."""
    return any(k in body_table for k in INLINE_BLOCKS)


def inline_elements(body_table: Mapping[str, Any]) -> dict[str, tuple[Any, Any]]:
    """``[body.charges]``, ``[body.masses]`` and ``[body.dipoles]`` as ``{kind: (positions,
    values or moments)}`` (each an empty list when not given); the numbers are checked where
    the design is built."""
    out: dict[str, tuple[Any, Any]] = {}
    for name, keys in INLINE_BLOCKS.items():
        block = body_table.get(name, {})
        if not isinstance(block, Mapping):
            raise input_error(f"body.{name}", "a table", block)
        check_keys(block, keys, f"body.{name}")
        out[name] = (block.get(keys[0], []), block.get(keys[1], []))
    return out


def design_path(body_table: Mapping[str, Any], source: str) -> Path:
    """The design file a ``[body]`` names (``design = PATH``, relative to the scene file)."""
    if has_inline_elements(body_table):
        raise InputError("body: give either design = PATH or inline elements, not both")
    value = body_table["design"]
    if not isinstance(value, str) or not value:
        raise input_error("body.design", "a path to design.json", value)
    path = Path(value)
    if not path.is_absolute() and source not in ("<default>", "<dict>"):
        path = Path(source).parent / path
    return path


# ------------------------------------------------------------------ runs' options and starts
def merge_options(base: SimulationOptions, overrides: Mapping[str, Any]) -> SimulationOptions:
    """A setup's options with a call's overrides (None keeps the setup's), validated again."""
    table = {k: v for k, v in overrides.items() if v is not None}
    # an unbounded max_step (inf) is passed too: parse_simulation_options reads it as the default
    merged = {k: getattr(base, k) for k in SIMULATION_KEYS if getattr(base, k) is not None}
    merged.update(table)
    return parse_simulation_options(merged, "simulation")


def resolve_periods(
    options: SimulationOptions, parameters: Any, initial: Any
) -> tuple[SimulationOptions, list[str]]:
    """Options whose ``periods`` is turned into ``t_end``: ``periods * 2 pi / rate`` for the
    motion's fastest rate (:func:`~chargedesign.validation.motion_rate`: the parameters' rates
    and the start's), with the note that says it; unchanged without ``periods``."""
    if options.periods is None:
        return options, []
    rate = motion_rate(parameters, initial)
    if not rate > 0.0:
        raise InputError(
            "simulation.periods: the body and its start have no rate to count periods of; "
            "give simulation.t_end"
        )
    t_end = options.periods * 2.0 * math.pi / rate
    note = (
        f"t_end = {fmt(t_end, PRECISE)} s: simulation.periods = {fmt(options.periods, PLAIN)} "
        f"periods 2 pi / rate of the motion's fastest rate {fmt(rate)} 1/s"
    )
    return replace(options, t_end=t_end, periods=None), [note]


def initial_spec(initial: Any) -> dict[str, Any]:
    """An initial spec as :func:`parse_initial` returns it, from a parsed spec, a raw
    ``[initial]`` mapping or ``(p, q, r, gamma1, gamma2, gamma3)``."""
    if isinstance(initial, Mapping):
        return dict(initial) if "gamma_norm" in initial else parse_initial(initial)
    arr = as_array(initial, "initial", (6,))
    return parse_initial({"omega": arr[:3].tolist(), "gamma": arr[3:].tolist()})


def with_level(initial: Any, level: float) -> dict[str, Any]:
    """An initial spec moved onto the level ``I3 = level`` (J s).

    Keeps gamma, the precession and p, q (of ``omega`` when the spec gives it); r is then
    solved from the level when the run starts. Used to start off the level ``I3 = 0``, where
    the theorem's I4 is not an integral.

    Parameters
    ----------
    initial : mapping or array_like
        As for :func:`initial_spec`.
    level : float
        The value of the physical I3, J s.

    Returns
    -------
    dict
        A spec as returned by :func:`parse_initial`.
    """
    value = as_finite_float(level, "level")
    spec = initial_spec(initial)
    out = {k: spec[k] for k in ("gamma", "gamma_norm", "precession")}
    if "omega" in spec:
        omega = np.asarray(spec["omega"], dtype=float)
        out["p"], out["q"] = float(omega[0]), float(omega[1])
    else:
        out["p"], out["q"] = spec["p"], spec["q"]
    out["level"] = value
    return out


def ensemble_states(spec: Any, states: Any = None) -> np.ndarray:
    """The starts of an ensemble, ``(m, 6)``: ``states`` when given (checked), else the set of
    an ``[initial]`` spec (``states`` or ``file``); one line when neither gives a set."""
    if states is not None:
        return parse_states(states, "states")
    if not (isinstance(spec, Mapping) and "states" in spec):
        raise InputError("initial: give states = [[p, q, r, gamma1, gamma2, gamma3], ...]")
    return np.asarray(spec["states"], dtype=float)


def check_off_singular_plane(gamma3: Any, threshold: float, name: str) -> None:
    """Refuse a start with ``|gamma3| <= gamma3_min`` (the plane where a singular case's
    terms are infinite), in one line naming the start (``name``) and the value."""
    if abs(gamma3) <= threshold:
        raise input_error(name, f"|gamma3| > gamma3_min = {fmt(threshold, PLAIN)}", gamma3)
