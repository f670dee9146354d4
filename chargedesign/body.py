"""A designed body: charges on carriers, magnets and ballast masses, with its target parameters and
fields; read and written as ``design.json`` (format ``chargedesign.design/1``, see CONTRACT.md).
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from chargedesign.elements import ElementSet
from chargedesign.errors import InputError
from chargedesign.files import write_json_atomic
from chargedesign.params import Parameters
from chargedesign.validation import as_array, input_error
from chargedesign.vocabulary import DESIGN_FORMAT, FIELD_KINDS, REALISABLE

__all__ = ["DESIGN_FORMAT", "FIELD_KINDS", "REALISABLE", "Design", "read_design", "write_design"]


def _legendre(value: Any, name: str) -> tuple[float, ...]:
    if isinstance(value, (list, tuple)) and len(value) == 0:
        return ()
    return tuple(float(x) for x in as_array(value, name, (None,)))


@dataclass
class Design(ElementSet):
    """An element set (:class:`~chargedesign.elements.ElementSet`: charges on carriers,
    magnets, ballast; SI units, body axes) plus what it is meant to realise.

    Attributes
    ----------
    parameters : Parameters
        The theorem's parameters the body targets.
    fields : dict[str, tuple[float, ...]]
        ``legendre`` coefficients per field kind (``magnetic``, ``electric``, ``gravity``);
        ``Phi = sum_k f_k R^k P_k(Z/R)``, f_k in the field's units per m^(k-1).
    charge_positions, charge_values, charge_radii, charge_masses, dipole_positions,
    dipole_moments, dipole_volumes, dipole_masses, mass_positions, mass_values
        The elements (keyword arguments; see :class:`~chargedesign.elements.ElementSet`).
    realises : list[str]
        Subset of ``mu``, ``V``, ``inertia`` that the design claims.
    continuous : list[ContinuousBody]
        Continuous charge or mass bodies (chargedesign.quadrature), design.json key
        ``continuous``; dicts in the design.json format are accepted and converted.
    extra : dict
        Further keys of design.json (provenance, residuals, timings, ...), kept verbatim.
    """

    parameters: Parameters
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    realises: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)
    continuous: list[Any] = field(default_factory=list)

    def __post_init__(self) -> None:
        super().__post_init__()
        for kind in self.fields:
            if kind not in FIELD_KINDS:
                raise input_error(f"fields.{kind}", "one of " + ", ".join(FIELD_KINDS), kind)
        self.fields = {k: _legendre(v, f"fields.{k}.legendre") for k, v in self.fields.items()}
        for item in self.realises:
            if item not in REALISABLE:
                raise input_error("realises", "items among " + ", ".join(REALISABLE), item)
        if not isinstance(self.continuous, (list, tuple)):
            raise input_error("continuous", "a list of bodies", self.continuous)
        from chargedesign.quadrature import ContinuousBody

        self.continuous = [
            ContinuousBody.coerce(b, f"continuous[{i}]") for i, b in enumerate(self.continuous)
        ]

    def field(self, kind: str) -> tuple[float, ...]:
        """Legendre coefficients of one field (empty tuple: no such field)."""
        return self.fields.get(kind, ())

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON mapping (plus ``extra`` keys)."""
        out: dict[str, Any] = {
            "format": DESIGN_FORMAT,
            "parameters": self.parameters.as_dict(),
            "fields": {k: {"legendre": list(v)} for k, v in self.fields.items()},
            **self.blocks(),
            "realises": list(self.realises),
        }
        if self.continuous:
            out["continuous"] = [b.to_dict() for b in self.continuous]
        for key, value in self.extra.items():
            out.setdefault(key, value)
        return out

    @classmethod
    def from_dict(cls, data: Any, where: str = "design") -> Design:
        if not isinstance(data, dict):
            raise input_error(where, "a JSON object", data)
        fmt = data.get("format", DESIGN_FORMAT)
        if fmt != DESIGN_FORMAT:
            raise input_error(f"{where}.format", repr(DESIGN_FORMAT), fmt)
        if "parameters" not in data:
            raise InputError(f"{where}: missing key 'parameters'")
        params = Parameters.from_mapping(data["parameters"], f"{where}.parameters")
        fields_in = data.get("fields") or {}
        if not isinstance(fields_in, dict):
            raise input_error(f"{where}.fields", "an object", fields_in)
        fields_out = {}
        for kind, spec in fields_in.items():
            if not isinstance(spec, dict) or "legendre" not in spec:
                raise input_error(f"{where}.fields.{kind}", "an object with key 'legendre'", spec)
            fields_out[kind] = spec["legendre"]

        known = {"format", "parameters", "fields", "charges", "masses", "dipoles", "realises"}
        known.add("continuous")
        return cls(
            parameters=params,
            fields=fields_out,
            **ElementSet.arrays_from_blocks(data, where),
            realises=list(data.get("realises", [])),
            extra={k: v for k, v in data.items() if k not in known},
            continuous=data.get("continuous") or [],
        )

    # ---- result protocol and pictures: thin methods over chargedesign.results / chargedesign.viz
    def __repr__(self) -> str:
        from chargedesign.results import compact_repr, design_summary

        return compact_repr(type(self).__name__, design_summary(self))

    def __str__(self) -> str:
        """The human report (as ``report.md`` and ``chargedesign design`` print it)."""
        from chargedesign.report import render_report

        return render_report(self)

    def _repr_html_(self) -> str:
        from chargedesign.results import design_summary, html_table

        return html_table(type(self).__name__, design_summary(self), self._html_picture())

    def _html_picture(self) -> str:
        from chargedesign.results import design_picture

        return design_picture(self)

    def to_pyvista(self, **kwargs: Any) -> Any:
        """The body as a ``pyvista.MultiBlock`` (see :func:`chargedesign.viz.design_blocks`)."""
        from chargedesign.viz import design_blocks

        return design_blocks(self, **kwargs)

    def plot(self, plotter: Any = None, **kwargs: Any) -> Any:
        """Draw the body into ``plotter`` (a new one when None); see
        :func:`chargedesign.viz.plot_design`."""
        from chargedesign.viz import plot_design

        return plot_design(self, plotter, **kwargs)


def read_design(path: str | os.PathLike[str]) -> Design:
    """Read a design.json file; bad files raise InputError naming the file and the reason."""
    p = Path(path)
    if not p.is_file():
        raise InputError(f"{p}: no such design file")
    try:
        data = json.loads(p.read_text(encoding="utf-8"))
    except (json.JSONDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: not valid JSON ({exc})") from exc
    return Design.from_dict(data, where=str(p))


def write_design(design: Design, path: str | os.PathLike[str]) -> None:
    """Write design.json atomically."""
    write_json_atomic(path, design.to_dict())
