"""Every scene key, declared once: its name, the JSON Schema of its value (type and range),
its unit, its default and where that default comes from, and a one-line doc.

From these declarations follow the validators' key lists (an unknown key is refused with one
line naming it), the JSON Schema (:mod:`chargedesign.schemas`), the docs' key tables
(:func:`chargedesign.schemas.keys_markdown`, kept equal to docs/ by a test) and the defaults
of the typed options (:func:`default_of`: ``DesignOptions``, ``SimulationOptions``,
``OutputOptions``, the medium's safety and the carriers' wall and samples read them here).

Each table is a tuple of :class:`Key`. The order is the order the one-line errors list the
keys in ("one of t_end, rtol, ...").
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

import numpy as np

from chargedesign.formatting import PLAIN, fmt
from chargedesign.physical.materials import BALLAST_DENSITY
from chargedesign.physical.sources import cite
from chargedesign.physical.sources import value as figure_value
from chargedesign.physical.state_of_the_art import (
    AIR_FILM,
    ATTITUDE_SENSORS,
    BALANCE,
    BEARINGS,
    GYROS,
    MOUNT_MATERIALS,
)
from chargedesign.validation import as_finite_float, check_keys, input_error
from chargedesign.vocabulary import (
    BODY_SHAPES,
    CASE_KEYS,
    DEFAULT_SIMULATION_METHOD,
    EFFECTS,
    LARMOR_READINGS,
    MATERIAL_ERROR_KEYS,
    OBJECTIVES,
    PARAMETER_NAMES,
    REALISABLE,
    SIMULATION_AXES,
    SIMULATION_METHODS,
    SIMULATION_ROUTES,
    SOURCES,
    STATE_NAMES,
    SUPPORT_FACILITIES,
    SUPPORT_STYLES,
)

NUMBER: dict[str, Any] = {"type": "number"}
NONNEG: dict[str, Any] = {"type": "number", "minimum": 0}
POSITIVE: dict[str, Any] = {"type": "number", "exclusiveMinimum": 0}
VECTOR: dict[str, Any] = {"type": "array", "items": NUMBER, "minItems": 3, "maxItems": 3}
POINTS: dict[str, Any] = {"type": "array", "items": VECTOR}
NUMBERS: dict[str, Any] = {"type": "array", "items": NUMBER}
BOOLEAN: dict[str, Any] = {"type": "boolean"}
STRING: dict[str, Any] = {"type": "string"}
TEXT_OR_NUMBER: dict[str, Any] = {"anyOf": [STRING, NUMBER]}


class _NoDefault:
    """The default of a key that has none, or whose default is derived (see ``source``)."""

    def __repr__(self) -> str:
        return "NO_DEFAULT"


NO_DEFAULT: Any = _NoDefault()


@dataclass(frozen=True)
class Key:
    """One key of a scene table.

    Attributes
    ----------
    name : str
    schema : mapping
        The JSON Schema of its value: type and range.
    doc : str
        What it means (one line).
    unit : str
        SI unit of a quantity ("" for a number without unit, a name or a switch).
    default : object
        The value an absent key takes (JSON-ready); ``NO_DEFAULT`` when there is none or it
        is derived from other keys (``source`` then says how).
    source : str
        Where the default comes from or why it is what it is ("" for a plain choice).
    refusal : str
        What the one-line error says was expected when a number is out of the key's range
        (default: the range in words, "a number in [0, 1]").
    option : str
        The metavar of the command-line option that sets it (``--max-charge Q``; "" for
        none): :func:`chargedesign.commands.arguments.key_options` makes the option.
    """

    name: str
    schema: Mapping[str, Any] = field(default_factory=dict)
    doc: str = ""
    unit: str = ""
    default: Any = NO_DEFAULT
    source: str = ""
    refusal: str = ""
    option: str = ""

    def __post_init__(self) -> None:
        assert "\n" not in self.doc, f"{self.name}: a key's doc is one line"

    @property
    def has_default(self) -> bool:
        return self.default is not NO_DEFAULT

    def json_schema(self) -> dict[str, Any]:
        out = dict(self.schema)
        doc = self.doc + (f" ({self.unit})" if self.unit else "")
        if doc:
            out["description"] = doc
        if self.has_default:
            out["default"] = list(self.default) if isinstance(self.default, tuple) else self.default
        return out


def range_words(spec: Mapping[str, Any], kind: str) -> str:
    """A declared range in words, for the one-line errors ("an integer >= 2") and the docs'
    tables ("number in (0, 1]"); ``kind`` alone when the value has no bounds."""
    lo = spec.get("minimum", spec.get("exclusiveMinimum"))
    hi = spec.get("maximum", spec.get("exclusiveMaximum"))
    if lo is None and hi is None:
        return kind
    if lo is not None and hi is not None:
        left = "(" if "exclusiveMinimum" in spec else "["
        right = ")" if "exclusiveMaximum" in spec else "]"
        return f"{kind} in {left}{lo}, {hi}{right}"
    if lo is not None:
        return f"{kind} {'>' if 'exclusiveMinimum' in spec else '>='} {lo}"
    return f"{kind} {'<' if 'exclusiveMaximum' in spec else '<='} {hi}"


def within_range(value: float, spec: Mapping[str, Any]) -> bool:
    """``value`` within a declared range (its minimum, maximum and exclusive bounds)."""
    return not (
        ("minimum" in spec and value < spec["minimum"])
        or ("exclusiveMinimum" in spec and value <= spec["exclusiveMinimum"])
        or ("maximum" in spec and value > spec["maximum"])
        or ("exclusiveMaximum" in spec and value >= spec["exclusiveMaximum"])
    )


def check_value(table: str, name: str, value: Any, where: str | None = None) -> Any:
    """``value`` of the key ``table.name`` checked against its declaration, as its type (a
    float, an int, a bool or one of the declared choices); a one-line error names ``where``
    (default ``table.name``), what the key expects and what was received.

    Numbers are real and finite (:func:`chargedesign.validation.as_finite_float`) and within
    the declared range; integers are ints (never bools); choices are the declared enum.
    """
    return check_declared(declared(table, name), value, where or f"{table}.{name}")


def check_declared(key: Key, value: Any, where: str, *, positive: bool = False) -> Any:
    """:func:`check_value` of one declaration; ``positive``: a number is refused as "a number
    > 0" before its declared range is checked."""
    spec = key.schema
    if "enum" in spec:
        if value not in spec["enum"]:
            raise input_error(where, "one of " + ", ".join(spec["enum"]), value)
        return value
    kind = spec.get("type")
    if kind == "boolean":
        if not isinstance(value, bool):
            raise input_error(where, "true or false", value)
        return value
    if kind == "integer":
        if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
            raise input_error(where, key.refusal or range_words(spec, "an integer"), value)
        if not within_range(float(value), spec):
            raise input_error(where, key.refusal or range_words(spec, "an integer"), value)
        return int(value)
    assert kind == "number", f"{where}: no declared check for {spec}"
    number = as_finite_float(value, where, positive=positive)
    if not within_range(number, spec):
        raise input_error(where, key.refusal or range_words(spec, "a number"), value)
    return number


def _enum(values: tuple[str, ...]) -> dict[str, Any]:
    return {"enum": list(values)}


_RESPONSE = (
    Key(
        "susceptibility",
        {"type": "number", "exclusiveMinimum": -1},
        "SI volume susceptibility (replaces the named material's)",
        source="the material's (chargedesign.physical.materials)",
    ),
    Key(
        "conductivity",
        NONNEG,
        "electrical conductivity (replaces the named material's)",
        "S/m",
        source="the material's (chargedesign.physical.materials)",
    ),
)
_MATERIAL_NAME = Key("material", STRING, "a named material (docs/buildable.md)")
_DENSITY = Key("density", POSITIVE, "density (with no material: a custom one)", "kg/m^3")

PARAMETERS = tuple(
    Key(
        name,
        POSITIVE if name == "C" else NUMBER,
        "moment of inertia about the symmetry axis" if name == "C" else f"the theorem's {name}",
        {"C": "kg m^2", "n": "1/s", "K": "1/s"}.get(
            name, "1/s^2" if name in ("kappa", "lambda", "rho") else ""
        ),
        1.0 if name == "C" else 0.0,
        "the unit of inertia" if name == "C" else "an omitted parameter is 0",
    )
    for name in PARAMETER_NAMES
)
FIELD = (
    Key("a1", NUMBER, "the paper's uniform term of Phi = a1 Z + a2 (3 Z^2 - R^2)", default=0.0),
    Key("a2", NUMBER, "the paper's gradient term (legendre = [a1, 2 a2])", default=0.0),
    Key("legendre", NUMBERS, "coefficients f_k of Phi = sum f_k R^k P_k(Z/R), k >= 1"),
    Key(
        "max",
        POSITIVE,
        "largest |field| the apparatus makes over the body (T, V/m or m/s^2)",
        source="none: no limit",
    ),
)
MEDIUM = (
    Key("name", STRING, "vacuum, air, sf6, oil, or any name with breakdown"),
    Key("breakdown", POSITIVE, "breakdown field (replaces the named medium's)", "V/m"),
    Key(
        "safety",
        {"type": "number", "exclusiveMinimum": 0, "maximum": 1},
        "surface fields stay <= safety * breakdown",
        default=0.5,
        source="half the breakdown field (docs/buildable.md)",
    ),
    Key(
        "gas",
        _enum(("vacuum", "air", "sf6", "oil")),
        "whose density and viscosity the drag estimate uses",
        source="the name's, if it names one",
    ),
)
CARRIERS = (
    _MATERIAL_NAME,
    _DENSITY,
    Key(
        "shell_thickness",
        NONNEG,
        "wall of a hollow carrier; 0 = solid",
        "m",
        1e-4,
        "thin spun or drawn aluminium",
    ),
    Key(
        "samples",
        {"type": "integer", "minimum": 6, "maximum": 2000},
        "surface points per carrier in the design",
        default=26,
        source="constraint generation adds the worst surface point",
    ),
    *_RESPONSE,
)
MAGNETS = (
    _MATERIAL_NAME,
    _DENSITY,
    Key("magnetisation", POSITIVE, "remanent magnetisation", "A/m", source="the material's"),
    Key("coercivity", POSITIVE, "intrinsic coercivity", "A/m", source="the material's"),
    *_RESPONSE,
)
BALLAST = (
    Key(
        "material",
        {"anyOf": [STRING, {"type": "array", "items": STRING, "minItems": 1}]},
        "a material, or a list of materials of opposite susceptibilities",
    ),
    _DENSITY,
    *_RESPONSE,
)
#: a scene's ``[holder]``: the sphere about O with a bore for each part
#: (chargedesign.physical.holder); the table's presence makes the design hold its parts
HOLDER = (
    Key(
        "material",
        STRING,
        "the holder's material (chargedesign.physical.holder.HOLDER_MATERIAL_NAMES)",
        source="the ballast's (its first material)",
    ),
)
#: what each material error is of, in the order of the vocabulary's MATERIAL_ERROR_KEYS
#: (susceptibility, density, magnetisation)
_MATERIAL_ERRORS = (
    "every material's susceptibility (one draw per material)",
    "the densities",
    "the magnets' remanent magnetisation",
)
TOLERANCE = tuple(
    Key(
        name,
        {"type": "number", "minimum": 0, "exclusiveMaximum": 1},
        f"relative error (one standard deviation) of {what}",
        default=0.0,
        source="exact material properties",
        refusal="a relative error in [0, 1)",
        option="X",
    )
    for name, what in zip(MATERIAL_ERROR_KEYS, _MATERIAL_ERRORS, strict=True)
)
DESIGN = (
    Key(
        "objective", _enum(OBJECTIVES), "what every source minimises (docs/design.md)", default="l1"
    ),
    Key("solver", STRING, "auto or a cvxpy solver name", default="auto"),
    Key("max_charge", POSITIVE, "bound on every |q|", "C", source="none: unbounded", option="Q"),
    Key("total_charge", NUMBER, "required total charge", "C", source="none: free", option="Q"),
    Key(
        "n_charges",
        {"type": "integer", "minimum": 1},
        "at most this many charges",
        source="none: as many as the optimum uses",
        option="N",
    ),
    Key(
        "total_mass",
        POSITIVE,
        "required total mass",
        "kg",
        source="none: the least mass",
        option="M",
    ),
    Key(
        "realise",
        {"type": "array", "items": _enum(REALISABLE), "uniqueItems": True},
        "what the design claims",
        source="what the conditions realise",
    ),
    Key("polish", BOOLEAN, "polish to machine precision on the support", default=True),
    Key(
        "tol",
        {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
        "largest accepted relative residual",
        source="1e-13 polished, 1e-7 unpolished",
    ),
    Key(
        "objectives",
        {
            "type": "object",
            "properties": {source: _enum(OBJECTIVES) for source in SOURCES},
            "additionalProperties": False,
        },
        "the objective per source",
        source="objective for every source",
    ),
    Key(
        "column_generation",
        BOOLEAN,
        "force column generation on or off",
        source="on above 2000 candidates, for HiGHS",
    ),
    Key(
        "sparsity",
        _enum(("auto", "reweighted", "mip")),
        "how n_charges is met",
        default="auto",
        source="reweighted l1, then mixed integer",
    ),
    Key("time_limit", POSITIVE, "time allowed to the mixed-integer solver", "s", 60.0),
    Key(
        "robust_weight",
        {"type": "number", "minimum": 0, "maximum": 1},
        "with objective robust: 0 is plain l1, 1 pure placement sensitivity",
        default=1.0,
    ),
    Key(
        "larmor",
        _enum(LARMOR_READINGS),
        "how n is realised: charges (the paper's (p6) second moments) or frame (the body "
        "realises n = 0, read in axes turning at n)",
        source="charges without [medium], frame with it",
    ),
    Key(
        "realised_fraction",
        {"type": "number", "exclusiveMinimum": 0, "exclusiveMaximum": 1},
        "the realised window: every parasitic below this fraction of each realised term",
        default=1e-3,
        source="a parasitic torque at a fraction f of the designed ones moves I4 by about f",
    ),
    Key(
        "realised_gravity",
        {"type": "number", "minimum": 0, "maximum": 100},
        "gravity on the builder's balance in the realised window",
        "m/s^2",
        9.80665,
        source="standard gravity (a lab on Earth); 0 is free fall",
    ),
)
SIMULATION = (
    Key("t_end", POSITIVE, "end of the run", "s", 100.0, option="T"),
    Key(
        "periods",
        POSITIVE,
        "the run's length in periods 2 pi / rate of its fastest rate (instead of t_end)",
        source="none: t_end",
    ),
    Key("rtol", POSITIVE, "relative tolerance (solve_ivp)", default=1e-12, option="RTOL"),
    Key("atol", POSITIVE, "absolute tolerance (solve_ivp)", default=1e-12, option="ATOL"),
    Key(
        "method",
        _enum(SIMULATION_METHODS),
        "taylor, a solve_ivp method or gauss-legendre",
        default=DEFAULT_SIMULATION_METHOD,
        source="heyoka's Taylor integrator (I4 drift 2.1e-14 at t = 1000, DESIGN.md)",
    ),
    Key(
        "effects",
        {"type": "array", "items": _enum(EFFECTS)},
        "what acts on the body",
        source="every physical effect with a source and a non-zero field (induced only by "
        "name); theorem for a body without elements",
    ),
    Key("max_step", POSITIVE, "largest step of solve_ivp", "s", source="unbounded"),
    Key(
        "step",
        POSITIVE,
        "fixed step of gauss-legendre",
        "s",
        source="min(0.01, t_end), rounded to divide t_end",
        option="STEP",
    ),
    Key(
        "samples",
        {"type": "integer", "minimum": 2},
        "output samples",
        default=2001,
        option="SAMPLES",
    ),
    Key(
        "route", _enum(SIMULATION_ROUTES), "the reduced model or the direct one", default="reduced"
    ),
    Key(
        "gamma3_min",
        POSITIVE,
        "singular-plane threshold (lambda or rho != 0)",
        default=1e-2,
    ),
    Key("tol", POSITIVE, "tolerance of the taylor method", source="machine epsilon"),
    Key(
        "monitors",
        {"type": "array", "items": STRING},
        "drifts to report even where they are no integrals",
        source="none",
    ),
    Key(
        "axes",
        _enum(SIMULATION_AXES),
        "the axes the motion is written in",
        source="turning for a frame body, else inertial",
    ),
)
INITIAL = (
    Key("omega", VECTOR, "angular velocity in body axes", "1/s"),
    Key("gamma", VECTOR, "the space axis Z in body axes (normalised)"),
    Key("level", TEXT_OR_NUMBER, "a level of I3, e.g. 'I3=0' (with p and q: r solved)"),
    Key("p", NUMBER, "p with level", "1/s"),
    Key("q", NUMBER, "q with level", "1/s"),
    Key("precession", NUMBER, "turn about space Z", "rad", 0.0, "it does not change the motion"),
    Key(
        "states",
        {"type": "array", "items": {**NUMBERS, "minItems": 6, "maxItems": 6}},
        "a set of states [p, q, r, gamma1, gamma2, gamma3]",
    ),
    Key("file", STRING, "a .csv or .npy file of states"),
)
OUTPUT = (
    Key("dir", STRING, "a relative folder without '..'", source="the command's --out"),
    Key("trajectory", BOOLEAN, "write trajectory.npz and trajectory.csv", default=True),
    Key("plot", BOOLEAN, "write integrals.png", default=True),
    Key("poincare", BOOLEAN, "write poincare.png", default=False),
    Key(
        "poincare_section",
        _enum(STATE_NAMES),
        "upward zero crossings of this state",
        default="gamma1",
    ),
    Key(
        "poincare_axes",
        {"type": "array", "items": _enum(STATE_NAMES), "minItems": 2, "maxItems": 2},
        "the section's two axes",
        default=("gamma2", "q"),
    ),
)
_SIZE = {"anyOf": [POSITIVE, VECTOR]}
#: a [body] region's keys (besides shape), by shape
REGION_KEYS: dict[str, tuple[str, ...]] = {
    "ball": ("radius", "spacing", "center", "symmetric"),
    "box": ("half_size", "size", "spacing", "center", "symmetric"),
    "cylinder": ("radius", "height", "spacing", "center", "symmetric"),
    "shell": ("radius", "n_points", "center", "symmetric"),
    "points": ("path", "scale", "center", "symmetric"),
    "mesh": ("path", "sample", "spacing", "scale", "center", "symmetric"),
}
_BLOCK = {"type": "object", "additionalProperties": False}
BODY = (
    Key("shape", _enum(BODY_SHAPES), "a region to design in", default="ball"),
    Key("radius", POSITIVE, "radius (required)", "m"),
    Key(
        "height", POSITIVE, "full height along body z, spanning -height/2..height/2 (required)", "m"
    ),
    Key(
        "spacing",
        POSITIVE,
        "lattice spacing (required for a mesh with sample = volume)",
        "m",
        source="ball radius/4, box min(half_size)/2, cylinder min(radius, height/2)/4",
    ),
    Key(
        "n_points",
        {"type": "integer", "minimum": 1},
        "about this many points on the sphere (Fibonacci rule)",
        default=200,
    ),
    Key("half_size", _SIZE, "half edge lengths (one of half_size, size required)", "m"),
    Key("size", _SIZE, "full edge lengths (one of half_size, size required)", "m"),
    Key("center", VECTOR, "offset of the shape", "m", (0.0, 0.0, 0.0), "O, the fixed point"),
    Key(
        "symmetric",
        BOOLEAN,
        "close the set under x -> -x, y -> -y, z -> -z and x <-> y",
        source="true for shapes symmetric already (centred ball, cylinder, shell, square box)",
    ),
    Key("path", STRING, "the points' or mesh's file, relative to the scene file"),
    Key("scale", POSITIVE, "metres per file unit", default=1.0),
    Key(
        "sample", _enum(("surface", "volume")), "a mesh's vertices or its volume", default="surface"
    ),
    Key(
        "carrier_radius",
        POSITIVE,
        "radius of every charge carrier (physical parts)",
        "m",
        source="a quarter of the candidate spacing: carriers never touch",
    ),
    Key("design", STRING, "a design.json to simulate"),
    Key(
        "charges",
        {**_BLOCK, "properties": {"positions": POINTS, "values": NUMBERS}},
        "inline charges (m, C)",
    ),
    Key(
        "masses",
        {**_BLOCK, "properties": {"positions": POINTS, "values": NUMBERS}},
        "inline masses (m, kg)",
    ),
    Key(
        "dipoles",
        {**_BLOCK, "properties": {"positions": POINTS, "moments": POINTS}},
        "inline dipoles (m, A m^2)",
    ),
)
_EXPRESSION = {**STRING, "maxLength": 20000}
_EXPRESSIONS = {"type": "array", "items": TEXT_OR_NUMBER, "minItems": 3, "maxItems": 3}
#: a scene's ``[case]``: any case of (ep) with its claimed integral, instead of
#: ``[parameters]`` (read by :func:`chargedesign.scene.case_file.case_from_table`;
#: docs/workbench.md)
CASE = (
    Key("name", {**STRING, "minLength": 1, "maxLength": 80}, "the case's name (required)"),
    Key(
        "inertia",
        _EXPRESSIONS,
        "A, B, C: principal moments at O, numbers or expressions of the parameters (required)",
        "kg m^2",
    ),
    Key(
        "V", _EXPRESSION, "potential: an expression in gamma1..3 and the parameters (required)", "J"
    ),
    Key(
        "l",
        _EXPRESSIONS,
        "vector potential l(gamma): 3 expressions (mu follows by (mu))",
        default=("0", "0", "0"),
        source="no gyroscopic forces",
    ),
    Key("mu", _EXPRESSIONS, "gyroscopic vector mu(gamma) instead of l (general claims only)"),
    Key("integral", _EXPRESSION, "the claimed integral F in p, q, r, gamma (required)"),
    Key(
        "level", TEXT_OR_NUMBER, "general, or the I3 value on which F is claimed", default="general"
    ),
    Key(
        "parameters",
        {
            "type": "object",
            "patternProperties": {"^[A-Za-z_][A-Za-z0-9_]*$": TEXT_OR_NUMBER},
            "additionalProperties": False,
            "maxProperties": 32,
        },
        "named parameters: name = number (exact: 0.1 is 1/10) or a text such as 1/3",
    ),
    Key("source", {**STRING, "maxLength": 2000}, "where the case comes from"),
    Key("note", {**STRING, "maxLength": 2000}, "a remark"),
)
assert tuple(key.name for key in CASE) == CASE_KEYS  # the case file's validator's list
#: caps on the testbed's work (a scene asks for no more): noise seeds, planned motions (one
#: ideal-loop integration each), the rates (Hz) a loop or a requirement setting may take,
#: the default cap on fixed integration steps per loop run
MAX_SEEDS = 10_000
MAX_PLANNED_MOTIONS = 64
RATE_RANGE_HZ = (0.1, 100_000.0)
MAX_LOOP_STEPS = 200_000
_RATES = f"{fmt(RATE_RANGE_HZ[0], PLAIN)}..{fmt(RATE_RANGE_HZ[1], PLAIN)} Hz"
_PLATFORM = (
    "a thin spherical shell (a cage) about O with an opening for the pedestal "
    "(the keep-out cap; closed for a full sphere): centre of mass R (1 - cos alpha) / 2 along "
    "the pedestal axis, inertia in closed form; 10 kg and 0.25 m radius: the tabletop class "
    "of the survey Schwartz, Peck & Hall, J. Guid. Control Dyn. 26(4) 2003 (e.g. NPS CubeTAS)"
)
_SHELL = "the thin spherical shell of platform_mass_kg and platform_radius_m (closed form)"
_MOTORS = (
    "ideal torque sources unless the scene gives its wheels' motor_bandwidth_Hz "
    "(a first-order lag) and wheel_friction_N_m (Coulomb, against the wheel's momentum): "
    "no default is sourced here (B. Bialke, 'High fidelity mathematical modeling of reaction "
    "wheel performance', AAS 98-063, 1998 gives the model's form; the figures are the "
    "wheel's datasheet's; no default)"
)
_WHEEL_LIMITS = (
    "limits sized from the planned motion times wheel_margin (1.5: headroom for "
    "noise and disturbances); flight-like wheels give 0.01-0.1 N m (Schwartz, Peck & Hall "
    "2003); give max_torque_N_m and max_momentum_N_m_s to check a real wheel"
)
_GYRO_GRADES = (
    "order-of-magnitude class figures (bias; angle random walk): navigation "
    "0.01 deg/h, 0.002 deg/sqrt(h); tactical 1 deg/h, 0.1 deg/sqrt(h); industrial 10 deg/h, "
    "0.5 deg/sqrt(h): P. D. Groves, Principles of GNSS, Inertial, and Multisensor Integrated "
    "Navigation Systems, 2nd ed., Artech House 2013, ch. 4 (inertial sensor grades) "
    + "; ".join(
        cite(f"sensors.gyro.{g}.{k}")
        for g in ("navigation", "tactical", "industrial")
        for k in ("arw", "bias")
    )
)
_ATTITUDE = "the attitude sensor's (attitude_sensor)"
_LOOP = "200 Hz and 1 ms of delay: the contract's example loop"
_START = (
    "none: the tool plans motions that fit the bearing (near the stable relative "
    "equilibrium on I3 = 0); a scene's start (initial_gamma, initial_p, initial_q; r from "
    "I3 = 0) is used when it fits"
)
_SEEDS = (
    "16 noise seeds (and 2 per requirement setting): a spread in seconds of run time; "
    "raise them for tighter percentiles"
)
_RATE_LIST = {
    "type": "array",
    "items": {"type": "number", "minimum": RATE_RANGE_HZ[0], "maximum": RATE_RANGE_HZ[1]},
    "minItems": 1,
    "maxItems": 12,
}
#: a scene's ``[testbed]``: the air-bearing platform, its ballast and wheels, the sampled loop,
#: sensors, disturbances and requirements (read by :mod:`chargedesign.scene.testbed`;
#: docs/testbed.md). Every default's source is here; testbed.json's ``sources`` lists them.
TESTBED = (
    Key(
        "platform_mass_kg", POSITIVE, "the platform's mass, wheels included", "kg", 10.0, _PLATFORM
    ),
    Key(
        "platform_radius_m",
        POSITIVE,
        "envelope radius (ballast stays inside)",
        "m",
        0.25,
        "with platform_mass_kg: the tabletop class (Schwartz, Peck & Hall 2003)",
    ),
    Key(
        "platform_inertia_kg_m2",
        {"type": "array", "items": VECTOR, "minItems": 3, "maxItems": 3},
        "3x3 about O, symmetric, physical",
        "kg m^2",
        source=_SHELL,
        refusal="a symmetric 3x3 inertia matrix (kg m^2)",
    ),
    Key("platform_com_m", VECTOR, "the platform's centre of mass", "m", source=_SHELL),
    Key(
        "bearing",
        _enum(tuple(BEARINGS)),
        "the air bearing's style (tilt limit, rated load, geometry)",
        default="tabletop",
        source="tabletop: tilt limit 30 deg, umbrella 45 deg, full_sphere every attitude "
        "(Schwartz, Peck & Hall 2003) "
        + "; ".join(cite(f"bearings.{b}.tilt_limit_deg") for b in BEARINGS),
    ),
    Key(
        "tilt_limit_deg",
        {"type": "number", "exclusiveMinimum": 0, "maximum": 180},
        "the bearing's tilt limit",
        "deg",
        source="the style's: 30, 45, 180 deg",
        refusal="a tilt limit in (0, 180] deg",
    ),
    Key(
        "pedestal_radius_m",
        POSITIVE,
        "the pedestal's radius (less than the ball's)",
        "m",
        source="the style's pedestal radius over the ball's radius (0.3) times bearing_radius_m",
    ),
    Key(
        "bearing_capacity_kg",
        POSITIVE,
        "the bearing's rated load",
        "kg",
        source="the style's rated load (state_of_the_art.BEARINGS: a vendor "
        "catalogue class); give your bearing's",
    ),
    Key(
        "bearing_radius_m",
        POSITIVE,
        "the bearing ball's radius (no ballast inside)",
        "m",
        0.05,
        "a 50 mm ball; the drag follows from it",
    ),
    Key(
        "bearing_gap_m",
        POSITIVE,
        "the air film's thickness",
        "m",
        AIR_FILM["thin_m"].value,
        f"{fmt(AIR_FILM['thin_m'].value * 1e6, PLAIN)} um, the thin end (the most drag) of the air "
        f"film's range {fmt(AIR_FILM['thin_m'].value * 1e6, PLAIN)}-"
        f"{fmt(AIR_FILM['thick_m'].value * 1e6, PLAIN)} um "
        f"{cite(AIR_FILM['thin_m'].key)}; {cite(AIR_FILM['thick_m'].key)}",
    ),
    Key(
        "ballast_material",
        _enum(tuple(BALLAST_DENSITY)),
        "the ballast parts' material",
        default="brass",
        source="brass (8500 kg/m^3, chargedesign.physical.materials): machinable, "
        "non-magnetic, dense",
    ),
    Key(
        "ballast_spacing_m",
        POSITIVE,
        "grid of candidate ballast sites (at most 100000: memory)",
        "m",
        source="a fifth of the platform's radius, coarsened if parts would touch",
    ),
    Key(
        "mount_material",
        _enum(tuple(MOUNT_MATERIALS)),
        "the posts' material",
        default="steel",
        source="steel posts (E = 200 GPa, ASM Handbook vol. 1, ASM International 1990) "
        + cite("mounts.steel.youngs_modulus"),
    ),
    Key(
        "wheels",
        _enum(("orthogonal", "pyramid")),
        "the wheel array: three orthogonal wheels, or four on a pyramid about body z",
        default="orthogonal",
    ),
    Key(
        "pyramid_angle_deg",
        {"type": "number", "minimum": 5, "maximum": 85},
        "the pyramid wheels' angle from body z",
        "deg",
        math.degrees(math.acos(1.0 / math.sqrt(3.0))),
        "arccos(1/sqrt(3)) = 54.74 deg: the four-wheel pyramid whose wheels "
        "share the three body axes equally",
        refusal="an angle from the body z axis in 5..85 deg",
    ),
    Key(
        "max_torque_N_m",
        POSITIVE,
        "each wheel's torque limit (checked when given)",
        "N m",
        source=_WHEEL_LIMITS,
    ),
    Key(
        "max_momentum_N_m_s",
        POSITIVE,
        "each wheel's momentum limit (checked when given)",
        "N m s",
        source="as max_torque_N_m",
    ),
    Key(
        "wheel_margin",
        {"type": "number", "minimum": 1},
        "headroom of sized wheels over the planned need",
        default=1.5,
        source="noise and disturbances",
        refusal="a margin >= 1",
    ),
    Key(
        "torque_resolution_N_m",
        POSITIVE,
        "torque quantum (at most a tenth of the need)",
        "N m",
        source="a 16-bit command over +-max torque: 2 max_torque / 2^16",
    ),
    Key(
        "motor_bandwidth_Hz",
        POSITIVE,
        "the motors' torque bandwidth (a first-order lag)",
        "Hz",
        source=_MOTORS,
    ),
    Key(
        "wheel_friction_N_m",
        NONNEG,
        "each wheel's Coulomb friction",
        "N m",
        source="none: as motor_bandwidth_Hz",
    ),
    Key(
        "rate_Hz",
        {"type": "number", "minimum": RATE_RANGE_HZ[0], "maximum": RATE_RANGE_HZ[1]},
        "control rate",
        "Hz",
        200.0,
        _LOOP,
        refusal=f"a control rate in {_RATES}",
    ),
    Key("delay_s", NONNEG, "the loop's delay (less than a control period)", "s", 1.0e-3, _LOOP),
    Key(
        "command",
        _enum(("predictive", "zoh")),
        "zero-order hold of the law sampled at t_k (zoh), or the model's average over the "
        "coming interval (predictive)",
        default="predictive",
        source="the better one (docs/testbed.md measures both)",
    ),
    Key(
        "gyro_grade",
        _enum(("ideal", *GYROS)),
        "the gyro's class (ideal: a perfect gyro)",
        default="tactical",
        source=_GYRO_GRADES,
    ),
    Key(
        "gyro_arw_rad_per_sqrt_s",
        NONNEG,
        "angle random walk (replaces the grade's)",
        "rad/sqrt(s)",
        source="the grade's",
    ),
    Key(
        "gyro_bias_rad_per_s",
        NONNEG,
        "gyro bias (replaces the grade's)",
        "rad/s",
        source="the grade's",
    ),
    Key(
        "attitude_sensor",
        _enum(tuple(ATTITUDE_SENSORS)),
        "the lab's attitude sensor",
        default="motion_capture",
        source=f"motion capture: {fmt(ATTITUDE_SENSORS['motion_capture'][0].value, PLAIN)} rad at "
        "180 Hz (OptiTrack cameras measured by Krumpek et al., arXiv:2502.21189; the 180 Hz rate "
        f"from the PrimeX 41 datasheet {cite('sensors.motion_capture.rate')}; the noise is the "
        "error along the line of sight (about 7 times the error across it), "
        f"{fmt(figure_value('sensors.motion_capture.along_m') * 1e3, PLAIN)} mm over an assumed "
        f"{fmt(figure_value('sensors.motion_capture.baseline_m'), PLAIN)} m baseline "
        f"{cite('sensors.motion_capture.along_m')}; {cite('sensors.motion_capture.baseline_m')})",
    ),
    Key(
        "attitude_noise_rad",
        NONNEG,
        "attitude noise per sample (replaces the sensor's)",
        "rad",
        source=_ATTITUDE,
    ),
    Key(
        "attitude_rate_Hz",
        POSITIVE,
        "attitude update rate (replaces the sensor's)",
        "Hz",
        source=_ATTITUDE,
    ),
    Key(
        "encoder_counts",
        {"type": "integer", "minimum": 16, "maximum": 2**32},
        "the wheels' encoders, counts per turn",
        source="4096 counts per turn (a 12-bit encoder) " + cite("sensors.encoder.counts"),
    ),
    Key(
        "estimator",
        _enum(("rls", "none")),
        "the centre-of-mass estimator: recursive least squares with gravity feed-forward, or none",
        default="rls",
        source="rls: recursive least squares of the centre-of-mass offset and the drag on "
        "the integrated torque balance, with gravity feed-forward (Kim & Agrawal 2009 estimate "
        "the offset online the same way)",
    ),
    Key(
        "imbalance_m",
        NONNEG,
        "centre-of-mass offset from O before estimation",
        "m",
        BALANCE["automatic_horizontal_m"].value,
        "0.14 um: the best published automatic balancing's ESTIMATED horizontal offset (an "
        "estimate, not a measurement; engrXiv doi:10.31224/7342) "
        + cite(BALANCE["automatic_horizontal_m"].key),
    ),
    Key(
        "drag_N_m_s",
        NONNEG,
        "the bearing's viscous drag coefficient b",
        "N m s",
        source="derived: viscous Couette drag of the air film, b = (4 pi / 3) eta R^4 / h "
        "for a hemispherical cup of radius R and gap h (eta of air at 20 C from the CRC "
        "Handbook, 97th ed., CRC Press 2016) " + cite("media.viscosity.air"),
    ),
    Key(
        "drag_feedforward",
        {"type": "number", "minimum": 0, "maximum": 1},
        "fraction of the drag the controller cancels",
        default=0.0,
        source="0: no drag fed forward (the baseline); a measured drag (spin-down "
        "test) fed forward as a fraction of the bearing's drag cancels that much of it",
        refusal="the fraction of the drag fed forward, in 0..1",
    ),
    Key(
        "initial_gamma",
        VECTOR,
        "a start's gamma (with initial_p, initial_q; r from I3 = 0)",
        source=_START,
    ),
    Key("initial_p", NUMBER, "a start's p", "1/s", source="as initial_gamma"),
    Key("initial_q", NUMBER, "a start's q", "1/s", source="as initial_gamma"),
    Key(
        "planned_motions",
        {"type": "integer", "minimum": 1, "maximum": MAX_PLANNED_MOTIONS},
        "starts that fit, at 0.9, 0.6, 0.3 ... of the tilt limit",
        default=3,
        source="3: starts at 0.9, 0.6 and 0.3 of the tilt limit from the stable "
        "relative equilibrium (the first is the loop's); the wheels are sized for the largest "
        "need among them",
    ),
    Key(
        "t_end_s",
        POSITIVE,
        "horizon of every run",
        "s",
        20.0,
        "20 s: the horizon of the issue's outside measurement",
    ),
    Key(
        "seeds",
        {"type": "integer", "minimum": 1, "maximum": MAX_SEEDS},
        "Monte Carlo runs",
        default=16,
        source=_SEEDS,
    ),
    Key(
        "target_I4_drift",
        POSITIVE,
        "the I4 drift the requirements keep",
        default=1.0e-3,
        source="1e-3: I4 kept to 0.1 % over the run",
    ),
    Key(
        "requirement_rates_Hz",
        _RATE_LIST,
        "control rates of the requirements sweep",
        "Hz",
        (25.0, 50.0, 100.0, 200.0),
        "25 Hz doubling up to the default loop's 200 Hz (rate_Hz)",
        refusal=f"1 to 12 rates in {_RATES}",
    ),
    Key(
        "requirement_seeds",
        {"type": "integer", "minimum": 1, "maximum": MAX_SEEDS},
        "seeds per gyro grade and rate",
        default=2,
        source="as seeds",
    ),
    Key(
        "max_loop_steps",
        {"type": "integer", "minimum": 1000, "maximum": 10**9},
        "fixed integration steps a loop run may take (checked before any work)",
        default=MAX_LOOP_STEPS,
        source="200000 fixed integration steps per loop run: a run's work is bounded "
        "before it starts",
    ),
)
SUPPORT = (
    Key(
        "style",
        _enum(SUPPORT_STYLES),
        "how the body is held: free fall, orbit, a full-sphere air bearing, electrostatic",
        default="air_bearing",
        source="the lab's full-sphere air bearing (the testbed's; docs/flight.md)",
    ),
    Key(
        "facility",
        _enum(SUPPORT_FACILITIES),
        "the free-fall facility: ZARM's Bremen Drop Tower, a drop (4.74 s) or the catapult (9.3 s)",
        default="drop_tower_catapult",
        source="the longest free fall (zarm.uni-bremen.de, the catapult system)",
    ),
)
#: the keys of a [body] that names the body to simulate (a design reference or inline elements)
BODY_REFERENCE_KEYS = ("design", "charges", "masses", "dipoles")

#: every table with a flat key list (parameters and fields have their own shapes)
TABLE_KEYS: dict[str, tuple[Key, ...]] = {
    "body": BODY,
    "design": DESIGN,
    "simulation": SIMULATION,
    "initial": INITIAL,
    "output": OUTPUT,
    "medium": MEDIUM,
    "carriers": CARRIERS,
    "magnets": MAGNETS,
    "ballast": BALLAST,
    "holder": HOLDER,
    "tolerance": TOLERANCE,
    "case": CASE,
    "testbed": TESTBED,
    "support": SUPPORT,
}


#: every key table by its place in a scene (a field's keys hold for each fields.<kind>)
DECLARED: dict[str, tuple[Key, ...]] = {"parameters": PARAMETERS, "fields": FIELD, **TABLE_KEYS}
#: every declared key's name as an attribute (``KEY.t_end == "t_end"``): code that repeats a
#: key's name (a table's key, an option's or an output's of the same name) takes it from the
#: declaration here, so that a key is spelled in one place
KEY: Any = SimpleNamespace(**{key.name: key.name for keys in DECLARED.values() for key in keys})


def key_names(table: str) -> tuple[str, ...]:
    """The names of a table's keys, in their declared order."""
    return tuple(key.name for key in DECLARED[table])


def declared(table: str, name: str) -> Key:
    """The declaration of one key."""
    return next(key for key in DECLARED[table] if key.name == name)


def default_of(table: str, name: str) -> Any:
    """The declared default of a key (its owner's typed options read it here)."""
    key = declared(table, name)
    assert key.has_default, f"{table}.{name} has no declared default"
    return key.default


def check_table(table: Any, name: str, where: str | None = None) -> Mapping[str, Any]:
    """``table`` as a mapping whose keys are all ``name``'s (one-line error naming the
    first unknown key)."""
    where = where or name
    if not isinstance(table, Mapping):
        raise input_error(where, "a table", table)
    check_keys(table, key_names(name), where)
    return table


def table_schema(name: str, description: str) -> dict[str, Any]:
    """The closed JSON Schema of a table, generated from its key list."""
    return {
        "type": "object",
        "description": description,
        "properties": {key.name: key.json_schema() for key in DECLARED[name]},
        "additionalProperties": False,
    }
