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
SymPy is imported lazily (only the derivation needs it), so importing the data types is cheap.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from fractions import Fraction
from functools import cache, lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np

from chargedesign.errors import InfeasibleError
from chargedesign.moments import moment_key, moment_keys, monomial_matrix
from chargedesign.params import Parameters
from chargedesign.validation import as_array, as_finite_float, as_points, as_weights, input_error

if TYPE_CHECKING:  # pragma: no cover
    from chargedesign.model.audit import AuditEntry
    from chargedesign.scene import Scene

SOURCES = ("charges", "dipoles", "masses")
#: what a design may claim to realise (CONTRACT.md)
REALISABLE = ("mu", "V", "inertia")
FIELD_KINDS = ("magnetic", "electric", "gravity")
#: the field each source feels (its potential energy) in V
SOURCE_FIELD = {"charges": "electric", "dipoles": "magnetic", "masses": "gravity"}
#: highest accepted degree of any field (the exact derivation grows like degree^3)
MAX_FIELD_DEGREE = 6
#: V (lambda = rho = 0) is a quartic in gamma: spherical-harmonic degrees 0..4
V_DEGREE = 4
#: magnetic field derived when a scene gives none: a1 = 1 T and f2 = 1 T/m (a2 = 0.5 T/m)
DEFAULT_MAGNETIC = (1.0, 1.0)
#: strength of an electric term that is needed but not forced, when nothing else fixes the
#: size of the charges (V/m^k); otherwise the strength follows the body (DEFAULT_LENGTH_RULE)
DEFAULT_ELECTRIC_STRENGTH = 1.0
#: body length (m) assumed for the default strengths when none is given (``length=None``)
DEFAULT_LENGTH = 1.0
#: a default strength makes the required moments this many times smaller than the natural
#: size of the elements (measured trade-off in docs/conditions.md: no extra charge, and a
#: cancellation of at most ~300 in the degree-k moments)
DEFAULT_STRENGTH_HEADROOM = 100
#: how a default strength e_k is chosen (docs/conditions.md, "Default field strengths")
DEFAULT_LENGTH_RULE = (
    "e_k = 10^round(log10(100 |T_k| / (Q L^k))): the required degree-k moments (Racah norm "
    "|T_k| / e_k) are then about 1/100 of the natural size Q L^k of charges of total size "
    "Q = max |M_key| / L^order over the moments the other conditions fix"
)
#: a given field strength within this relative distance of a forced one is read as equal
#: (float inputs only: 0.7 and -0.28 are not exactly related in binary)
FIELD_MATCH_RTOL = 1e-9
#: which source realises each degree of V, in order of preference (others contribute nothing)
DEGREE_PREFERENCE = {
    1: ("charges", "dipoles", "masses"),
    2: ("dipoles", "charges", "masses"),
}
DEFAULT_PREFERENCE = ("charges", "dipoles", "masses")
#: the theorem's parameter symbols used by the derivation (names of chargedesign.model.case)
_PARAM_NAMES = ("C", "c", "d", "n", "K", "kappa")


# ============================================================================ data types
@dataclass(frozen=True)
class LinearCondition:
    """One linear condition ``sum_k coefficients[k] * moment[k] = value`` on one source.

    Moment keys: sorted axis letters for charges and masses (``"xxz"``), and
    ``"<component>:<letters>"`` for dipoles (``"z:x"`` is ``sum sigma_z x``).
    ``provenance`` says which term of mu, V or the inertia the condition realises.
    ``exact_value`` (and ``exact_coefficients``) hold the exact rational values as strings
    (``"-7/10"``) when the conditions were derived with ``exact=True``; empty otherwise.
    """

    source: str
    coefficients: dict[str, float]
    value: float
    provenance: str
    exact_value: str = ""
    exact_coefficients: dict[str, str] = field(default_factory=dict)

    @property
    def single_key(self) -> str | None:
        """The moment key when the condition fixes a single moment, else None."""
        return next(iter(self.coefficients)) if len(self.coefficients) == 1 else None

    @property
    def fixed_value(self) -> float:
        """``value / coefficient`` for a single-moment condition (the moment's value)."""
        key = self.single_key
        if key is None:
            raise ValueError("fixed_value: the condition involves several moments")
        return self.value / self.coefficients[key]

    def to_dict(self) -> dict[str, Any]:
        out: dict[str, Any] = {
            "source": self.source,
            "coefficients": dict(self.coefficients),
            "value": self.value,
            "provenance": self.provenance,
        }
        if self.exact_value:
            out["exact_value"] = self.exact_value
            out["exact_coefficients"] = dict(self.exact_coefficients)
        return out


@dataclass
class LinearConditions:
    """All conditions of a target, with the fields they assume.

    Attributes
    ----------
    conditions : list of LinearCondition
    fields : dict[str, tuple[float, ...]]
        Legendre coefficients of the magnetic, electric and gravity fields the conditions
        assume (given by the user, or derived: see ``notes``).
    notes : list of str
        The choices made (which source realises which degree of V, forced and default
        field strengths, what the design stage must still enforce).
    realise : tuple of str
        What the conditions realise (subset of ``mu``, ``V``, ``inertia``).
    field_origin : dict[str, str]
        ``"given"`` or ``"derived"`` per field kind.
    length : float or None
        The body length scale (m) the default field strengths were chosen for; None when no
        strength was chosen by default (nothing depends on the body's size).
    length_assumed : bool
        True when no length was given and :data:`DEFAULT_LENGTH` (1 m) was used for a default
        strength (:func:`chargedesign.design.design_body` then re-derives the conditions for
        the candidates' size, :meth:`for_length`).
    default_strengths : dict[str, float]
        The field coefficients chosen by default, e.g. ``{"electric e4": 1e-06}`` (V/m^4).
    """

    conditions: list[LinearCondition]
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    notes: list[str] = field(default_factory=list)
    realise: tuple[str, ...] = ()
    field_origin: dict[str, str] = field(default_factory=dict)
    length: float | None = None
    length_assumed: bool = False
    default_strengths: dict[str, float] = field(default_factory=dict)
    _inputs: tuple[Any, ...] | None = field(default=None, repr=False, compare=False)

    def for_length(self, length: float) -> LinearConditions:
        """The same derivation with the default field strengths chosen for ``length`` (m).

        Returns ``self`` when no strength depends on the body length (nothing was chosen by
        default) or when the conditions were not made by :func:`derive_conditions`.
        """
        if not self.default_strengths or self._inputs is None:
            return self
        params, fields, realise, exact = self._inputs
        return derive_conditions(params, fields, realise, exact=exact, length=length)

    def for_source(self, source: str) -> list[LinearCondition]:
        return [c for c in self.conditions if c.source == source]

    def system(self, source: str, positions: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The linear system ``A w = b`` for weights at candidate ``positions`` (n, 3).

        For charges and masses ``w`` has shape (n,); for dipoles ``w`` is the flattened
        (n, 3) moment array (row-major: sigma_1x, sigma_1y, sigma_1z, sigma_2x, ...).
        Returns ``A`` of shape (m, n) or (m, 3n) and ``b`` of shape (m,).
        """
        if source not in SOURCES:
            raise input_error("source", "one of " + ", ".join(SOURCES), source)
        rows = self.for_source(source)
        pts = np.asarray(positions, dtype=np.float64)
        n = len(pts)
        width = 3 * n if source == "dipoles" else n
        A = np.zeros((len(rows), width))
        b = np.array([row.value for row in rows], dtype=np.float64)
        for a, row in enumerate(rows):
            for key, coef in row.coefficients.items():
                if source == "dipoles":
                    comp, letters = key.split(":")
                    col = "xyz".index(comp)
                    A[a, col::3] += coef * monomial_matrix(pts, [letters])[0]
                else:
                    A[a] += coef * monomial_matrix(pts, [key])[0]
        return A, b

    def fixed_moments(self, source: str) -> dict[str, float]:
        """Moments fixed individually by a single-moment condition: ``{key: value}``."""
        out: dict[str, float] = {}
        for row in self.for_source(source):
            key = row.single_key
            if key is not None:
                out[key] = row.fixed_value
        return out

    def combinations(self) -> list[LinearCondition]:
        """Conditions that involve several moments (e.g. degree-4 harmonic moments)."""
        return [c for c in self.conditions if c.single_key is None]

    def to_dict(self) -> dict[str, Any]:
        """The JSON form of ``chargedesign conditions --json`` (contract keys first)."""
        out: dict[str, Any] = {s: self.fixed_moments(s) for s in SOURCES}
        out["combinations"] = [c.to_dict() for c in self.combinations()]
        out["fields"] = {
            kind: {"legendre": list(self.fields.get(kind, ())), "origin": origin}
            for kind, origin in self.field_origin.items()
        }
        out["realise"] = list(self.realise)
        if self.default_strengths:
            out["default_strengths"] = {
                "length_m": self.length,
                "length_assumed": self.length_assumed,
                "rule": DEFAULT_LENGTH_RULE,
                "values": dict(self.default_strengths),
            }
        out["notes"] = list(self.notes)
        out["conditions"] = [c.to_dict() for c in self.conditions]
        return out


# ===================================================================== exact algebra
Poly3 = dict[tuple[int, int, int], Any]


def _multinomial_signed(s: int) -> list[tuple[int, int, int]]:
    """Terms of ``(1 - g1^2 - g2^2)^s``: (coefficient, power of g1^2, power of g2^2)."""
    out = []
    for j in range(s + 1):
        for k in range(s - j + 1):
            coef = math.factorial(s) // (
                math.factorial(s - j - k) * math.factorial(j) * math.factorial(k)
            )
            out.append(((-1) ** (j + k) * coef, j, k))
    return out


def _sphere_reduce(poly: Mapping[tuple[int, int, int], Any]) -> Poly3:
    """Reduce a polynomial in gamma on ``|gamma| = 1``: gamma3 appears at most linearly.

    ``gamma3^(2s+t) -> gamma3^t (1 - gamma1^2 - gamma2^2)^s``. The monomials
    ``gamma1^a gamma2^b gamma3^t`` (t in {0, 1}) are linearly independent on the sphere, so
    two polynomials agree on it iff their reduced forms agree coefficient by coefficient.
    Coefficients may be Fractions or sympy expressions.
    """
    out: Poly3 = {}
    for (a, b, e), coef in poly.items():
        s, t = divmod(e, 2)
        for mult, j, k in _multinomial_signed(s):
            mono = (a + 2 * j, b + 2 * k, t)
            out[mono] = out.get(mono, 0) + mult * coef
    return out


def _solve_dense(matrix: list[list[Fraction]], rhs: list[Fraction]) -> list[Fraction] | None:
    """One solution of ``matrix x = rhs`` (free unknowns 0), or None if inconsistent."""
    rows = [[*r, b] for r, b in zip(matrix, rhs, strict=True)]
    ncols = len(matrix[0]) if matrix else 0
    pivots: list[int] = []
    r = 0
    for col in range(ncols):
        piv = next((i for i in range(r, len(rows)) if rows[i][col] != 0), None)
        if piv is None:
            continue
        rows[r], rows[piv] = rows[piv], rows[r]
        inv = 1 / rows[r][col]
        rows[r] = [v * inv for v in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][col] != 0:
                factor = rows[i][col]
                rows[i] = [a - factor * b for a, b in zip(rows[i], rows[r], strict=True)]
        pivots.append(col)
        r += 1
    if any(row[-1] != 0 for row in rows[r:]):
        return None
    x = [Fraction(0)] * ncols
    for i, col in enumerate(pivots):
        x[col] = rows[i][-1]
    return x


def _nullspace(matrix: list[list[Fraction]], ncols: int) -> list[list[Fraction]]:
    """A basis of ``{x : matrix x = 0}`` (exact), as a list of vectors of length ``ncols``."""
    rows = [list(r) for r in matrix]
    pivots: list[int] = []
    r = 0
    for col in range(ncols):
        piv = next((i for i in range(r, len(rows)) if rows[i][col] != 0), None)
        if piv is None:
            continue
        rows[r], rows[piv] = rows[piv], rows[r]
        inv = 1 / rows[r][col]
        rows[r] = [v * inv for v in rows[r]]
        for i in range(len(rows)):
            if i != r and rows[i][col] != 0:
                factor = rows[i][col]
                rows[i] = [a - factor * b for a, b in zip(rows[i], rows[r], strict=True)]
        pivots.append(col)
        r += 1
    basis = []
    for free in (c for c in range(ncols) if c not in pivots):
        vec = [Fraction(0)] * ncols
        vec[free] = Fraction(1)
        for i, col in enumerate(pivots):
            vec[col] = -rows[i][free]
        basis.append(vec)
    return basis


def _independent_columns(matrix: list[list[Fraction]], ncols: int) -> list[int]:
    """Indices of columns of ``matrix`` (M rows) that form a basis of its column space."""
    reduced: dict[int, list[Fraction]] = {}  # pivot row -> reduced basis column
    chosen = []
    for j in range(ncols):
        col = [row[j] for row in matrix]
        for p, vec in reduced.items():
            if col[p] != 0:
                factor = col[p] / vec[p]
                col = [a - factor * b for a, b in zip(col, vec, strict=True)]
        pivot = next((i for i, v in enumerate(col) if v != 0), None)
        if pivot is None:
            continue
        reduced[pivot] = col
        chosen.append(j)
        if len(chosen) == len(matrix):
            break
    return chosen


def _key_rank(key: str) -> tuple[int, int, int, int]:
    """Pivot order: lower orders first, then the order of :func:`moment_keys`."""
    comp = -1
    letters = key
    if ":" in key:
        c, letters = key.split(":")
        comp = "xyz".index(c)
    order = len(letters)
    return (order, moment_keys(order).index(letters), comp, 0)


@dataclass
class _Row:
    coeffs: dict[str, Fraction]
    rhs: Fraction
    provenance: str


class _System:
    """The exact linear conditions of one source, kept in reduced row echelon form.

    ``pivots`` maps a pivot key to its reduced row (pivot coefficient 1, no other pivot key)
    with the exact combination of input equations that produced it. ``display`` keeps the
    independent conditions in the form they are reported.
    """

    def __init__(self) -> None:
        self.pivots: dict[str, tuple[dict[str, Fraction], Fraction, dict[int, Fraction]]] = {}
        self.labels: list[str] = []
        self.display: list[_Row] = []

    def copy(self) -> _System:
        new = _System()
        new.pivots = {k: (dict(r), b, dict(c)) for k, (r, b, c) in self.pivots.items()}
        new.labels = list(self.labels)
        new.display = list(self.display)
        return new

    def _reduce(
        self, coeffs: Mapping[str, Fraction], rhs: Fraction, combo: dict[int, Fraction]
    ) -> tuple[dict[str, Fraction], Fraction, dict[int, Fraction]]:
        row = {k: v for k, v in coeffs.items() if v != 0}
        for p in [k for k in row if k in self.pivots]:
            a = row.get(p, Fraction(0))
            if a == 0:
                continue
            prow, prhs, pcombo = self.pivots[p]
            for k, v in prow.items():
                nv = row.get(k, Fraction(0)) - a * v
                if nv == 0:
                    row.pop(k, None)
                else:
                    row[k] = nv
            rhs -= a * prhs
            for i, v in pcombo.items():
                nv = combo.get(i, Fraction(0)) - a * v
                if nv == 0:
                    combo.pop(i, None)
                else:
                    combo[i] = nv
        return row, rhs, combo

    def add(
        self, coeffs: Mapping[str, Fraction], rhs: Fraction, label: str
    ) -> tuple[str, dict[int, Fraction]]:
        """Add one equation. Returns ``("new" | "implied" | "inconsistent", combination)``.

        The combination maps input-equation indices (into ``labels``) to their weights in
        the reduced row (for ``"inconsistent"``: in the contradiction ``0 = nonzero``).
        """
        index = len(self.labels)
        self.labels.append(label)
        row, rhs, combo = self._reduce(coeffs, rhs, {index: Fraction(1)})
        if not row:
            return ("implied" if rhs == 0 else "inconsistent", combo)
        pivot = min(row, key=_key_rank)
        inv = 1 / row[pivot]
        row = {k: v * inv for k, v in row.items()}
        rhs *= inv
        combo = {i: v * inv for i, v in combo.items()}
        for p, (prow, prhs, pcombo) in list(self.pivots.items()):
            a = prow.get(pivot, Fraction(0))
            if a == 0:
                continue
            for k, v in row.items():
                nv = prow.get(k, Fraction(0)) - a * v
                if nv == 0:
                    prow.pop(k, None)
                else:
                    prow[k] = nv
            for i, v in combo.items():
                nv = pcombo.get(i, Fraction(0)) - a * v
                if nv == 0:
                    pcombo.pop(i, None)
                else:
                    pcombo[i] = nv
            self.pivots[p] = (prow, prhs - a * rhs, pcombo)
        self.pivots[pivot] = (row, rhs, combo)
        return ("new", combo)

    def add_display(self, coeffs: Mapping[str, Fraction], rhs: Fraction, provenance: str) -> None:
        """Add a condition reported as given (skipped when already implied)."""
        status, combo = self.add(coeffs, rhs, provenance)
        if status == "inconsistent":
            raise InfeasibleError(
                f"{provenance}: contradicts {self._describe(combo, skip_last=True)}"
            )
        if status == "new":
            self.display.append(_Row({k: v for k, v in coeffs.items() if v != 0}, rhs, provenance))

    def _describe(self, combo: Mapping[int, Fraction], skip_last: bool = False) -> str:
        last = len(self.labels) - 1
        used = [self.labels[i] for i in sorted(combo) if not (skip_last and i == last)]
        return "; ".join(used[:4]) + (f"; and {len(used) - 4} more" if len(used) > 4 else "")

    def affine_image(
        self, functionals: Sequence[Mapping[str, Fraction]]
    ) -> tuple[list[Fraction], list[list[Fraction]]]:
        """The attainable values of linear functionals ``L_m . moments`` under the system.

        Returns ``(W0, G)``: every solution gives ``W = W0 + G t`` (shapes (M,) and (M, F)).
        """
        # only free keys in the functionals, or in the rows of pivots they use, matter
        keys: set[str] = set()
        for L in functionals:
            for k in L:
                keys.update(self.pivots[k][0] if k in self.pivots else (k,))
        free = sorted((k for k in keys if k not in self.pivots), key=_key_rank)
        W0 = []
        G = []
        for L in functionals:
            W0.append(
                sum((a * self.pivots[k][1] for k, a in L.items() if k in self.pivots), Fraction(0))
            )
            row = []
            for f in free:
                value = L.get(f, Fraction(0))
                for k, a in L.items():
                    if k in self.pivots:
                        value -= a * self.pivots[k][0].get(f, Fraction(0))
                row.append(value)
            G.append(row)
        # keep a basis of the directions W can move in (at most len(functionals) columns)
        basis = _independent_columns(G, len(free))
        return W0, [[row[j] for j in basis] for row in G]


# ================================================================ symbolic derivation
@lru_cache(maxsize=1)
def _sympy_symbols() -> dict[str, Any]:
    import sympy as sp

    from chargedesign.model import case

    x, y, z = sp.symbols("x y z", real=True)
    return {
        "x": x,
        "y": y,
        "z": z,
        "gammas": (case.g1, case.g2, case.g3),
        "params": tuple(getattr(case, name) for name in _PARAM_NAMES),
        "fs": sp.symbols(f"f1:{MAX_FIELD_DEGREE + 1}", real=True),
    }


def _field_symbols(degree: int) -> tuple[Any, ...]:
    """Legendre coefficients ``f_1 .. f_degree`` of a field as sympy symbols."""
    return tuple(_sympy_symbols()["fs"][:degree])


def _zonal_solid(k: int, Z: Any, S: Any) -> Any:
    """``R^k P_k(Z/R)`` as a polynomial in Z and S = R^2 (sympy)."""
    import sympy as sp

    u = sp.Symbol("u")
    poly = sp.Poly(sp.legendre(k, u), u)
    return sp.expand(sum(co * Z**e * S ** ((k - e) // 2) for (e,), co in poly.terms()))


def _flux_factor(k: int, Z: Any, S: Any) -> Any:
    """``R^(k-1) P_k'(Z/R)`` as a polynomial in Z and S (sympy); see :func:`_flux_moments`."""
    import sympy as sp

    u = sp.Symbol("u")
    poly = sp.Poly(sp.diff(sp.legendre(k, u), u), u)
    return sp.expand(sum(co * Z**e * S ** ((k - 1 - e) // 2) for (e,), co in poly.terms()))


@dataclass(frozen=True)
class _Harmonic:
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


def _to_fraction(value: Any) -> Fraction:
    return Fraction(int(value.p), int(value.q))


@cache
def _harmonics(k: int) -> tuple[_Harmonic, ...]:
    """The 2k+1 real solid harmonics of degree k (see :class:`_Harmonic`)."""
    import sympy as sp

    sym = _sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    g1, g2, g3 = sym["gammas"]
    S = x * x + y * y + z * z
    u = sp.Symbol("u")
    Pk = sp.legendre(k, u)
    out = []
    for m in range(k + 1):
        dP = sp.Poly(sp.diff(Pk, u, m), u)
        Q = sum(co * z**e * S ** ((k - m - e) // 2) for (e,), co in dP.terms())
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
            out.append(_Harmonic(k, f"{k},{m}{tag}", weight, poly, text))
    return tuple(out)


@cache
def _sphere_projector(kmax: int) -> tuple[list[tuple[int, int, int]], list[list[Fraction]]]:
    """Reduced monomials up to degree kmax and the matrix taking their coefficients to the
    coefficients in the harmonic basis ``H_km(gamma)``, k <= kmax (square, exact inverse)."""
    monos = [(a, b, t) for t in (0, 1) for a in range(kmax + 1) for b in range(kmax + 1 - a - t)]
    monos = [m for m in monos if sum(m) <= kmax]
    harmonics = [h for k in range(kmax + 1) for h in _harmonics(k)]
    index = {m: i for i, m in enumerate(monos)}
    basis = [[Fraction(0)] * len(harmonics) for _ in monos]
    for j, h in enumerate(harmonics):
        for mono, coef in _sphere_reduce(h.poly).items():
            if coef != 0:
                basis[index[mono]][j] += coef
    # invert column by column: projector = basis^-1
    size = len(monos)
    inverse_cols = []
    for i in range(size):
        e = [Fraction(int(i == j)) for j in range(size)]
        col = _solve_dense(basis, e)
        if col is None:  # pragma: no cover - the harmonics are a basis on the sphere
            raise AssertionError("harmonic basis is singular")
        inverse_cols.append(col)
    projector = [[inverse_cols[j][i] for j in range(size)] for i in range(size)]
    return monos, projector


def _project(poly: Mapping[tuple[int, int, int], Any], kmax: int) -> dict[str, Any]:
    """Coefficients of a polynomial on the sphere in the harmonics up to degree kmax.

    Keys are harmonic labels (``"2,2c"``); coefficients keep the input's type (Fraction or
    sympy expressions, which are expanded).
    """
    import sympy as sp

    monos, projector = _sphere_projector(kmax)
    reduced = _sphere_reduce(poly)
    labels = [h.label for k in range(kmax + 1) for h in _harmonics(k)]
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


def _gamma_poly(expr: Any) -> dict[tuple[int, int, int], Any]:
    """A sympy polynomial in gamma as ``{(a, b, e): coefficient}``."""
    import sympy as sp

    g = _sympy_symbols()["gammas"]
    return {e: c for e, c in sp.Poly(sp.expand(expr), *g).terms()}


@dataclass(frozen=True)
class _ParamPoly:
    """A polynomial in the theorem's parameters (C, c, d, n, K, kappa), exact, fast to evaluate."""

    terms: tuple[tuple[tuple[int, ...], Fraction], ...]
    text: str

    @classmethod
    def from_sympy(cls, expr: Any) -> _ParamPoly:
        import sympy as sp

        params = _sympy_symbols()["params"]
        poly = sp.Poly(sp.expand(expr), *params)
        terms = tuple((e, _to_fraction(c)) for e, c in poly.terms() if c != 0)
        return cls(terms, str(sp.factor(expr)))

    def __call__(self, values: Sequence[Fraction]) -> Fraction:
        total = Fraction(0)
        for exps, coef in self.terms:
            term = coef
            for v, e in zip(values, exps, strict=True):
                if e:
                    term *= v**e
            total += term
        return total


@dataclass(frozen=True)
class _MuEquation:
    """``sum_key (sum_k f_k coefficients[key][k]) I_key = rhs(params)`` for one harmonic of one
    component of mu, from coefficient matching on the sphere."""

    component: int
    harmonic: str
    coefficients: dict[str, dict[int, Fraction]]
    rhs: _ParamPoly
    label: str


def _cartesian_split(expr: Any) -> dict[str, dict[int, dict[tuple[int, int, int], Any]]]:
    """Split a polynomial in (x, y, z, gamma, f_k) that is linear in the f_k into
    ``{moment key: {k: gamma polynomial}}``: replaces x^i y^j z^l by the moment I_key."""
    import sympy as sp

    sym = _sympy_symbols()
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


@cache
def _mu_system(degree: int) -> tuple[_MuEquation, ...]:
    """The coefficient-matching equations of the charges' mu for a magnetic field of
    ``degree`` (symbolic field coefficients f_1..f_degree; cached per degree).

    ``mu = -sum q (r . B) r`` with ``B = -grad Phi``, ``Phi = sum_k f_k R^k P_k(r . gamma / R)``
    in body axes; the moments ``I_key = sum q x^i y^j z^l`` are the unknowns. Both sides are
    reduced on ``|gamma| = 1`` and written in the harmonic basis (an invertible change of
    basis of the reduced monomials, which separates the equations by moment order).
    """
    import sympy as sp

    from chargedesign.model.case import symbolic_case

    sym = _sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    g1, g2, g3 = sym["gammas"]
    fs = _field_symbols(degree)
    Z = x * g1 + y * g2 + z * g3
    S = x * x + y * y + z * z
    phi = sum(f * _zonal_solid(k, Z, S) for k, f in enumerate(fs, start=1))
    B = [-sp.diff(phi, v) for v in (x, y, z)]
    r_dot_B = x * B[0] + y * B[1] + z * B[2]
    kmax = max(degree, 2)
    target = symbolic_case().mu
    equations = []
    for a, ra in enumerate((x, y, z)):
        physical = _cartesian_split(-r_dot_B * ra)
        rows: dict[str, dict[str, dict[int, Fraction]]] = {}
        for key, per_k in physical.items():
            for k, gpoly in per_k.items():
                for label, coef in _project(gpoly, kmax).items():
                    rows.setdefault(label, {}).setdefault(key, {})[k] = coef
        theorem = _project(_gamma_poly(target[a]), kmax)
        harmonics = {h.label: h for kk in range(kmax + 1) for h in _harmonics(kk)}
        for label in [h.label for kk in range(kmax + 1) for h in _harmonics(kk)]:
            if label not in rows and label not in theorem:
                continue
            rhs = _ParamPoly.from_sympy(theorem.get(label, sp.Integer(0)))
            h = harmonics[label]
            text = (
                f"mu_{a + 1}: coefficient of the degree-{h.degree} harmonic {h.text} "
                f"(theorem: {rhs.text})"
            )
            equations.append(_MuEquation(a, label, rows.get(label, {}), rhs, text))
    return tuple(equations)


@lru_cache(maxsize=1)
def _v_projection() -> dict[str, _ParamPoly]:
    """The theorem's V (lambda = rho = 0) on the sphere in the harmonic basis, degrees 0..4."""
    import sympy as sp

    from chargedesign.model.case import lam, rho, symbolic_case

    V = symbolic_case().V.subs({lam: 0, rho: 0})
    V = sp.expand(sp.cancel(V))
    return {
        label: _ParamPoly.from_sympy(coef)
        for label, coef in _project(_gamma_poly(V), V_DEGREE).items()
    }


# ================================================================== input handling
def _validate_realise(realise: Any, name: str) -> tuple[str, ...]:
    if isinstance(realise, str) or not isinstance(realise, Iterable):
        raise input_error(name, "a list of " + ", ".join(REALISABLE), realise)
    items = list(realise)
    for item in items:
        if item not in REALISABLE:
            raise input_error(name, "items among " + ", ".join(REALISABLE), item)
    if len(set(items)) != len(items):
        raise input_error(name, "no repeated items", items)
    return tuple(k for k in REALISABLE if k in items)


def _validate_fields(fields: Any) -> dict[str, tuple[float, ...]]:
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


def _exact(value: float, exact: bool) -> Fraction:
    """The exact rational of a float: as printed (``0.3 -> 3/10``) or its binary value."""
    return Fraction(repr(value)) if exact else Fraction(value)


def _fmt(value: Fraction) -> str:
    return str(value)


def _num(value: Fraction) -> str:
    """Short decimal text of an exact value (for messages and notes)."""
    return f"{float(value):.12g}"


_FIELD_NAMES = {"magnetic": "f", "electric": "e", "gravity": "g"}


def _coefficient_name(kind: str, k: int) -> str:
    if kind == "magnetic" and k == 1:
        return "a1 (legendre[0])"
    if kind == "magnetic" and k == 2:
        return "a2 (legendre[1] = 2 a2)"
    return f"{_FIELD_NAMES[kind]}{k} (legendre[{k - 1}])"


# ====================================================================== the engine
@dataclass
class _Context:
    params: Parameters
    P: list[Fraction]  # C, c, d, n, K, kappa
    exact: bool
    fields: dict[str, list[Fraction]]  # exact legendre coefficients in use
    derivable: set[str]  # field kinds the engine may still choose (electric)
    systems: dict[str, _System]
    notes: list[str]
    length: Fraction = Fraction(1)  # body length scale (m) for default strengths
    length_given: bool = False
    defaults: dict[str, Fraction] = field(default_factory=dict)  # strengths chosen by default

    def coefficient(self, kind: str, k: int) -> Fraction:
        coeffs = self.fields.get(kind, [])
        return coeffs[k - 1] if k <= len(coeffs) else Fraction(0)

    def set_coefficient(self, kind: str, k: int, value: Fraction) -> None:
        coeffs = self.fields.setdefault(kind, [])
        while len(coeffs) < k:
            coeffs.append(Fraction(0))
        coeffs[k - 1] = value


#: what "contributes nothing to degree 1" means for each source
_DEGREE_ONE_MEANING = {
    "masses": " (centre of mass at O: uniform gravity adds nothing to V)",
    "dipoles": " (total dipole moment zero: the uniform field a1 adds nothing to V)",
    "charges": " (electric dipole moment zero: the uniform field e1 adds nothing to V)",
}


def _functionals(source: str, k: int) -> list[tuple[_Harmonic, dict[str, Fraction]]]:
    if source == "dipoles":
        return [(h, h.dipole_moments()) for h in _harmonics(k)]
    return [(h, h.moments()) for h in _harmonics(k)]


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
    t = _solve_dense(normal, rhs)
    if t is None:  # pragma: no cover - normal equations are always consistent
        raise AssertionError("inconsistent normal equations")
    return [
        W0[m] + sum((G[m][j] * t[j] for j in range(nfree)), Fraction(0)) for m in range(len(W0))
    ]


def _degree_description(k: int, P: Sequence[Fraction]) -> str:
    """Which theorem parameters make up the degree-k part of V (for messages)."""
    proj = _v_projection()
    zonal: set[str] = set()
    sectoral: set[str] = set()
    for h in _harmonics(k):
        if h.label not in proj:
            continue
        for exps, coef in proj[h.label].terms:
            term = coef
            for v, e in zip(P, exps, strict=True):
                term *= v**e
            if term == 0:
                continue
            names = {_PARAM_NAMES[i] for i, e in enumerate(exps) if e and i >= 3}
            (zonal if h.label.endswith(",0c") else sectoral).update(names)
    parts = []
    if zonal:
        parts.append("zonal part from " + ", ".join(sorted(zonal)))
    if sectoral:
        parts.append("sectoral part from " + ", ".join(sorted(sectoral)))
    return "; ".join(parts) if parts else "no target terms"


def _realise_degree(ctx: _Context, k: int) -> None:
    """Assign the degree-k part of V to one source; make the others contribute their least."""
    proj = _v_projection()
    harmonics = _harmonics(k)
    target = [proj[h.label](ctx.P) if h.label in proj else Fraction(0) for h in harmonics]
    weights = [h.weight for h in harmonics]
    present = list(ctx.systems)
    carriers = [
        s
        for s in present
        if ctx.coefficient(SOURCE_FIELD[s], k) != 0 or SOURCE_FIELD[s] in ctx.derivable
    ]
    preference = DEGREE_PREFERENCE.get(k, DEFAULT_PREFERENCE)
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
                f"{s}: fields.{kind} has no degree-{k} term ({_coefficient_name(kind, k)} = 0)"
            )
    description = _degree_description(k, ctx.P)
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
                    f"V degree {k}: {s} in fields.{kind} {_coefficient_name(kind, k)} "
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


def _proportionality(fixed: list[Fraction], wanted: list[Fraction]) -> Fraction | None:
    """The scalar f with ``wanted == f * fixed`` exactly (fixed not all zero), else None."""
    norm = sum((v * v for v in fixed), Fraction(0))
    f = sum((a * b for a, b in zip(fixed, wanted, strict=True)), Fraction(0)) / norm
    return f if all(w == f * v for w, v in zip(wanted, fixed, strict=True)) else None


def _designate(
    ctx: _Context,
    trial: dict[str, _System],
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
    harmonics = _harmonics(k)
    funcs = _functionals(source, k)
    scaled = [r / h.weight for r, h in zip(remainder, harmonics, strict=True)]  # = f * W
    W0, G = trial[source].affine_image([L for _, L in funcs])
    # rows z with z G = 0: the combinations of W fixed by the source's other conditions
    nfree = len(G[0]) if G else 0
    transposed = [[G[m][j] for m in range(len(W0))] for j in range(nfree)]
    Z = _nullspace(transposed, len(W0))
    fixed = [sum((z[m] * W0[m] for m in range(len(W0))), Fraction(0)) for z in Z]
    wanted = [sum((z[m] * scaled[m] for m in range(len(W0))), Fraction(0)) for z in Z]
    name = _coefficient_name(kind, k)
    fixer = "mu" if source == "charges" else "the inertia" if source == "masses" else "V"
    need: Fraction | None = None
    if any(fixed):
        need = _proportionality(fixed, wanted)
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
            ctx.defaults[f"{kind} {_FIELD_NAMES[kind]}{k}"] = f
        else:
            f, why = Fraction(0), f"not needed (no degree-{k} part for the {source})"
        ctx.set_coefficient(kind, k, f)
        if f != 0 or k <= V_DEGREE:
            notes.append(f"fields.{kind} {name} = {_num(f)} derived: {why}")
    else:
        f = ctx.coefficient(kind, k)
        if need is not None and need != f:
            close = abs(need - f) <= FIELD_MATCH_RTOL * abs(need)
            if ctx.exact or not close:
                return False, (
                    f"fields.{kind} {name} = {_num(f)} does not fit: {fixer} fixes the "
                    f"{source}' degree-{k} moments, which require {name} = {_num(need)}"
                )
            notes.append(
                f"fields.{kind} {name} = {_num(f)} given matches the required {_num(need)} "
                f"to rounding; the conditions use the required value"
            )
            f = need
    if f == 0:
        if any(scaled):
            return False, f"{source}: fields.{kind} {name} = 0"
        return True, ""
    proj = _v_projection()
    for (h, L), value in zip(funcs, scaled, strict=True):
        theorem = proj[h.label].text if h.label in proj else "0"
        trial[source].add_display(
            L,
            value / f,
            f"V degree {k}: {source} in fields.{kind} {name} realise the theorem's "
            f"coefficient {theorem} of the harmonic {h.text}",
        )
    if any(scaled):
        notes.append(f"V degree {k}: realised by {source} in fields.{kind} ({name} = {_num(f)})")
    return True, ""


def _log10(value: Fraction) -> float:
    """log10 of a positive exact value (no overflow for huge or tiny values)."""
    return math.log10(value.numerator) - math.log10(value.denominator)


def _default_strength(
    ctx: _Context, system: _System, source: str, k: int, scaled: Sequence[Fraction]
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
    harmonics = _harmonics(k)
    target_sq = sum((h.weight * v * v for h, v in zip(harmonics, scaled, strict=True)), Fraction(0))
    natural = Fraction(0)
    for key, (row, rhs, _) in system.pivots.items():
        if len(row) != 1 or rhs == 0:
            continue
        order = len(key.split(":")[-1])
        natural = max(natural, abs(rhs / row[key]) / L**order)
    length_text = (
        f"L = {_num(L)} m" if ctx.length_given else f"L = {_num(L)} m assumed (no length given)"
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
        f"natural size Q L^{k} of {source} of total size Q ~ {float(natural):.3g} (fixed by "
        "the other conditions): no extra weight, no significant cancellation"
    )


def _charges_for_mu(ctx: _Context) -> None:
    magnetic = ctx.fields.get("magnetic", [])
    n, K = ctx.P[3], ctx.P[4]
    f1 = ctx.coefficient("magnetic", 1)
    f2 = ctx.coefficient("magnetic", 2)
    if n != 0 and f1 == 0:
        raise InfeasibleError(
            f"fields.magnetic: a1 = 0 while n = {ctx.params.n:g} != 0: the n terms of mu need "
            "charges in a uniform magnetic field (a1 != 0)"
        )
    if K != 0 and f2 == 0:
        raise InfeasibleError(
            f"fields.magnetic: a2 = 0 while K = {ctx.params.K:g} != 0: the K terms of mu need "
            "charges in a magnetic quadrupole (a2 != 0)"
        )
    degree = max(len(magnetic), 1)
    system = ctx.systems["charges"]
    for eq in _mu_system(degree):
        coeffs = {
            key: sum(
                (magnetic[k - 1] * c for k, c in per_k.items() if k <= len(magnetic)), Fraction(0)
            )
            for key, per_k in eq.coefficients.items()
        }
        rhs = eq.rhs(ctx.P)
        status, combo = system.add(coeffs, rhs, eq.label)
        if status == "inconsistent":
            raise InfeasibleError(
                "mu cannot be realised by charges in this magnetic field: "
                + system._describe(combo)
            )
    for pivot in sorted(system.pivots, key=_key_rank):
        row, rhs, combo = system.pivots[pivot]
        system.display.append(_Row(dict(row), rhs, system._describe(combo)))
    ctx.notes.append(
        f"charges: mu matched on |gamma| = 1 for a magnetic field of degree {degree}: "
        f"{len(system.pivots)} independent conditions on the moments of orders 2..{degree + 1}"
    )
    ctx.notes.append(
        "charges: their canonical angular momentum about Z, sum q psi (natural axisymmetric "
        "gauge), then equals the theorem's l . gamma on |gamma| = 1, constant 2 n C included "
        "(l_dot_gamma_residual)"
    )


def _masses_for_inertia(ctx: _Context) -> None:
    C = ctx.P[0]
    system = ctx.systems["masses"]
    rows = [
        ("xx", C / 2, "inertia: C = M_xx + M_yy and A = B = 2C give M_xx = C/2"),
        ("yy", C / 2, "inertia: C = M_xx + M_yy and A = B = 2C give M_yy = C/2"),
        ("zz", 3 * C / 2, "inertia: A = M_yy + M_zz = 2C gives M_zz = 3C/2"),
        ("xy", Fraction(0), "inertia: product of inertia xy is zero (principal axes)"),
        ("xz", Fraction(0), "inertia: product of inertia xz is zero (principal axes)"),
        ("yz", Fraction(0), "inertia: product of inertia yz is zero (principal axes)"),
    ]
    for key, value, why in rows:
        system.add_display({key: Fraction(1)}, value, why)
    ctx.notes.append(
        "masses: nonnegative values are the design stage's job (not a linear condition)"
    )


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
        and ``length_assumed`` is set (:func:`chargedesign.design.design_body` then
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
        raise input_error("params", "a chargedesign.params.Parameters", params)
    goals = _validate_realise(realise, "realise")
    given = _validate_fields(fields)
    if length is not None:
        length = as_finite_float(length, "length", positive=True)
    if params.singular and ({"mu", "V"} & set(goals)):
        which = ", ".join(
            f"{name} = {value:g}"
            for name, value in (("lambda", params.lam), ("rho", params.rho))
            if value != 0
        )
        raise InfeasibleError(
            f"parameters {which}: singular on gamma3 = 0: no finite charge distribution realises "
            "them; the model and the reduced simulation still accept them"
        )
    P = [_exact(getattr(params, name), exact) for name in _PARAM_NAMES]
    fields_exact = {kind: [_exact(v, exact) for v in coeffs] for kind, coeffs in given.items()}
    ctx = _Context(
        params=params,
        P=P,
        exact=exact,
        fields=fields_exact,
        derivable=set(),
        systems={},
        notes=[],
        length=_exact(DEFAULT_LENGTH if length is None else length, exact),
        length_given=length is not None,
    )
    origin = {kind: "given" for kind in given}
    if "magnetic" not in given:
        needs_f1 = "mu" in goals and P[3] != 0
        proj = _v_projection()
        needs_f2 = ("mu" in goals and P[4] != 0) or (
            "V" in goals and any(proj[h.label](P) != 0 for h in _harmonics(2) if h.label in proj)
        )
        derived = [
            Fraction(DEFAULT_MAGNETIC[0]) if needs_f1 else Fraction(0),
            Fraction(DEFAULT_MAGNETIC[1]) if needs_f2 else Fraction(0),
        ]
        while derived and derived[-1] == 0:
            derived.pop()
        ctx.fields["magnetic"] = derived
        origin["magnetic"] = "derived"
        if derived:
            ctx.notes.append(
                "fields.magnetic derived (none given): legendre "
                f"{[float(v) for v in derived]} (a1 = 1 T, a2 = 0.5 T/m where needed)"
            )
    if "electric" not in given:
        ctx.fields["electric"] = []
        origin["electric"] = "derived"
        if "V" in goals:
            ctx.derivable.add("electric")
    if "gravity" not in given:
        ctx.fields["gravity"] = []
        origin["gravity"] = "derived"
    if "mu" in goals or "V" in goals:
        ctx.systems["charges"] = _System()
    if "V" in goals:
        ctx.systems["dipoles"] = _System()
    if "inertia" in goals:
        ctx.systems["masses"] = _System()
    if "mu" in goals:
        _charges_for_mu(ctx)
    if "inertia" in goals:
        _masses_for_inertia(ctx)
    if "V" in goals:
        kmax = max(
            V_DEGREE,
            len(ctx.fields["magnetic"]),
            len(ctx.fields["electric"]),
            len(ctx.fields["gravity"]) if "masses" in ctx.systems else 0,
        )
        for k in range(1, kmax + 1):
            _realise_degree(ctx, k)
        if "masses" not in ctx.systems and any(ctx.fields["gravity"]):
            ctx.notes.append("fields.gravity acts on no designed element (inertia not realised)")
    elif given.get("electric"):
        ctx.notes.append("fields.electric is not used: V is not realised")
    if "V" in goals and "mu" not in goals:
        ctx.notes.append("charges: mu is not realised; their moments serve V only")
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
                    exact_value=_fmt(row.rhs) if exact else "",
                    exact_coefficients={k: _fmt(v) for k, v in row.coeffs.items()} if exact else {},
                )
            )
    out_fields: dict[str, tuple[float, ...]] = {}
    for kind in FIELD_KINDS:
        coeffs = list(ctx.fields.get(kind, []))
        while coeffs and coeffs[-1] == 0:
            coeffs.pop()
        out_fields[kind] = tuple(float(v) for v in coeffs)
        if exact and origin[kind] == "derived" and coeffs:
            ctx.notes.append(f"fields.{kind} exact legendre: [{', '.join(map(_fmt, coeffs))}]")
    return LinearConditions(
        conditions=conditions,
        fields=out_fields,
        notes=ctx.notes,
        realise=goals,
        field_origin={kind: origin[kind] for kind in FIELD_KINDS},
        length=float(ctx.length) if ctx.defaults else None,
        length_assumed=bool(ctx.defaults) and length is None,
        default_strengths={name: float(v) for name, v in ctx.defaults.items()},
        _inputs=(params, fields, goals, exact),
    )


def realise_from_scene(scene: Scene) -> tuple[str, ...]:
    """The ``[design] realise`` list of a scene (default: all of mu, V, inertia), validated."""
    value = scene.table("design").get("realise", list(REALISABLE))
    if not isinstance(value, list):
        raise input_error("design.realise", "a list of " + ", ".join(REALISABLE), value)
    return _validate_realise(value, "design.realise")


def scene_length(scene: Scene) -> tuple[float | None, str]:
    """The body length scale of a scene (m): the largest distance of a candidate from O.

    The candidates of the scene's ``[body]`` table are built as the design stage builds them
    (:func:`chargedesign.candidates.candidates_from_table`), so the conditions command and
    the design choose the same default strengths. A scene with no usable ``[body]`` gives
    ``(None, reason)``: the conditions do not validate the body (the design does).
    """
    from pathlib import Path

    from chargedesign.candidates import candidates_from_table
    from chargedesign.errors import ChargeDesignError

    table = scene.table("body")
    if not table:
        return None, "the scene has no [body]"
    base_dir = Path(scene.source).parent if scene.source not in ("<default>", "<dict>") else None
    try:
        size = candidates_from_table(table, base_dir=base_dir).geometry.size
    except ChargeDesignError as exc:
        return None, f"[body] not usable ({exc})"
    if not size > 0:
        return None, "the candidates all sit at O"
    return size, ""


def conditions_for_scene(scene: Scene, *, exact: bool = False) -> LinearConditions:
    """:func:`derive_conditions` for a scene's parameters, fields and ``[design] realise``.

    Default field strengths are chosen for the size of the scene's body
    (:func:`scene_length`), as :func:`chargedesign.design.design_from_scene` does.
    """
    from chargedesign.scene import Scene as _Scene

    if not isinstance(scene, _Scene):
        raise input_error("scene", "a chargedesign.scene.Scene", scene)
    realise = realise_from_scene(scene)
    length, why = scene_length(scene)
    result = derive_conditions(scene.parameters, scene.fields, realise, exact=exact, length=length)
    if result.length_assumed and why:
        result.notes.append(f"body length {DEFAULT_LENGTH:g} m assumed: {why}")
    return result


# ============================================================ symbolic results & audit
def moment_symbol(key: str) -> Any:
    """The charge moment ``I_key`` as a real sympy symbol (``I_xyz``)."""
    import sympy as sp

    return sp.Symbol(f"I_{key}", real=True)


def symbolic_mu_solution(degree: int = 2) -> dict[str, Any]:
    """The charges' moments that realise mu, for symbolic parameters and field coefficients.

    Solves the coefficient-matching equations of :func:`_mu_system` with ``sympy.linsolve``
    for generic (non-zero) ``f_1 .. f_degree`` (symbols ``f1, f2, ...``), degree >= 2 (a
    field of degree 1 cannot give the K terms). Moments left free appear as themselves.

    Returns
    -------
    dict[str, sympy.Expr]
        ``{moment key: expression}`` for every moment of orders 2..degree+1.
    """

    if (
        isinstance(degree, bool)
        or not isinstance(degree, int)
        or not 2 <= degree <= MAX_FIELD_DEGREE
    ):
        # degree 1 cannot give the K terms of mu (they need a magnetic quadrupole)
        raise input_error("degree", f"an integer in 2..{MAX_FIELD_DEGREE}", degree)
    return dict(_symbolic_mu_solution(degree))


@cache
def _symbolic_mu_solution(degree: int) -> tuple[tuple[str, Any], ...]:
    import sympy as sp

    fs = _field_symbols(degree)
    params = _sympy_symbols()["params"]
    keys = [k for order in range(2, degree + 2) for k in moment_keys(order)]
    symbols = [moment_symbol(k) for k in keys]
    equations = []
    for eq in _mu_system(degree):
        lhs = sum(
            sum(fs[k - 1] * sp.Rational(c.numerator, c.denominator) for k, c in per_k.items())
            * moment_symbol(key)
            for key, per_k in eq.coefficients.items()
        )
        rhs = sum(
            sp.Rational(c.numerator, c.denominator)
            * sp.Mul(*[p**e for p, e in zip(params, exps, strict=True)])
            for exps, c in eq.rhs.terms
        )
        equations.append(sp.expand(lhs - rhs))
    solutions = sp.linsolve(equations, symbols)
    if not solutions:  # pragma: no cover - mu is always realisable for generic fields
        raise InfeasibleError("mu has no symbolic solution")
    (solution,) = list(solutions)
    return tuple((key, sp.factor(value)) for key, value in zip(keys, solution, strict=True))


def audit_p6() -> AuditEntry:
    """Compare the printed moment conditions (p6) with the derived ones, exactly.

    The derived conditions come from :func:`symbolic_mu_solution` for the paper's field
    ``Phi = a1 Z + a2 (3 Z^2 - R^2)`` (legendre ``[a1, 2 a2]``, generic a1, a2 != 0); the
    printed (p6) are :func:`chargedesign.model.printed.printed_p6`, solved for the same 16
    moments. ``difference`` lists ``printed - derived`` for each moment that differs.
    """
    import sympy as sp

    from chargedesign.model.audit import AuditEntry
    from chargedesign.model.printed import a1, a2, printed_p6

    f1, f2 = _field_symbols(2)
    derived = {
        key: sp.factor(value.subs({f1: a1, f2: 2 * a2}, simultaneous=True))
        for key, value in symbolic_mu_solution(2).items()
    }
    keys = list(derived)
    symbols = [moment_symbol(k) for k in keys]
    printed_solutions = sp.linsolve(list(printed_p6()), symbols)
    if not printed_solutions:
        return AuditEntry("p6", False, "printed (p6) is inconsistent", "")
    (printed_tuple,) = list(printed_solutions)
    differences = []
    undetermined = []
    for key, printed_value in zip(keys, printed_tuple, strict=True):
        if printed_value.free_symbols & set(symbols):
            undetermined.append(key)
        diff = sp.factor(sp.simplify(printed_value - derived[key]))
        if diff != 0:
            differences.append(f"I_{key}: {diff}")
    agrees = not differences
    note = (
        "printed (p6) solved for the 16 second and third charge moments, minus the moments "
        "derived by matching mu = -sum q (r . B) r with the theorem's mu on |gamma| = 1 "
        "(Phi = a1 Z + a2 (3 Z^2 - R^2), generic a1, a2 != 0)"
    )
    if undetermined:
        note += "; moments (p6) leaves free: " + ", ".join(undetermined)
    return AuditEntry("p6", agrees, "0" if agrees else "; ".join(differences), note)


@cache
def _flux_moments(degree: int) -> Any:
    """``sum_j q_j psi(r_j; gamma)`` in charge moments, symbolic field of ``degree``.

    ``psi = rho A_phi = -(R^2 - Z^2) sum_k f_k R^(k-1) P_k'(Z/R) / (k + 1)`` (natural
    axisymmetric gauge; ``B = curl(psi / rho e_phi) = -grad Phi``), ``Z = r . gamma``.
    """
    import sympy as sp

    sym = _sympy_symbols()
    x, y, z = sym["x"], sym["y"], sym["z"]
    g1, g2, g3 = sym["gammas"]
    fs = _field_symbols(degree)
    Z = x * g1 + y * g2 + z * g3
    S = x * x + y * y + z * z
    g = sum(f * _flux_factor(k, Z, S) / (k + 1) for k, f in enumerate(fs, start=1))
    psi = sp.expand(-(S - Z**2) * g)
    total = 0
    for key, per_k in _cartesian_split(psi).items():
        for k, gpoly in per_k.items():
            for (a, b, e), c in gpoly.items():
                total += (
                    fs[k - 1]
                    * sp.Rational(c.numerator, c.denominator)
                    * g1**a
                    * g2**b
                    * g3**e
                    * moment_symbol(key)
                )
    return total


def l_dot_gamma_residual(degree: int = 2) -> Any:
    """The I3-level check: physical ``l . gamma`` minus the theorem's, reduced on the sphere.

    The charges' canonical angular momentum about the space axis Z in the natural axisymmetric
    gauge is ``sum_j q_j psi(r_j; gamma)`` (``psi = rho A_phi``, the flux function). With the
    moments of any charge set that satisfies the mu conditions
    (:func:`symbolic_mu_solution`, generic field of ``degree``), this is compared with the
    theorem's ``l . gamma = C (2 n g1^2 + 2 n g2^2 + n g3^2 + K f g3)``.

    Returns
    -------
    sympy.Expr
        The reduced difference: ``0`` means the charges realise l . gamma exactly,
        including its constant ``2 n C`` on the sphere (so ``(omega I + l) . gamma`` is the
        charges' conserved canonical angular momentum with no offset).
    """
    import sympy as sp

    from chargedesign.model.case import GAMMA, symbolic_case

    solution = symbolic_mu_solution(degree)
    subs = {moment_symbol(k): v for k, v in solution.items()}
    physical = sp.expand(_flux_moments(degree).xreplace(subs))
    theorem = symbolic_case().l.dot(GAMMA)
    reduced = _sphere_reduce(_gamma_poly(sp.expand(physical - theorem)))
    g1, g2, g3 = _sympy_symbols()["gammas"]
    total = sum(sp.factor(sp.cancel(c)) * g1**a * g2**b * g3**e for (a, b, e), c in reduced.items())
    return sp.simplify(total)


def physical_l_dot_gamma(
    positions: Any, charges: Any, magnetic: Sequence[float], gammas: Any
) -> np.ndarray:
    """The charges' canonical angular momentum about Z, ``sum_j q_j psi(r_j; gamma)``.

    Parameters
    ----------
    positions : array_like, shape (n, 3)
        Charge positions in body axes, m.
    charges : array_like, shape (n,)
        Charges in C.
    magnetic : sequence of float
        Legendre coefficients of the magnetic scalar potential (T m / m^k).
    gammas : array_like, shape (m, 3)
        Unit vectors of the space Z axis in body axes.

    Returns
    -------
    ndarray, shape (m,)
        ``l . gamma`` in kg m^2 / s (compare with the theorem's ``l . gamma``).
    """
    from chargedesign.fields import AxisymmetricField

    pts = as_points(positions, "positions")
    q = as_weights(charges, "charges", len(pts))
    psi = AxisymmetricField(tuple(magnetic)).flux_function_body(pts, gammas)
    return np.asarray(psi @ q)


__all__ = [
    "DEFAULT_ELECTRIC_STRENGTH",
    "DEFAULT_LENGTH",
    "DEFAULT_LENGTH_RULE",
    "DEFAULT_MAGNETIC",
    "MAX_FIELD_DEGREE",
    "REALISABLE",
    "SOURCES",
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
