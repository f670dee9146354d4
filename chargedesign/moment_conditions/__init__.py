"""The conditions engine: target parameters and fields -> linear conditions on moments.

What each kind of element must realise, as linear conditions ``A w = b`` on its Cartesian
moments (see ``docs/conditions.md`` for the derivation and the choices):

- **charges** (Lorentz force in the magnetic field) realise ``mu``: the charges' gyroscopic
  vector ``mu = -sum q (r . B) r`` (B = -grad Phi_m in body axes) is expanded with the
  moments as unknowns, reduced on ``|gamma| = 1`` and matched coefficient by coefficient
  with the theorem's ``mu``; the linear system is solved exactly (sympy / rationals);
- **V** (lambda = rho = 0) is split into spherical-harmonic degrees 0..4; a source of
  weights w in a degree-k field term ``f_k R^k P_k`` contributes ``f_k sum_m W_km R_km(gamma)``
  (addition theorem), so each degree is realised by one source: dipoles in the magnetic
  quadrupole (degree 2), charges in an electric octupole (degree 3, strength forced by the
  charges' mu-fixed third moments) and hexadecapole (degree 4); every other source that sits
  in a field of that degree is made to contribute nothing (or its forced minimum);
- **masses** realise the inertia ``A = B = 2C`` about O (products zero), and sit with their
  centre at O when a uniform gravity field is present.

The data types are shared with the design stage: :class:`LinearCondition` and
:class:`LinearConditions` (``system(source, positions)`` builds ``A`` and ``b``).
SymPy is imported lazily (only a derivation beyond the shipped tables needs it), so importing the
data types is cheap.

Modules (each imports only those above it):

- :mod:`~chargedesign.moment_conditions.constants`: what is accepted, the defaults and preferences;
- :mod:`~chargedesign.moment_conditions.types`: :class:`LinearCondition`, :class:`LinearConditions`;
- :mod:`~chargedesign.moment_conditions.algebra`: exact rational algebra (reduction on the sphere,
  elimination, the per-source echelon system);
- :mod:`~chargedesign.moment_conditions.table_data`: the shipped tables of the pure, degree-only
  pieces (harmonics, V on the sphere, mu equations), read without sympy;
- :mod:`~chargedesign.moment_conditions.harmonics`: real solid harmonics and the projection on
  ``|gamma| = 1`` (sympy, lazily);
- :mod:`~chargedesign.moment_conditions.context`: the state of one derivation;
- :mod:`~chargedesign.moment_conditions.mu`: the charges' mu by coefficient matching, and its
  symbolic solution;
- :mod:`~chargedesign.moment_conditions.potential`: V by degrees, forced and default field
  strengths;
- :mod:`~chargedesign.moment_conditions.inertia`: the masses' inertia;
- :mod:`~chargedesign.moment_conditions.derive`: :func:`derive_conditions`, which runs the steps;
- :mod:`~chargedesign.moment_conditions.scene`: :func:`conditions_for_scene`, :func:`scene_length`,
  :func:`realise_from_scene`;
- :mod:`~chargedesign.moment_conditions.level`: the level of I3 (``l . gamma`` of the charges);
- :mod:`~chargedesign.moment_conditions.audit`: :func:`audit_p6`, the paper's printed conditions;
- :mod:`~chargedesign.moment_conditions.case`: ``derive_case_conditions``, the same steps for a
  case of (ep) with polynomial V and mu (the workbench);
- :mod:`~chargedesign.moment_conditions.tables`: the tables derived with sympy, their text and
  ``write_tables`` (``make tables``).
"""

from chargedesign.moment_conditions.audit import audit_p6
from chargedesign.moment_conditions.constants import (
    DEFAULT_ELECTRIC_STRENGTH,
    DEFAULT_LENGTH,
    DEFAULT_LENGTH_RULE,
    DEFAULT_MAGNETIC,
    DEFAULT_PREFERENCE,
    DEFAULT_STRENGTH_HEADROOM,
    DEGREE_PREFERENCE,
    FIELD_KINDS,
    FIELD_LETTERS,
    FIELD_MATCH_RTOL,
    MAX_FIELD_DEGREE,
    REALISABLE,
    SOURCE_FIELD,
    SOURCES,
    V_DEGREE,
)
from chargedesign.moment_conditions.derive import derive_conditions
from chargedesign.moment_conditions.level import l_dot_gamma_residual, physical_l_dot_gamma
from chargedesign.moment_conditions.mu import moment_symbol, symbolic_mu_solution
from chargedesign.moment_conditions.scene import (
    conditions_for_scene,
    realise_from_scene,
    scene_length,
)
from chargedesign.moment_conditions.types import LinearCondition, LinearConditions

# isort: split
# private helpers that tests and docs/conditions.md import from here (pure, cached)
from chargedesign.moment_conditions.harmonics import real_solid_harmonics as real_solid_harmonics
from chargedesign.moment_conditions.mu import mu_system as mu_system

__all__ = [
    "DEFAULT_ELECTRIC_STRENGTH",
    "DEFAULT_LENGTH",
    "DEFAULT_LENGTH_RULE",
    "DEFAULT_MAGNETIC",
    "DEFAULT_PREFERENCE",
    "DEFAULT_STRENGTH_HEADROOM",
    "DEGREE_PREFERENCE",
    "FIELD_KINDS",
    "FIELD_LETTERS",
    "FIELD_MATCH_RTOL",
    "MAX_FIELD_DEGREE",
    "REALISABLE",
    "SOURCES",
    "SOURCE_FIELD",
    "V_DEGREE",
    "LinearCondition",
    "LinearConditions",
    "audit_p6",
    "conditions_for_scene",
    "derive_conditions",
    "l_dot_gamma_residual",
    "moment_symbol",
    "physical_l_dot_gamma",
    "realise_from_scene",
    "scene_length",
    "symbolic_mu_solution",
]
