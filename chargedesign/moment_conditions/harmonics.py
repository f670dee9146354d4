"""Solid harmonics and coefficient matching on the sphere ``|gamma| = 1`` (sympy, lazily).

The real solid harmonics ``H_km`` with their addition-theorem weights (Racah
normalisation), the exact projection of a polynomial in gamma onto them, and the symbolic
pieces the mu and V derivations share. SymPy is imported inside the functions only; the
harmonics up to ``MAX_FIELD_DEGREE`` are read from the shipped table
(:mod:`~chargedesign.moment_conditions.table_data`), which the tests re-derive with sympy.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from functools import cache, lru_cache
from typing import Any

from chargedesign.moment_conditions.algebra import inverse_exact, sphere_reduce
from chargedesign.moment_conditions.constants import MAX_FIELD_DEGREE, PARAM_NAMES
from chargedesign.moment_conditions.table_data import fraction_text, shipped_table
from chargedesign.moments import moment_key


@lru_cache(maxsize=1)
def sympy_symbols() -> dict[str, Any]:
    """The sympy symbols of the derivation: x, y, z, the gammas, the parameters, the f_k."""
    import sympy as sp

    from chargedesign.model import case

    x, y, z = sp.symbols("x y z", real=True)
    return {
        "x": x,
        "y": y,
        "z": z,
        "gammas": (case.g1, case.g2, case.g3),
        "params": tuple(getattr(case, name) for name in PARAM_NAMES),
        "fs": sp.symbols(f"f1:{MAX_FIELD_DEGREE + 1}", real=True),
    }


def field_symbols(degree: int) -> tuple[Any, ...]:
    """Legendre coefficients ``f_1 .. f_degree`` of a field as sympy symbols."""
    return tuple(sympy_symbols()["fs"][:degree])


def body_coordinates() -> tuple[Any, Any, Any, Any, Any]:
    """``(x, y, z, Z, S)``: body coordinates, ``Z = r . gamma`` and ``S = R^2 = r . r`` (sympy)."""
    sym = sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    g1, g2, g3 = sym["gammas"]
    return x, y, z, x * g1 + y * g2 + z * g3, x * x + y * y + z * z


def in_z_and_s(poly: Any, degree: int, Z: Any, S: Any) -> Any:
    """``R^degree p(Z/R)`` as a polynomial in Z and S = R^2, for a polynomial ``p`` in one
    variable (``sympy.Poly``) whose powers have the parity of ``degree``."""
    return sum(co * Z**e * S ** ((degree - e) // 2) for (e,), co in poly.terms())


def zonal_solid_harmonic(k: int, Z: Any, S: Any) -> Any:
    """``R^k P_k(Z/R)`` as a polynomial in Z and S = R^2 (sympy)."""
    import sympy as sp

    u = sp.Symbol("u")
    poly = sp.Poly(sp.legendre(k, u), u)
    return sp.expand(in_z_and_s(poly, k, Z, S))


@dataclass(frozen=True)
class SolidHarmonic:
    """A real solid harmonic ``H_km`` (rational coefficients) and its addition-theorem weight.

    ``|a|^k |b|^k P_k(a.b / |a||b|) = sum_m weight_km H_km(a) H_km(b)``; with
    ``R_km = sqrt(weight) H_km`` this is the Racah normalisation. ``H_k0 = R^k P_k``,
    ``H_km = Re / Im (x + i y)^m * R^(k-m) P_k^(m)(z/R)`` (m-th derivative of P_k).
    """

    degree: int
    label: str  # e.g. "2,2c"
    weight: Fraction
    poly: dict[tuple[int, int, int], Fraction]  # exponents of (x, y, z)
    text: str  # H_km(gamma) as a sympy string, for provenance

    def moments(self) -> dict[str, Fraction]:
        """``sum_j w_j H_km(r_j)`` as a combination of Cartesian moment keys."""
        return {moment_key(e): c for e, c in self.poly.items()}

    def dipole_moments(self) -> dict[str, Fraction]:
        """``sum_j sigma_j . grad H_km(r_j)`` as a combination of dipole moment keys."""
        out: dict[str, Fraction] = {}
        for (i, j, k), coef in self.poly.items():
            for axis, e in enumerate((i, j, k)):
                if e == 0:
                    continue
                lowered = [i, j, k]
                lowered[axis] -= 1
                key = "xyz"[axis] + ":" + moment_key((lowered[0], lowered[1], lowered[2]))
                out[key] = out.get(key, Fraction(0)) + e * coef
        return {k: v for k, v in out.items() if v != 0}

    def to_json(self) -> dict[str, Any]:
        """The harmonic as a row of the shipped table (exact fractions as text)."""
        return {
            "label": self.label,
            "weight": fraction_text(self.weight),
            "poly": [[list(e), fraction_text(c)] for e, c in self.poly.items()],
            "text": self.text,
        }

    @classmethod
    def from_json(cls, degree: int, row: Mapping[str, Any]) -> SolidHarmonic:
        """The harmonic of a row of the shipped table (:meth:`to_json`)."""
        poly = {(e[0], e[1], e[2]): Fraction(c) for e, c in row["poly"]}
        return cls(degree, row["label"], Fraction(row["weight"]), poly, row["text"])


def _to_fraction(value: Any) -> Fraction:
    return Fraction(int(value.p), int(value.q))


@cache
def real_solid_harmonics(k: int) -> tuple[SolidHarmonic, ...]:
    """The 2k+1 real solid harmonics of degree k (see :class:`SolidHarmonic`).

    Read from the shipped table up to ``MAX_FIELD_DEGREE`` (the same as
    :func:`derive_real_solid_harmonics`, which the tests check exactly), derived otherwise.
    """
    table = shipped_table("harmonics")
    if table is not None and str(k) in table:
        return tuple(SolidHarmonic.from_json(k, row) for row in table[str(k)])
    return derive_real_solid_harmonics(k)


@cache
def derive_real_solid_harmonics(k: int) -> tuple[SolidHarmonic, ...]:
    """The 2k+1 real solid harmonics of degree k, derived with sympy (the source of truth of
    the shipped table)."""
    import sympy as sp

    sym = sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    g1, g2, g3 = sym["gammas"]
    S = x * x + y * y + z * z
    u = sp.Symbol("u")
    Pk = sp.legendre(k, u)
    out = []
    for m in range(k + 1):
        dP = sp.Poly(sp.diff(Pk, u, m), u)
        Q = in_z_and_s(dP, k - m, z, S)
        weight = (
            Fraction(1) if m == 0 else Fraction(2 * math.factorial(k - m), math.factorial(k + m))
        )
        re = sum(
            math.comb(m, j) * x ** (m - j) * y**j * (-1) ** (j // 2) for j in range(0, m + 1, 2)
        )
        im = sum(
            math.comb(m, j) * x ** (m - j) * y**j * (-1) ** ((j - 1) // 2)
            for j in range(1, m + 1, 2)
        )
        parts = [("c", re)] + ([("s", im)] if m > 0 else [])
        for tag, part in parts:
            expr = sp.expand(part * Q)
            poly = {e: _to_fraction(c) for e, c in sp.Poly(expr, x, y, z).terms() if c != 0}
            text = str(sp.factor(expr.subs({x: g1, y: g2, z: g3}, simultaneous=True)))
            out.append(SolidHarmonic(k, f"{k},{m}{tag}", weight, poly, text))
    return tuple(out)


@cache
def _sphere_projector(kmax: int) -> tuple[list[tuple[int, int, int]], list[list[Fraction]]]:
    """Reduced monomials up to degree kmax and the matrix taking their coefficients to the
    coefficients in the harmonic basis ``H_km(gamma)``, k <= kmax (square, exact inverse)."""
    monos = [(a, b, t) for t in (0, 1) for a in range(kmax + 1) for b in range(kmax + 1 - a - t)]
    monos = [m for m in monos if sum(m) <= kmax]
    harmonics = [h for k in range(kmax + 1) for h in real_solid_harmonics(k)]
    index = {m: i for i, m in enumerate(monos)}
    basis = [[Fraction(0)] * len(harmonics) for _ in monos]
    for j, h in enumerate(harmonics):
        for mono, coef in sphere_reduce(h.poly).items():
            if coef != 0:
                basis[index[mono]][j] += coef
    projector = inverse_exact(basis)
    if projector is None:  # pragma: no cover - the harmonics are a basis on the sphere
        raise AssertionError("harmonic basis is singular")
    return monos, projector


def project_on_harmonics(poly: Mapping[tuple[int, int, int], Any], kmax: int) -> dict[str, Any]:
    """Coefficients of a polynomial on the sphere in the harmonics up to degree kmax.

    Keys are harmonic labels (``"2,2c"``); coefficients keep the input's type (Fraction or
    sympy expressions, which are expanded).
    """
    import sympy as sp

    monos, projector = _sphere_projector(kmax)
    reduced = sphere_reduce(poly)
    labels = [h.label for k in range(kmax + 1) for h in real_solid_harmonics(k)]
    symbolic = any(isinstance(v, sp.Basic) for v in reduced.values())
    extra = [m for m, v in reduced.items() if m not in set(monos) and v != 0]
    if extra:  # pragma: no cover - callers pass kmax >= the polynomial's degree
        raise AssertionError(f"polynomial of degree > {kmax}")
    out: dict[str, Any] = {}
    for i, label in enumerate(labels):
        total: Any = 0
        for j, mono in enumerate(monos):
            coef = reduced.get(mono, 0)
            if coef == 0 or projector[i][j] == 0:
                continue
            w = projector[i][j]
            total += (sp.Rational(w.numerator, w.denominator) if symbolic else w) * coef
        if symbolic:
            total = sp.expand(total)
        if total != 0:
            out[label] = total
    return out


def gamma_poly(expr: Any) -> dict[tuple[int, int, int], Any]:
    """A sympy polynomial in gamma as ``{(a, b, e): coefficient}``."""
    import sympy as sp

    g = sympy_symbols()["gammas"]
    return {e: c for e, c in sp.Poly(sp.expand(expr), *g).terms()}


@dataclass(frozen=True)
class ParamPoly:
    """A polynomial in the theorem's parameters (C, c, d, n, K, kappa), exact, fast to evaluate."""

    terms: tuple[tuple[tuple[int, ...], Fraction], ...]
    text: str

    @classmethod
    def from_sympy(cls, expr: Any) -> ParamPoly:
        import sympy as sp

        params = sympy_symbols()["params"]
        poly = sp.Poly(sp.expand(expr), *params)
        terms = tuple((e, _to_fraction(c)) for e, c in poly.terms() if c != 0)
        return cls(terms, str(sp.factor(expr)))

    def to_json(self) -> dict[str, Any]:
        """The polynomial as an entry of a shipped table (exact fractions as text)."""
        return {"terms": [[list(e), fraction_text(c)] for e, c in self.terms], "text": self.text}

    @classmethod
    def from_json(cls, entry: Mapping[str, Any]) -> ParamPoly:
        """The polynomial of a shipped table's entry (:meth:`to_json`)."""
        return cls(tuple((tuple(e), Fraction(c)) for e, c in entry["terms"]), entry["text"])

    def __call__(self, values: Sequence[Fraction]) -> Fraction:
        total = Fraction(0)
        for exps, coef in self.terms:
            term = coef
            for v, e in zip(values, exps, strict=True):
                if e:
                    term *= v**e
            total += term
        return total


def cartesian_split(expr: Any) -> dict[str, dict[int, dict[tuple[int, int, int], Any]]]:
    """Split a polynomial in (x, y, z, gamma, f_k) that is linear in the f_k into
    ``{moment key: {k: gamma polynomial}}``: replaces x^i y^j z^l by the moment I_key."""
    import sympy as sp

    sym = sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    gens = (x, y, z, *sym["gammas"], *sym["fs"])
    out: dict[str, dict[int, dict[tuple[int, int, int], Any]]] = {}
    for exps, coef in sp.Poly(sp.expand(expr), *gens).terms():
        key = moment_key(exps[:3])
        f_exps = exps[6:]
        if sum(f_exps) != 1:  # pragma: no cover - the expressions are linear in the field
            raise AssertionError("expression not linear in the field coefficients")
        k = f_exps.index(1) + 1
        g = exps[3:6]
        bucket = out.setdefault(key, {}).setdefault(k, {})
        bucket[g] = bucket.get(g, 0) + _to_fraction(coef)
    return out
