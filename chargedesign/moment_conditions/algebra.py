"""Exact rational algebra of the derivation: reduction on the sphere, elimination, echelon form.

Everything here computes with :class:`fractions.Fraction` (or sympy coefficients for
:func:`sphere_reduce`), so the conditions are exact before they are rounded to floats.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import Any

from chargedesign.errors import InfeasibleError
from chargedesign.moments import moment_keys

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


def sphere_reduce(poly: Mapping[tuple[int, int, int], Any]) -> Poly3:
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


def _row_reduce(rows: list[list[Fraction]], ncols: int) -> list[int]:
    """Gauss-Jordan elimination of ``rows`` in place over their first ``ncols`` columns.

    Pivot rows end up first, scaled to a pivot of 1, with zeros above and below each pivot
    (columns past ``ncols``, e.g. a right-hand side, are carried along). Returns the pivot
    columns in order.
    """
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
    return pivots


def solve_exact(matrix: list[list[Fraction]], rhs: list[Fraction]) -> list[Fraction] | None:
    """One solution of ``matrix x = rhs`` (free unknowns 0), or None if inconsistent."""
    rows = [[*r, b] for r, b in zip(matrix, rhs, strict=True)]
    ncols = len(matrix[0]) if matrix else 0
    pivots = _row_reduce(rows, ncols)
    if any(row[-1] != 0 for row in rows[len(pivots) :]):
        return None
    x = [Fraction(0)] * ncols
    for i, col in enumerate(pivots):
        x[col] = rows[i][-1]
    return x


def inverse_exact(matrix: list[list[Fraction]]) -> list[list[Fraction]] | None:
    """The inverse of a square matrix (exact; one Gauss-Jordan pass on ``[matrix | I]``), or
    None if it is singular."""
    size = len(matrix)
    rows = [[*row, *(Fraction(int(i == j)) for j in range(size))] for i, row in enumerate(matrix)]
    if len(_row_reduce(rows, size)) < size:
        return None
    return [row[size:] for row in rows]


def exact_nullspace(matrix: list[list[Fraction]], ncols: int) -> list[list[Fraction]]:
    """A basis of ``{x : matrix x = 0}`` (exact), as a list of vectors of length ``ncols``."""
    rows = [list(r) for r in matrix]
    pivots = _row_reduce(rows, ncols)
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


def key_rank(key: str) -> tuple[int, int, int, int]:
    """Pivot order: lower orders first, then the order of :func:`moment_keys`."""
    comp = -1
    letters = key
    if ":" in key:
        c, letters = key.split(":")
        comp = "xyz".index(c)
    order = len(letters)
    return (order, moment_keys(order).index(letters), comp, 0)


@dataclass
class ConditionRow:
    """One exact condition: sparse coefficients, right-hand side and where it came from."""

    coeffs: dict[str, Fraction]
    rhs: Fraction
    provenance: str


def _subtract_scaled(
    target: dict[Any, Fraction], source: Mapping[Any, Fraction], a: Fraction
) -> None:
    """``target -= a * source`` for sparse exact vectors, in place (zero entries removed)."""
    for k, v in source.items():
        nv = target.get(k, Fraction(0)) - a * v
        if nv == 0:
            target.pop(k, None)
        else:
            target[k] = nv


class SourceSystem:
    """The exact linear conditions of one source, kept in reduced row echelon form.

    ``pivots`` maps a pivot key to its reduced row (pivot coefficient 1, no other pivot key)
    with the exact combination of input equations that produced it. ``display`` keeps the
    independent conditions in the form they are reported.
    """

    def __init__(self) -> None:
        self.pivots: dict[str, tuple[dict[str, Fraction], Fraction, dict[int, Fraction]]] = {}
        self.labels: list[str] = []
        self.display: list[ConditionRow] = []

    def copy(self) -> SourceSystem:
        new = SourceSystem()
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
            _subtract_scaled(row, prow, a)
            rhs -= a * prhs
            _subtract_scaled(combo, pcombo, a)
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
        pivot = min(row, key=key_rank)
        inv = 1 / row[pivot]
        row = {k: v * inv for k, v in row.items()}
        rhs *= inv
        combo = {i: v * inv for i, v in combo.items()}
        for p, (prow, prhs, pcombo) in list(self.pivots.items()):
            a = prow.get(pivot, Fraction(0))
            if a == 0:
                continue
            _subtract_scaled(prow, row, a)
            _subtract_scaled(pcombo, combo, a)
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
            self.display.append(
                ConditionRow({k: v for k, v in coeffs.items() if v != 0}, rhs, provenance)
            )

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
        free = sorted((k for k in keys if k not in self.pivots), key=key_rank)
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
