"""One way to print a quantity: significant digits by kind, with its unit.

Every number the report, the command line, reprs and HTML tables print goes through
:func:`fmt`, so one kind of number reads the same everywhere::

    fmt(0.012345)                  # '0.0123'     FIGURE: a derived figure, 3 digits
    fmt(0.012345, PRECISE, "C")    # '0.01235 C'  PRECISE: a value to reuse, 4 digits
    fmt(2.5e-14, ROUGH)            # '2.5e-14'    ROUGH: a residual or ratio, 2 digits
    fmt(3.3e-16, ORDER)            # '3e-16'      ORDER: an order of magnitude, 1 digit
    fmt(0.1 + 0.2, FULL)           # '0.3'        FULL: a number to read back, 12 digits

The kinds and their digits are those the package has always printed (the text of every
command is unchanged by routing it through here). Pure: imports nothing of the package.
"""

from __future__ import annotations

import math
from typing import Any

__all__ = [
    "AGREEMENT",
    "CELL",
    "DIRECTION",
    "ERROR",
    "EXACT",
    "FIGURE",
    "FLOOR",
    "FULL",
    "KINDS",
    "ORDER",
    "ORDER_SCI",
    "PLAIN",
    "PRECISE",
    "ROUGH",
    "fmt",
    "fmt_length",
]

#: a derived figure in running text (a field, a mass, a length, a ratio): 3 significant digits
FIGURE = "figure"
#: a value a reader may reuse (element totals, rates, limits): 4 significant digits
PRECISE = "precise"
#: a residual, an error or a rough ratio: 2 significant digits
ROUGH = "rough"
#: an order of magnitude: 1 significant digit
ORDER = "order"
#: an order of magnitude in scientific notation (``1e-05``)
ORDER_SCI = "order_sci"
#: a number as given (parameters, Legendre coefficients): Python's ``g``, 6 digits
PLAIN = "plain"
#: a table cell (HTML): 6 significant digits
CELL = "cell"
#: a number a reader copies back (CSV cells, an exact value as a decimal): 12 significant digits
FULL = "full"
#: every digit (machine-readable text: CSV): the shortest form that reads back is ``repr``;
#: this is the fixed 17 digits the tables have always used
EXACT = "exact"
#: a relative error in a checker table: 4 digits, scientific
ERROR = "error"
#: an error floor beside it: 2 digits, scientific
FLOOR = "floor"
#: an agreement between two routes: 3 digits, scientific
AGREEMENT = "agreement"
#: a component of a unit direction: signed, 4 decimals
DIRECTION = "direction"

#: the format specification of each kind
KINDS: dict[str, str] = {
    FIGURE: ".3g",
    PRECISE: ".4g",
    ROUGH: ".2g",
    ORDER: ".1g",
    ORDER_SCI: ".0e",
    PLAIN: "g",
    CELL: ".6g",
    FULL: ".12g",
    EXACT: ".17g",
    ERROR: ".3e",
    FLOOR: ".1e",
    AGREEMENT: ".2e",
    DIRECTION: "+.4f",
}


def fmt(value: Any, kind: str = FIGURE, unit: str = "") -> str:
    """``value`` with the digits of its ``kind`` (:data:`KINDS`), then `` unit`` if given.

    Parameters
    ----------
    value : float or int
    kind : str
        One of :data:`KINDS` (default :data:`FIGURE`, 3 significant digits).
    unit : str
        Appended after one space (nothing when empty).
    """
    try:
        spec = KINDS[kind]
    except KeyError:
        raise ValueError(f"fmt: unknown kind {kind!r} (one of {', '.join(KINDS)})") from None
    text = format(value, spec)
    return f"{text} {unit}" if unit else text


#: length units from the largest down, with their size in m
_LENGTH_UNITS = (("m", 1.0), ("mm", 1e-3), ("µm", 1e-6), ("nm", 1e-9))


def fmt_length(x: float, kind: str = FIGURE) -> str:
    """A length in m, mm, µm or nm (the largest unit it reaches), ``any`` when infinite."""
    if not math.isfinite(x):
        return "any"
    for unit, scale in _LENGTH_UNITS:
        if abs(x) >= scale:
            return fmt(x / scale, kind, unit)
    return fmt(x, kind, "m")
