"""The shipped tables of the derivation's pure, rate-free pieces (read without sympy).

The real solid harmonics, the theorem's V on the sphere and the charges' mu equations per
magnetic degree depend on nothing but the degree: they are derived once with sympy (the
source of truth, :mod:`~chargedesign.moment_conditions.tables`) and shipped as JSON in
``chargedesign/data/conditions/`` (``make tables`` regenerates them; the tests re-derive
them and compare the text exactly). Reading them instead of deriving them keeps sympy out
of a float derivation's start-up (about 2 s of CPU: its import and the harmonics).
"""

from __future__ import annotations

from fractions import Fraction
from functools import cache
from typing import Any

from chargedesign.shipped_data import ShippedData

#: the format tag every shipped table carries
TABLE_FORMAT = "chargedesign.conditions-table/1"
#: the shipped tables, by name (``chargedesign/data/conditions/<name>.json``)
TABLE_NAMES = ("harmonics", "v_projection", "mu_system")


def fraction_text(value: Fraction) -> str:
    """An exact rational as the text ``Fraction`` reads back (``"3/10"``, ``"-2"``)."""
    return str(value)


@cache
def table_file(name: str) -> ShippedData:
    """The shipped file of the table ``name``."""
    return ShippedData(
        f"data/conditions/{name}.json",
        TABLE_FORMAT,
        f"chargedesign.moment_conditions {name}, derived with sympy; regenerate with "
        "`make tables`, never by hand",
    )


def shipped_table(name: str) -> dict[str, Any] | None:
    """The entries of the shipped table ``name``; None when it is not shipped, or stale
    (the callers then derive with sympy, as when the table is regenerated)."""
    entries: dict[str, Any] | None = table_file(name).entries()
    return entries
