"""``derive_conditions``: the theorem's parameters and fields -> linear moment conditions.

Validates the inputs, reads them as exact rationals, derives the fields a scene leaves out,
then runs the steps in order (mu for the charges, the inertia for the masses, V degree by
degree) on one exact echelon system per source, and rounds the result to
:class:`LinearConditions`.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Iterable, Mapping, Sequence
from fractions import Fraction
from typing import Any

from chargedesign.errors import InfeasibleError
from chargedesign.formatting import PLAIN, fmt
from chargedesign.limits import MAX_FIELD_DEGREE
from chargedesign.moment_conditions.algebra import SourceSystem
from chargedesign.moment_conditions.constants import (
    DEFAULT_LENGTH,
    DEFAULT_MAGNETIC,
    FIELD_KINDS,
    PARAM_NAMES,
    REALISABLE,
    SOURCES,
    V_DEGREE,
)
from chargedesign.moment_conditions.context import DerivationContext
from chargedesign.moment_conditions.harmonics import real_solid_harmonics
from chargedesign.moment_conditions.inertia import masses_for_inertia
from chargedesign.moment_conditions.mu import charges_for_mu
from chargedesign.moment_conditions.potential import realise_degree, v_projection
from chargedesign.moment_conditions.types import LinearCondition, LinearConditions
from chargedesign.params import Parameters
from chargedesign.validation import as_array, as_finite_float, input_error


def _exact(value: float, exact: bool) -> Fraction:
    """The exact rational of a float: as printed (``0.3 -> 3/10``) or its binary value."""
    return Fraction(repr(value)) if exact else Fraction(value)


def derive_conditions(
    params: Parameters,
    fields: Mapping[str, Sequence[float]] | None = None,
    realise: Iterable[str] = REALISABLE,
    *,
    exact: bool = False,
    length: float | None = None,
) -> LinearConditions:
    """Linear moment conditions that realise the theorem's mu, V and inertia.

    Parameters
    ----------
    params : Parameters
        The theorem's parameters (SI units). lambda and rho must be 0 when realising mu or V.
    fields : mapping of str to sequence of float, optional
        Legendre coefficients per field kind (``magnetic``, ``electric``, ``gravity``), as in
        design.json (the paper's a1, a2 are ``[a1, 2 a2]``). A kind that is absent is
        derived: magnetic ``[1, 1]`` where needed, electric from the forced/default
        strengths, no gravity. A given field is used as given (missing terms are 0).
    realise : iterable of str
        Subset of ``mu``, ``V``, ``inertia``.
    exact : bool
        Read the inputs as the decimals they print as (``0.3 -> 3/10``) and report exact
        rational values (``exact_value``). Otherwise the binary value of each float is used;
        both paths compute exactly, the float values are correctly rounded.
    length : float, optional
        The body's length scale in m (largest distance of a candidate from O). A field
        strength that is needed but not forced (e.g. the electric e4 when no electric field
        is given) is chosen for it, so that the moments it requires have the natural size of
        the elements the other conditions force (docs/conditions.md). None: 1 m is assumed
        and ``length_assumed`` is set (:func:`chargedesign.designer.design_body` then
        re-derives for the candidates' size). Given field strengths never depend on it.

    Returns
    -------
    LinearConditions

    Raises
    ------
    InputError
        Non-finite or malformed input.
    InfeasibleError
        The targets cannot be realised (the message names the cause).
    """
    if not isinstance(params, Parameters):
        raise TypeError(f"params: expected a Parameters, got {type(params).__name__}")
    goals = validate_realise(realise, "realise")
    P = [_exact(getattr(params, name), exact) for name in PARAM_NAMES]
    given, ctx = open_derivation(params, P, fields, length, exact=exact)
    _refuse_singular(params, goals)
    _derive_missing_fields(ctx, given, goals)
    _run_steps(ctx, given, goals)
    rederive = functools.partial(derive_conditions, params, fields, goals, exact=exact)
    return close_derivation(ctx, goals, rederive)


def validate_realise(realise: Any, name: str) -> tuple[str, ...]:
    """The validated ``realise`` items (known to REALISABLE, not repeated) as a tuple."""
    if isinstance(realise, str) or not isinstance(realise, Iterable):
        raise input_error(name, "a list of " + ", ".join(REALISABLE), realise)
    items = list(realise)
    for item in items:
        if item not in REALISABLE:
            raise input_error(name, "items among " + ", ".join(REALISABLE), item)
    if len(set(items)) != len(items):
        raise input_error(name, "no repeated items", items)
    return tuple(k for k in REALISABLE if k in items)


def validate_fields(fields: Any) -> dict[str, tuple[float, ...]]:
    """``{kind: legendre coefficients}`` of a fields mapping, trailing zeros dropped."""
    if fields is None:
        return {}
    if not isinstance(fields, Mapping):
        raise input_error("fields", "a mapping of field kind to legendre coefficients", fields)
    out: dict[str, tuple[float, ...]] = {}
    for kind, value in fields.items():
        if kind not in FIELD_KINDS:
            raise input_error(f"fields.{kind}", "one of " + ", ".join(FIELD_KINDS), kind)
        if isinstance(value, (list, tuple)) and len(value) == 0:
            coeffs: tuple[float, ...] = ()
        else:
            coeffs = tuple(float(v) for v in as_array(value, f"fields.{kind}", (None,)))
        while coeffs and coeffs[-1] == 0.0:
            coeffs = coeffs[:-1]
        if len(coeffs) > MAX_FIELD_DEGREE:
            raise input_error(
                f"fields.{kind}", f"a field of degree <= {MAX_FIELD_DEGREE}", list(coeffs)
            )
        out[kind] = coeffs
    return out


def open_derivation(
    params: Parameters,
    P: list[Fraction],
    fields: Mapping[str, Sequence[float]] | None,
    length: float | None,
    *,
    exact: bool,
    **context: Any,
) -> tuple[dict[str, tuple[float, ...]], DerivationContext]:
    """The given fields and length checked (one-line errors), and the state of a derivation
    that reads them as exact rationals (as printed with ``exact``, else their binary values):
    a kind not given is empty and "derived" until the engine derives it; ``context``: the
    further fields of :class:`DerivationContext` (a case's targets)."""
    given = validate_fields(fields)
    if length is not None:
        length = as_finite_float(length, "length", positive=True)
    ctx = DerivationContext(
        params=params,
        P=P,
        exact=exact,
        fields={kind: [_exact(v, exact) for v in given.get(kind, ())] for kind in FIELD_KINDS},
        derivable=set(),
        systems={},
        notes=[],
        length=_exact(DEFAULT_LENGTH if length is None else length, exact),
        length_given=length is not None,
        origin={kind: "given" if kind in given else "derived" for kind in FIELD_KINDS},
        **context,
    )
    return given, ctx


def close_derivation(
    ctx: DerivationContext, realise: tuple[str, ...], rederive: Callable[..., LinearConditions]
) -> LinearConditions:
    """The derivation's result: every source's rows rounded, the fields in use and their
    origin (given/derived), the notes, and the default strengths with the length they were
    chosen for; ``rederive(length=...)`` derives again for another body size."""
    conditions = rounded_conditions(ctx)
    return LinearConditions(
        conditions=conditions,
        fields=output_fields(ctx),
        notes=ctx.notes,
        realise=realise,
        field_origin={kind: ctx.origin[kind] for kind in FIELD_KINDS},
        length=float(ctx.length) if ctx.defaults else None,
        length_assumed=bool(ctx.defaults) and not ctx.length_given,
        default_strengths={name: float(v) for name, v in ctx.defaults.items()},
        _rederive=rederive,
    )


def _refuse_singular(params: Parameters, goals: tuple[str, ...]) -> None:
    """InfeasibleError when lambda or rho is set and mu or V is to be realised."""
    if params.singular and ({"mu", "V"} & set(goals)):
        which = ", ".join(
            f"{name} = {fmt(value, PLAIN)}"
            for name, value in (("lambda", params.lam), ("rho", params.rho))
            if value != 0
        )
        raise InfeasibleError(
            f"parameters {which}: singular on gamma3 = 0: no finite charge distribution realises "
            "them; the model and the reduced simulation still accept them"
        )


def _derive_missing_fields(
    ctx: DerivationContext, given: Mapping[str, tuple[float, ...]], goals: tuple[str, ...]
) -> None:
    """Fill in ``ctx.fields`` for the kinds not given: the magnetic field where mu or V needs
    it; the electric field is the engine's to choose for V."""
    P = ctx.P
    if "magnetic" not in given:
        needs_f1 = "mu" in goals and P[3] != 0
        proj = v_projection()
        needs_f2 = ("mu" in goals and P[4] != 0) or (
            "V" in goals
            and any(proj[h.label](P) != 0 for h in real_solid_harmonics(2) if h.label in proj)
        )
        derived = [
            Fraction(DEFAULT_MAGNETIC[0]) if needs_f1 else Fraction(0),
            Fraction(DEFAULT_MAGNETIC[1]) if needs_f2 else Fraction(0),
        ]
        while derived and derived[-1] == 0:
            derived.pop()
        ctx.fields["magnetic"] = derived
        if derived:
            ctx.notes.append(
                "fields.magnetic derived (none given): legendre "
                f"{[float(v) for v in derived]} (a1 = 1 T, a2 = 0.5 T/m where needed)"
            )
    if "electric" not in given and "V" in goals:
        ctx.derivable.add("electric")


def _run_steps(
    ctx: DerivationContext, given: Mapping[str, tuple[float, ...]], goals: tuple[str, ...]
) -> None:
    """Open one exact system per source and run mu, inertia, then V degree by degree."""
    if "mu" in goals or "V" in goals:
        ctx.systems["charges"] = SourceSystem()
    if "V" in goals:
        ctx.systems["dipoles"] = SourceSystem()
    if "inertia" in goals:
        ctx.systems["masses"] = SourceSystem()
    if "mu" in goals:
        charges_for_mu(ctx)
    if "inertia" in goals:
        masses_for_inertia(ctx)
    if "V" in goals:
        kmax = max(
            V_DEGREE,
            len(ctx.fields["magnetic"]),
            len(ctx.fields["electric"]),
            len(ctx.fields["gravity"]) if "masses" in ctx.systems else 0,
        )
        for k in range(1, kmax + 1):
            realise_degree(ctx, k)
        if "masses" not in ctx.systems and any(ctx.fields["gravity"]):
            ctx.notes.append("fields.gravity acts on no designed element (inertia not realised)")
    elif given.get("electric"):
        ctx.notes.append("fields.electric is not used: V is not realised")
    if "V" in goals and "mu" not in goals:
        ctx.notes.append("charges: mu is not realised; their moments serve V only")


def rounded_conditions(ctx: DerivationContext) -> list[LinearCondition]:
    """The rows of every source's system, rounded to floats (with exact text when exact)."""
    exact = ctx.exact
    conditions = []
    for source in SOURCES:
        system = ctx.systems.get(source)
        if system is None:
            continue
        for row in system.display:
            conditions.append(
                LinearCondition(
                    source=source,
                    coefficients={k: float(v) for k, v in row.coeffs.items()},
                    value=float(row.rhs),
                    provenance=row.provenance,
                    exact_value=str(row.rhs) if exact else "",
                    exact_coefficients={k: str(v) for k, v in row.coeffs.items()} if exact else {},
                )
            )
    return conditions


def output_fields(ctx: DerivationContext) -> dict[str, tuple[float, ...]]:
    """Every field kind's coefficients as floats (trailing zeros dropped); with ``exact``,
    a note of each derived field's exact coefficients."""
    out_fields: dict[str, tuple[float, ...]] = {}
    for kind in FIELD_KINDS:
        coeffs = list(ctx.fields.get(kind, []))
        while coeffs and coeffs[-1] == 0:
            coeffs.pop()
        out_fields[kind] = tuple(float(v) for v in coeffs)
        if ctx.exact and ctx.origin[kind] == "derived" and coeffs:
            ctx.notes.append(f"fields.{kind} exact legendre: [{', '.join(map(str, coeffs))}]")
    return out_fields
