"""The shipped tables derived with sympy: their text, and the text the package ships.

``make tables`` writes :func:`table_text` for every name of
:data:`~chargedesign.moment_conditions.table_data.TABLE_NAMES` into
``chargedesign/data/conditions/``; the tests check that the shipped text is the derived
text, character for character (as for the JSON Schemas).
"""

from __future__ import annotations

from typing import Any

from chargedesign.moment_conditions.constants import MAX_FIELD_DEGREE
from chargedesign.moment_conditions.harmonics import derive_real_solid_harmonics
from chargedesign.moment_conditions.mu import derive_mu_system
from chargedesign.moment_conditions.potential import derive_v_projection
from chargedesign.moment_conditions.table_data import TABLE_NAMES, table_file


def derived_entries(name: str) -> dict[str, Any]:
    """The entries of the table ``name``, derived with sympy (JSON-ready)."""
    if name == "harmonics":
        return {
            str(k): [h.to_json() for h in derive_real_solid_harmonics(k)]
            for k in range(MAX_FIELD_DEGREE + 1)
        }
    if name == "v_projection":
        return {label: poly.to_json() for label, poly in derive_v_projection().items()}
    if name == "mu_system":
        return {
            str(d): [eq.to_json() for eq in derive_mu_system(d)]
            for d in range(1, MAX_FIELD_DEGREE + 1)
        }
    raise ValueError(f"table: expected one of {', '.join(TABLE_NAMES)}, got {name!r}")


def table_text(name: str) -> str:
    """The text of the table ``name`` as shipped (derived with sympy now)."""
    return table_file(name).text(derived_entries(name))


def shipped_table_text(name: str) -> str:
    """The text of the table ``name`` the package ships ('' when it ships none)."""
    return table_file(name).shipped_text()


def write_tables() -> list[str]:
    """Write every table's derived text into the package's data folder; their names."""
    for name in TABLE_NAMES:
        table_file(name).write(derived_entries(name))
    return list(TABLE_NAMES)
