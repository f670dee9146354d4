"""One entry of the audit of the paper's printed formulas (light: no sympy), shared by
:mod:`chargedesign.model.audit` and :mod:`chargedesign.moment_conditions.audit`."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class AuditEntry:
    """One printed formula compared with its derived counterpart.

    ``difference`` is the exact difference (printed - derived), simplified on |gamma| = 1,
    written term by term as a sympy string; ``"0"`` when the two agree.
    """

    name: str
    agrees: bool
    difference: str
    note: str = ""

    def to_dict(self) -> dict[str, object]:
        return {
            "name": self.name,
            "agrees": self.agrees,
            "difference": self.difference,
            "note": self.note,
        }
