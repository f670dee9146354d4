"""Names used in several places, declared once.

Every module that accepts or reports one of these vocabularies imports it from here (the old
module-level names, e.g. ``chargedesign.body.REALISABLE`` or ``chargedesign.checker.PRECISIONS``,
stay importable as re-exports). This module imports nothing, so the command line can use it
for ``--help`` without loading numpy.
"""

from __future__ import annotations

#: the format tag of design.json (CONTRACT.md)
DESIGN_FORMAT = "chargedesign.design/1"

#: the theorem's parameters as written in scenes and design.json (``lambda``: attribute ``lam``)
PARAMETER_NAMES = ("C", "c", "d", "n", "K", "kappa", "lambda", "rho")

#: the axisymmetric fields a scene or design may give (``fields.<kind>.legendre``)
FIELD_KINDS = ("magnetic", "electric", "gravity")
#: the same kinds, under the name the forward check uses
FIELD_NAMES = FIELD_KINDS

#: what a design may claim to realise (design.json ``realises``, scene ``design.realise``)
REALISABLE = ("mu", "V", "inertia")

#: the verdict's four states (design.json ``verdict.state``, CONTRACT.md "The verdict record")
VERDICT_STATES = (
    "buildable and realised",
    "buildable parts, NOT realised as designed",
    "NOT buildable",
    "not checked for buildability",
)
#: what holds the fixed point O, as the verdict records it (``verdict.support.state``)
SUPPORT_STATES = ("included", "open", "none")

#: design.json ``buildability``'s flag: every part within its limits (renamed from
#: ``buildable``: a body within its limits may still not be buildable or realised, which is
#: the verdict's word); files with the old name are read (``Design.from_dict``)
WITHIN_LIMITS_KEY = "parts_within_limits"
OLD_WITHIN_LIMITS_KEY = "buildable"

#: the element sources of a body, as design.json blocks
SOURCES = ("charges", "dipoles", "masses")

#: effects a simulation may include (scene ``simulation.effects``)
#: (``coils``: the magnetic effects act in the field apparatus' own field, the designed a1, a2
#: plus the coil pairs' degree >= 3 harmonics recorded in design.json)
EFFECTS = (
    "lorentz",
    "electric",
    "magnetization",
    "gravity",
    "induced",
    "eddy",
    "coils",
    "theorem",
)

#: effects the forward check reports: effect -> (source, field it needs or None)
CHECK_EFFECTS: dict[str, tuple[str, str | None]] = {
    "lorentz": ("charges", "magnetic"),
    "electric": ("charges", "electric"),
    "gravity": ("masses", "gravity"),
    "magnetization": ("dipoles", "magnetic"),
    "inertia": ("masses", None),
}

#: arithmetic of the forward check's sums (``chargedesign check --precision``)
PRECISIONS = ("auto", "double", "double-double")

#: default relative tolerance and orientation count of the forward check
CHECK_DEFAULT_TOL = 1e-9
CHECK_DEFAULT_ORIENTATIONS = 1000

#: design objectives per source (``[design] objective``); "robust" is the l1 norm weighted by
#: each candidate's first-order placement sensitivity (``[design] robust_weight`` mixes it)
OBJECTIVES = ("l1", "l2", "linf", "robust")

#: shapes of a scene's ``[body]`` region (candidate points)
BODY_SHAPES = ("ball", "box", "cylinder", "shell", "points", "mesh")

#: export formats of ``chargedesign export``
EXPORT_FORMATS = ("json", "csv", "vtp", "vtu")

#: the scene tables every stage may read (CONTRACT.md, and the physical tables of the limits)
SCENE_TABLES = (
    "parameters",
    "fields",
    "body",
    "design",
    "simulation",
    "initial",
    "output",
    "medium",
    "carriers",
    "magnets",
    "ballast",
    "tolerance",
    "testbed",
    "case",
    "support",
)

#: how the body is held (the ``[support]`` table, docs/flight.md): in free fall, in orbit, on
#: a full-sphere air bearing, or suspended electrostatically (like Gravity Probe B's rotors)
SUPPORT_STYLES = ("free_fall", "orbit", "air_bearing", "electrostatic")
#: the free-fall facilities the support knows (ZARM's Bremen Drop Tower: a drop, the catapult)
SUPPORT_FACILITIES = ("drop_tower_drop", "drop_tower_catapult")

#: the keys of a ``[case]`` table (a case of (ep), docs/workbench.md), in the order
#: chargedesign.scene.keys declares them; ``source`` and ``note`` are the catalogue's additions
CASE_KEYS = (
    "name",
    "inertia",
    "V",
    "l",
    "mu",
    "integral",
    "level",
    "parameters",
    "source",
    "note",
)

#: the materials' relative property errors a scene's ``[tolerance]`` table may give
MATERIAL_ERROR_KEYS = ("chi_relative", "density_relative", "magnetisation_relative")

#: how the theorem's n is realised (scene ``[design] larmor``, design.json ``larmor.reading``):
#: ``charges`` is the paper's (p6) reading (second moments of charge, a Larmor charge-to-mass
#: ratio); ``frame`` realises the theorem with n = 0 and reads the motion in axes turning at n
#: about Z (Larmor's theorem: n is a uniform rotation of axes)
LARMOR_READINGS = ("charges", "frame")

#: the axes a simulation writes its motion in (``[simulation] axes``, ``simulate --axes``):
#: ``turning`` (axes turning at the frame reading's rate about Z; the default for a ``frame``
#: body) or ``inertial`` (the body's own physics, n = 0 for a frame body)
SIMULATION_AXES = ("turning", "inertial")

#: trajectory state names in output files (CONTRACT.md)
STATE_NAMES = ("p", "q", "r", "gamma1", "gamma2", "gamma3")

#: how a sweep runs its points (``sweep --executor``)
SWEEP_EXECUTORS = ("process", "dask", "serial")

#: scipy's solve_ivp methods a simulation may use (``[simulation] method``)
SOLVE_IVP_METHODS = ("DOP853", "RK45", "RK23", "Radau", "BDF", "LSODA")
#: every integration method (:mod:`chargedesign.simulation.integrate`)
SIMULATION_METHODS = ("taylor", *SOLVE_IVP_METHODS, "gauss-legendre")
#: the default method (the integrator falls back to DOP853 when heyoka cannot be imported)
DEFAULT_SIMULATION_METHOD = "taylor"
#: the equations' routes (``[simulation] route``): reduced polynomials or direct sums
SIMULATION_ROUTES = ("reduced", "direct")
#: the conserved-quantity monitors, in report order
#: (:data:`chargedesign.simulation.monitors.MONITORS` has one entry per name)
MONITOR_NAMES = (
    "energy",
    "gamma_norm",
    "I3",
    "I4",
    "kowalevski",
    "lagrange",
    "F",
    "goriachev_chaplygin",
)
#: other names a monitor may be asked for by
MONITOR_ALIASES = {"I1": "energy", "I2": "gamma_norm", "goriachev": "goriachev_chaplygin"}

__all__ = [
    "BODY_SHAPES",
    "CASE_KEYS",
    "CHECK_DEFAULT_ORIENTATIONS",
    "CHECK_DEFAULT_TOL",
    "CHECK_EFFECTS",
    "DEFAULT_SIMULATION_METHOD",
    "DESIGN_FORMAT",
    "EFFECTS",
    "EXPORT_FORMATS",
    "FIELD_KINDS",
    "FIELD_NAMES",
    "LARMOR_READINGS",
    "MONITOR_ALIASES",
    "MONITOR_NAMES",
    "OBJECTIVES",
    "PARAMETER_NAMES",
    "PRECISIONS",
    "REALISABLE",
    "SCENE_TABLES",
    "SIMULATION_AXES",
    "SIMULATION_METHODS",
    "SIMULATION_ROUTES",
    "SOLVE_IVP_METHODS",
    "SOURCES",
    "STATE_NAMES",
    "SUPPORT_FACILITIES",
    "SUPPORT_STYLES",
    "SWEEP_EXECUTORS",
]
