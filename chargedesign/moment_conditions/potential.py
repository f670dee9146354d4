"""V by spherical-harmonic degrees, and the field strengths it forces or leaves open.

V (lambda = rho = 0) is split into degrees 0..4; a source of weights w in a degree-k field
term ``f_k R^k P_k`` contributes ``f_k sum_m W_km R_km(gamma)`` (addition theorem), so each
degree is realised by one source (:data:`DEGREE_PREFERENCE`): dipoles in the magnetic
quadrupole (degree 2), charges in an electric octupole (degree 3, strength forced by the
charges' mu-fixed third moments) and hexadecapole (degree 4, strength chosen for the body,
:func:`_default_strength`); every other source in a field of that degree is made to
contribute nothing (or its forced minimum).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from fractions import Fraction
from functools import lru_cache

from chargedesign.errors import InfeasibleError
from chargedesign.formatting import fmt
from chargedesign.moment_conditions.algebra import SourceSystem, exact_nullspace, solve_exact
from chargedesign.moment_conditions.constants import (
    DEFAULT_ELECTRIC_STRENGTH,
    DEFAULT_PREFERENCE,
    DEFAULT_STRENGTH_HEADROOM,
    DEGREE_PREFERENCE,
    FIELD_LETTERS,
    FIELD_MATCH_RTOL,
    PARAM_NAMES,
    SOURCE_FIELD,
    V_DEGREE,
)
from chargedesign.moment_conditions.context import (
    DerivationContext,
    decimal_text,
    field_coefficient_name,
)
from chargedesign.moment_conditions.harmonics import (
    ParamPoly,
    SolidHarmonic,
    gamma_poly,
    project_on_harmonics,
    real_solid_harmonics,
)
from chargedesign.moment_conditions.table_data import shipped_table


@lru_cache(maxsize=1)
def v_projection() -> dict[str, ParamPoly]:
    """The theorem's V (lambda = rho = 0) on the sphere in the harmonic basis, degrees 0..4.

    Read from the shipped table (the same as :func:`derive_v_projection`, which the tests
    check exactly).
    """
    table = shipped_table("v_projection")
    if table is not None:
        return {label: ParamPoly.from_json(entry) for label, entry in table.items()}
    return derive_v_projection()


@lru_cache(maxsize=1)
def derive_v_projection() -> dict[str, ParamPoly]:
    """:func:`v_projection` derived with sympy (the source of the shipped table)."""
    import sympy as sp

    from chargedesign.model.case import lam, rho, symbolic_case

    V = symbolic_case().V.subs({lam: 0, rho: 0})
    V = sp.expand(sp.cancel(V))
    return {
        label: ParamPoly.from_sympy(coef)
        for label, coef in project_on_harmonics(gamma_poly(V), V_DEGREE).items()
    }


#: what "contributes nothing to degree 1" means for each source
_DEGREE_ONE_MEANING = {
    "masses": " (centre of mass at O: uniform gravity adds nothing to V)",
    "dipoles": " (total dipole moment zero: the uniform field a1 adds nothing to V)",
    "charges": " (electric dipole moment zero: the uniform field e1 adds nothing to V)",
}


def _functionals(source: str, k: int) -> list[tuple[SolidHarmonic, dict[str, Fraction]]]:
    if source == "dipoles":
        return [(h, h.dipole_moments()) for h in real_solid_harmonics(k)]
    return [(h, h.moments()) for h in real_solid_harmonics(k)]


def _min_norm(
    W0: list[Fraction], G: list[list[Fraction]], weights: list[Fraction]
) -> list[Fraction]:
    """The attainable ``W = W0 + G t`` of least ``sum weight_m W_m^2`` (exact)."""
    nfree = len(G[0]) if G else 0
    if nfree == 0:
        return list(W0)
    normal = [
        [
            sum((weights[m] * G[m][i] * G[m][j] for m in range(len(W0))), Fraction(0))
            for j in range(nfree)
        ]
        for i in range(nfree)
    ]
    rhs = [
        -sum((weights[m] * G[m][i] * W0[m] for m in range(len(W0))), Fraction(0))
        for i in range(nfree)
    ]
    t = solve_exact(normal, rhs)
    if t is None:  # pragma: no cover - normal equations are always consistent
        raise AssertionError("inconsistent normal equations")
    return [
        W0[m] + sum((G[m][j] * t[j] for j in range(nfree)), Fraction(0)) for m in range(len(W0))
    ]


def _degree_description(k: int, P: Sequence[Fraction]) -> str:
    """Which theorem parameters make up the degree-k part of V (for messages)."""
    proj = v_projection()
    zonal: set[str] = set()
    sectoral: set[str] = set()
    for h in real_solid_harmonics(k):
        if h.label not in proj:
            continue
        for exps, coef in proj[h.label].terms:
            term = coef
            for v, e in zip(P, exps, strict=True):
                term *= v**e
            if term == 0:
                continue
            names = {PARAM_NAMES[i] for i, e in enumerate(exps) if e and i >= 3}
            (zonal if h.label.endswith(",0c") else sectoral).update(names)
    parts = []
    if zonal:
        parts.append("zonal part from " + ", ".join(sorted(zonal)))
    if sectoral:
        parts.append("sectoral part from " + ", ".join(sorted(sectoral)))
    return "; ".join(parts) if parts else "no target terms"


def v_target(ctx: DerivationContext) -> dict[str, tuple[Fraction, str]]:
    """V on the sphere, harmonic label -> (exact coefficient, its text): a case's own
    (``ctx.v_target``) or the theorem's at the derivation's parameters."""
    if ctx.v_target is not None:
        return ctx.v_target
    return {label: (poly(ctx.P), poly.text) for label, poly in v_projection().items()}


def realise_degree(ctx: DerivationContext, k: int) -> None:
    """Assign the degree-k part of V to one source; make the others contribute their least."""
    proj = v_target(ctx)
    harmonics = real_solid_harmonics(k)
    target = [proj[h.label][0] if h.label in proj else Fraction(0) for h in harmonics]
    weights = [h.weight for h in harmonics]
    present = list(ctx.systems)
    carriers = [
        s
        for s in present
        if ctx.coefficient(SOURCE_FIELD[s], k) != 0 or SOURCE_FIELD[s] in ctx.derivable
    ]
    table = DEGREE_PREFERENCE if ctx.preference is None else ctx.preference
    preference = table.get(k, DEFAULT_PREFERENCE)
    options: list[str | None] = [s for s in preference if s in carriers]
    if not options:
        options = [None]
    reasons: list[str] = []
    for s in preference:
        if s not in present:
            continue
        kind = SOURCE_FIELD[s]
        if s not in carriers:
            reasons.append(
                f"{s}: fields.{kind} has no degree-{k} term ({field_coefficient_name(kind, k)} = 0)"
            )
    description = (
        _degree_description(k, ctx.P) if ctx.v_target is None else f"the case's degree-{k} part"
    )
    for designated in options:
        trial = {s: ctx.systems[s].copy() for s in present}
        remainder = list(target)
        notes: list[str] = []
        # non-designated sources: the least unwanted contribution their conditions allow
        for s in carriers:
            if s == designated:
                continue
            kind = SOURCE_FIELD[s]
            f = ctx.coefficient(kind, k)
            if f == 0:
                continue  # derivable field not used at this degree
            funcs = _functionals(s, k)
            W0, G = trial[s].affine_image([L for _, L in funcs])
            W = _min_norm(W0, G, weights)
            for (h, L), value in zip(funcs, W, strict=True):
                trial[s].add_display(
                    L,
                    value,
                    f"V degree {k}: {s} in fields.{kind} {field_coefficient_name(kind, k)} "
                    f"contribute {'nothing' if value == 0 else 'their least (fixed) part'} "
                    f"to the harmonic {h.text}" + _DEGREE_ONE_MEANING.get(s, "") * (k == 1),
                )
            for m, value in enumerate(W):
                remainder[m] -= f * weights[m] * value
            if any(W):
                notes.append(
                    f"V degree {k}: {s} in fields.{kind} contribute a fixed part (their moments "
                    "are fixed by other conditions); the designated source realises the rest"
                )
        if designated is None:
            if any(remainder):
                reasons.append(f"no source carries degree {k}")
                break
            ctx.systems.update(trial)
            ctx.notes.extend(notes)
            return
        ok, reason = _designate(ctx, trial, designated, k, remainder, notes)
        if ok:
            ctx.systems.update(trial)
            ctx.notes.extend(notes)
            return
        reasons.append(reason)
    raise InfeasibleError(f"V degree {k} ({description}) cannot be realised: " + "; ".join(reasons))


def proportionality(fixed: list[Fraction], wanted: list[Fraction]) -> Fraction | None:
    """The scalar f with ``wanted == f * fixed`` exactly (fixed not all zero), else None."""
    norm = sum((v * v for v in fixed), Fraction(0))
    f = sum((a * b for a, b in zip(fixed, wanted, strict=True)), Fraction(0)) / norm
    return f if all(w == f * v for w, v in zip(wanted, fixed, strict=True)) else None


def _designate(
    ctx: DerivationContext,
    trial: dict[str, SourceSystem],
    source: str,
    k: int,
    remainder: list[Fraction],
    notes: list[str],
) -> tuple[bool, str]:
    """Let ``source`` realise ``remainder`` (harmonic coefficients of degree k).

    The source contributes ``f w_km W_km``; its own conditions (mu for charges, the inertia
    for masses) may already fix some combinations ``Z W = Z W0`` of its degree-k moments.
    Then ``f`` is forced (``Z remainder/w = f Z W0``): derived when the field is the engine's
    to choose, checked against the user's value otherwise.
    """
    kind = SOURCE_FIELD[source]
    harmonics = real_solid_harmonics(k)
    funcs = _functionals(source, k)
    scaled = [r / h.weight for r, h in zip(remainder, harmonics, strict=True)]  # = f * W
    W0, G = trial[source].affine_image([L for _, L in funcs])
    # rows z with z G = 0: the combinations of W fixed by the source's other conditions
    nfree = len(G[0]) if G else 0
    transposed = [[G[m][j] for m in range(len(W0))] for j in range(nfree)]
    Z = exact_nullspace(transposed, len(W0))
    fixed = [sum((z[m] * W0[m] for m in range(len(W0))), Fraction(0)) for z in Z]
    wanted = [sum((z[m] * scaled[m] for m in range(len(W0))), Fraction(0)) for z in Z]
    name = field_coefficient_name(kind, k)
    fixer = "mu" if source == "charges" else "the inertia" if source == "masses" else "V"
    need: Fraction | None = None
    if any(fixed):
        need = proportionality(fixed, wanted)
        if need is None:
            return False, (
                f"{source} in fields.{kind}: {fixer} fixes their degree-{k} moments, which "
                "cannot give this part"
            )
    elif any(wanted):
        return False, (
            f"{source} in fields.{kind}: {fixer} fixes their degree-{k} moments (to zero in "
            "the needed directions), so they cannot give this part"
        )
    if kind in ctx.derivable:
        if need is not None:
            f = need
            why = f"forced: {fixer} fixes the {source}' degree-{k} moments"
        elif any(scaled):
            f, why = _default_strength(ctx, trial[source], source, k, scaled)
            ctx.defaults[f"{kind} {FIELD_LETTERS[kind]}{k}"] = f
        else:
            f, why = Fraction(0), f"not needed (no degree-{k} part for the {source})"
        ctx.set_coefficient(kind, k, f)
        if f != 0 or k <= V_DEGREE:
            notes.append(f"fields.{kind} {name} = {decimal_text(f)} derived: {why}")
    else:
        f = ctx.coefficient(kind, k)
        if need is not None and need != f:
            close = abs(need - f) <= FIELD_MATCH_RTOL * abs(need)
            if ctx.exact or not close:
                return False, (
                    f"fields.{kind} {name} = {decimal_text(f)} does not fit: {fixer} fixes the "
                    f"{source}' degree-{k} moments, which require {name} = {decimal_text(need)}"
                )
            notes.append(
                f"fields.{kind} {name} = {decimal_text(f)} given matches the required "
                f"{decimal_text(need)} to rounding; the conditions use the required value"
            )
            f = need
    if f == 0:
        if any(scaled):
            return False, f"{source}: fields.{kind} {name} = 0"
        return True, ""
    proj = v_target(ctx)
    whose = "theorem's" if ctx.v_target is None else "case's"
    for (h, L), value in zip(funcs, scaled, strict=True):
        theorem = proj[h.label][1] if h.label in proj else "0"
        trial[source].add_display(
            L,
            value / f,
            f"V degree {k}: {source} in fields.{kind} {name} realise the {whose} "
            f"coefficient {theorem} of the harmonic {h.text}",
        )
    if any(scaled):
        notes.append(
            f"V degree {k}: realised by {source} in fields.{kind} ({name} = {decimal_text(f)})"
        )
    return True, ""


def _log10(value: Fraction) -> float:
    """log10 of a positive exact value (no overflow for huge or tiny values)."""
    return math.log10(value.numerator) - math.log10(value.denominator)


def _default_strength(
    ctx: DerivationContext, system: SourceSystem, source: str, k: int, scaled: Sequence[Fraction]
) -> tuple[Fraction, str]:
    """A degree-k strength that is needed but not forced: suited to the body's size.

    The source must give ``scaled_m / f`` as its degree-k harmonic moments ``W_km``. With the
    Racah normalisation ``|sqrt(w_km) H_km(r)|`` summed in squares over m is ``|r|^(2k)``, so
    weights of total size Q within a distance L give degree-k moments of Racah norm at most
    ``Q L^k``. The other conditions already fix moments of the source (mu fixes the charges'
    second and third moments), hence ``Q ~ max |M_key| / L^order``. The strength is chosen so
    that the required moments are :data:`DEFAULT_STRENGTH_HEADROOM` (100) times smaller
    than that natural size (rounded to a power of ten): the source then needs no significant
    cancellation to keep its degree-k moments small (a strength too large for the body makes
    them tiny against what its weights carry), nor larger weights than the other conditions
    need (a strength too small). Nothing fixed (Q = 0): :data:`DEFAULT_ELECTRIC_STRENGTH`.
    """
    L = ctx.length
    harmonics = real_solid_harmonics(k)
    target_sq = sum((h.weight * v * v for h, v in zip(harmonics, scaled, strict=True)), Fraction(0))
    natural = Fraction(0)
    for key, (row, rhs, _) in system.pivots.items():
        if len(row) != 1 or rhs == 0:
            continue
        order = len(key.split(":")[-1])
        natural = max(natural, abs(rhs / row[key]) / L**order)
    length_text = (
        f"L = {decimal_text(L)} m"
        if ctx.length_given
        else f"L = {decimal_text(L)} m assumed (no length given)"
    )
    if natural == 0:
        return Fraction(DEFAULT_ELECTRIC_STRENGTH), (
            f"default strength (not forced; no other condition fixes the {source}' size)"
        )
    # log10 of headroom * sqrt(target_sq) / (Q L^k)
    raw = 0.5 * _log10(target_sq) - _log10(natural) - k * _log10(L)
    exponent = round(raw + math.log10(DEFAULT_STRENGTH_HEADROOM))
    f = Fraction(10) ** exponent
    return f, (
        f"default strength (not forced), chosen for the body's length {length_text}: the "
        f"required degree-{k} moments are then about 1/{DEFAULT_STRENGTH_HEADROOM} of the "
        f"natural size Q L^{k} of {source} of total size Q ~ {fmt(float(natural))} (fixed by "
        "the other conditions): no extra weight, no significant cancellation"
    )
