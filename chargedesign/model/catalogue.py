"""The catalogue of the paper's integrable cases, each a case file certified exactly.

The entries live in ``chargedesign/data/cases/catalogue.toml``: each names a case file of
that folder (``[case]`` tables, :mod:`chargedesign.model.case_file`), with optional parameter
overrides (the theorem's limits are its own file with parameters set to zero), a name and a
source. :func:`certify_catalogue` runs :func:`chargedesign.model.case_file.certify_case` on
each (what ``chargedesign catalogue`` prints).
"""

from __future__ import annotations

import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from importlib import resources
from typing import Any

from chargedesign.model.case_file import CaseCertificate, certify_case
from chargedesign.readers import loads_toml
from chargedesign.results import Result
from chargedesign.scene.case_file import Case, case_from_table
from chargedesign.validation import check_keys

#: the keys of one catalogue entry
ENTRY_KEYS = ("file", "name", "source", "parameters")


def _data_text(name: str) -> str:
    return resources.files("chargedesign").joinpath("data", "cases", name).read_text("utf-8")


def catalogue_entries() -> list[dict[str, Any]]:
    """The entries of ``data/cases/catalogue.toml`` (file, and optional name, source,
    parameters)."""
    data = loads_toml(_data_text("catalogue.toml"), "data/cases/catalogue.toml")
    entries = data.get("entry", [])
    for i, entry in enumerate(entries):
        check_keys(entry, ENTRY_KEYS, f"catalogue.entry[{i}]")
    return list(entries)


def entry_table(entry: Mapping[str, Any]) -> dict[str, Any]:
    """The ``[case]`` table of an entry: its file's, with the entry's overrides applied."""
    name = entry["file"]
    table = dict(loads_toml(_data_text(name), f"data/cases/{name}")["case"])
    parameters = dict(table.get("parameters", {}))
    for key, value in entry.get("parameters", {}).items():
        if key not in parameters:
            raise ValueError(f"catalogue: {name} has no parameter {key!r} to override")
        parameters[key] = value
    table["parameters"] = parameters
    for key in ("name", "source"):
        if key in entry:
            table[key] = entry[key]
    return table


def catalogue_cases() -> list[Case]:
    """Every case of the catalogue, validated."""
    return [case_from_table(entry_table(e), f"case {e['file']}") for e in catalogue_entries()]


def catalogue_case(name: str) -> Case:
    """One case of the catalogue by its name."""
    for entry in catalogue_entries():
        table = entry_table(entry)
        if table["name"] == name:
            return case_from_table(table, f"case {entry['file']}")
    names = ", ".join(entry_table(e)["name"] for e in catalogue_entries())
    raise ValueError(f"catalogue: no case named {name!r} (the cases: {names})")


@dataclass(repr=False)
class CatalogueReport(Result):
    """The certificate of every catalogue case (``chargedesign catalogue``).

    Attributes
    ----------
    certificates : list of CaseCertificate
    seconds : float
        Wall time of the whole catalogue.
    """

    certificates: Sequence[CaseCertificate]
    seconds: float

    @property
    def holds(self) -> bool:
        """Every claim holds and every integral is independent."""
        return all(c.holds and c.independent for c in self.certificates)

    def to_dict(self) -> dict[str, Any]:
        return {
            "cases": [c.to_dict()["case"] for c in self.certificates],
            "holds": self.holds,
            "seconds": self.seconds,
        }

    def _summary(self) -> dict[str, Any]:
        return {
            "cases": len(self.certificates),
            "certified": sum(c.holds and c.independent for c in self.certificates),
            "holds": self.holds,
            "seconds": self.seconds,
        }

    def _text(self) -> str:
        width = max((len(c.name) for c in self.certificates), default=4)
        lines = [
            "Catalogue of the paper's cases: exact certificates (rational arithmetic)",
            "",
            f"  {'case':<{width}}  {'level':<8} {'holds':<6} {'indep.':<7} {'all par.':<9} "
            f"{'seconds':<8} source",
        ]
        for c in self.certificates:
            level = "general" if c.level == "general" else f"I3 = {c.level}"
            for_all = {True: "yes", False: "NO", None: "-"}[c.holds_for_all_parameters]
            lines.append(
                f"  {c.name:<{width}}  {level:<8} {'yes' if c.holds else 'NO':<6} "
                f"{'yes' if c.independent else 'NO':<7} {for_all:<9} {c.seconds:<8.3f} {c.source}"
            )
        certified = sum(c.holds and c.independent for c in self.certificates)
        lines += [
            "",
            f"  {certified}/{len(self.certificates)} certified in {self.seconds:.2f} s "
            "(holds at the files' values, independent; 'all par.': for all values of the "
            "non-zero parameters)",
        ]
        return "\n".join(lines)


def certify_catalogue() -> CatalogueReport:
    """Certify every case of the catalogue."""
    start = time.perf_counter()
    certificates = [certify_case(case) for case in catalogue_cases()]
    return CatalogueReport(certificates, time.perf_counter() - start)


__all__ = [
    "CatalogueReport",
    "catalogue_case",
    "catalogue_cases",
    "catalogue_entries",
    "certify_catalogue",
    "entry_table",
]
