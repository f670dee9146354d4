"""The realisability map's terms as shipped: derived once with sympy, read without it.

Each term of the model's V and mu that :func:`chargedesign.physical.realism.realisability_map`
lists depends on no body: its expression, its degree in gamma and its coefficients (a
polynomial in C, c, d and gamma). They are derived with sympy, the source of truth
(:func:`chargedesign.physical.realism.derived_map_terms`), and shipped as JSON in
``chargedesign/data/realism/map_terms.json`` (``make tables`` regenerates it; the tests
re-derive it and compare the text exactly). Reading it keeps sympy out of every command
that writes a realism budget (about 1.2 s of CPU: the import and the derivation).

A term's values on the map's orientations are computed here as the sympy route computed
them (``lambdify`` of the coefficients with the body's c and d substituted), to the last
bit: sympy's float arithmetic on c and d (correctly rounded, as IEEE doubles), the printed
coefficients' 15 significant digits (rounded half up, as mpmath prints them), and the printed
expression's order of operations. The tests check the two routes agree exactly.
"""

from __future__ import annotations

import math
from decimal import ROUND_HALF_UP, Decimal
from fractions import Fraction
from typing import Any

import numpy as np

from chargedesign.shipped_data import ShippedData

#: the format tag the shipped map carries
MAP_FORMAT = "chargedesign.realisability-map-terms/1"
#: the significant digits sympy prints a float of 53 bits with (``prec_to_dps(53)``)
PRINTED_DIGITS = 15


#: the shipped file of the map's terms
MAP_FILE = ShippedData(
    "data/realism/map_terms.json",
    MAP_FORMAT,
    "chargedesign.physical.realism map terms, derived with sympy; regenerate with "
    "`make tables`, never by hand",
)


def shipped_map() -> dict[str, Any]:
    """The entries of the shipped map: per term key, ``expression``, ``degree`` and
    ``components`` (see :func:`component_values`; None for a singular term)."""
    entries: dict[str, Any] | None = MAP_FILE.entries()
    if entries is None:
        raise RuntimeError(f"{MAP_FILE.path()}: missing or stale (regenerate it: make tables)")
    return entries


def printed_float(value: float) -> float:
    """A float as sympy prints it, read back: 15 significant digits, rounded half away from
    zero (mpmath's ``to_str`` truncates to 18 digits, then rounds on the 16th)."""
    if value == 0.0 or not math.isfinite(value):
        return value
    exact = Decimal(value)
    unit = Decimal(1).scaleb(exact.adjusted() - (PRINTED_DIGITS - 1))
    return float(exact.quantize(unit, rounding=ROUND_HALF_UP))


def _coefficient(contributions: list[list[Any]], c: float, d: float) -> float | None:
    """One monomial's coefficient with c and d substituted, as sympy makes it and lambdify
    prints it; None when it vanishes (sympy drops the term)."""
    total: float | Fraction | None = None
    for text, c_power, d_power in contributions:
        rational = Fraction(text)
        if c_power == 0 and d_power == 0:
            term: float | Fraction = rational
        else:
            # Rational * c**i * d**j: each a correctly rounded operation on 53 bits
            term = float(rational)
            if c_power:
                term = float(term * float(Fraction(c) ** c_power))
            if d_power:
                term = float(term * float(Fraction(d) ** d_power))
        if total is None:
            total = term
        elif isinstance(total, Fraction) and isinstance(term, Fraction):
            total = total + term
        else:
            total = float(float(total) + float(term))
    if total is None or total == 0:
        return None
    if isinstance(total, Fraction):
        # an exact coefficient is printed as p/q (or an integer) and divided in Python
        return total.numerator / total.denominator
    return printed_float(total)


def component_values(
    monomials: list[dict[str, Any]], C: float, c: float, d: float, gammas: np.ndarray
) -> np.ndarray | float:
    """One component of a map term's coefficient on the orientations ``gammas`` (shape (n,
    3), unit vectors), with the body's C (kg m^2), c and d.

    ``monomials``, in the printed order (lex in C, gamma1..3, descending): each has
    ``powers`` (exponents of C, gamma1, gamma2, gamma3) and ``terms`` (``[rational text, power
    of c, power of d]``). Evaluated left to right as the printed expression is: each term
    ``coefficient * C`` times each gamma power in turn, the terms summed in order. Returns
    the values, shape (n,), or 0.0 when every term vanishes.
    """
    total: np.ndarray | float | None = None
    for monomial in monomials:
        coefficient = _coefficient(monomial["terms"], c, d)
        if coefficient is None:
            continue
        c_power, *gamma_powers = monomial["powers"]
        value: Any = coefficient * C**c_power if c_power != 1 else coefficient * C
        for g, power in zip(gammas.T, gamma_powers, strict=True):
            if power == 1:
                value = value * g
            elif power:
                value = value * g**power
        total = value if total is None else total + value
    return 0.0 if total is None else total
