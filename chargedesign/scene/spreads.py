"""Manufacturing error sizes as written (``20um``, ``0.02 mm``, ``1e-5``, ``1%``), read at the
boundary into a :class:`Spread` (the tolerance command's options and the scene's
``[tolerance]`` errors); :mod:`chargedesign.tolerancing` draws from them.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass
from typing import Any

from chargedesign.formatting import PLAIN, fmt
from chargedesign.validation import as_finite_float, input_error

LENGTH_UNITS = {"m": 1.0, "mm": 1e-3, "um": 1e-6, "µm": 1e-6, "nm": 1e-9}


@dataclass(frozen=True)
class Spread:
    """One error size: ``value`` absolute (SI: m, C, A m^2, kg) or relative (a fraction)."""

    value: float
    relative: bool

    def __str__(self) -> str:
        if self.relative:
            return f"{fmt(100 * self.value, PLAIN)}%"
        return f"{fmt(self.value, PLAIN)}"

    def scaled(self, factor: float) -> Spread:
        return Spread(self.value * factor, self.relative)


_SPREAD = re.compile(r"^\s*([0-9.eE+-]+)\s*(%|[a-zA-Zµ]*)\s*$")


def parse_spread(text: Any, name: str, length: bool = False) -> Spread:
    """Parse ``20um``, ``0.02 mm``, ``1e-5`` (SI), ``1%`` (relative).

    Parameters
    ----------
    text : str or float
        The error: a number with an optional unit, or a percentage. Lengths (``length=True``)
        accept ``m``, ``mm``, ``um`` (or ``µm``), ``nm``; values take SI numbers only. A
        relative position error is a fraction of the element's distance from O.
    name : str
        The option's name for the error message.
    """
    if isinstance(text, (int, float)) and not isinstance(text, bool):
        value = as_finite_float(text, name)
        if value < 0.0:
            raise input_error(name, "a non-negative error", text)
        return Spread(value, False)
    match = _SPREAD.match(str(text)) if isinstance(text, str) else None
    units = "m, mm, um, nm or %" if length else "%"
    if match is None:
        raise input_error(name, f"a number with an optional unit ({units}), e.g. 20um or 1%", text)
    try:
        number = float(match.group(1))
    except ValueError:
        raise input_error(name, "a number with an optional unit, e.g. 20um or 1%", text) from None
    unit = match.group(2)
    if not math.isfinite(number) or number < 0:
        raise input_error(name, "a non-negative error", text)
    if unit == "%":
        return Spread(number / 100.0, True)
    if unit == "":
        return Spread(number, False)
    if length and unit in LENGTH_UNITS:
        return Spread(number * LENGTH_UNITS[unit], False)
    raise input_error(name, f"a unit among {units}", unit)


#: no error at all (the default of each of an error model's kinds)
NO_SPREAD = Spread(0.0, False)
