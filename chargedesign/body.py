"""A designed body: charges on carriers, magnets and ballast masses, with its target parameters and
fields; read and written as ``design.json`` (format ``chargedesign.design/1``, see CONTRACT.md).
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from chargedesign.elements import ElementSet
from chargedesign.errors import InputError
from chargedesign.files import write_json_atomic
from chargedesign.larmor import LarmorReading, body_parameters
from chargedesign.params import Parameters
from chargedesign.quadrature import ContinuousBody
from chargedesign.readers import json_kind, read_json_file, refuse_other_kind, sniff_kind
from chargedesign.results import compact_repr, design_summary, design_text, html_table
from chargedesign.scene.design_materials import check_mass_materials, materials_from_dict
from chargedesign.scene.medium import Medium
from chargedesign.validation import (
    as_array,
    as_finite_float,
    check_choice,
    check_design_numbers,
    check_instance,
    input_error,
)
from chargedesign.vocabulary import (
    DESIGN_FORMAT,
    FIELD_KINDS,
    OLD_WITHIN_LIMITS_KEY,
    REALISABLE,
    WITHIN_LIMITS_KEY,
)


def check_items(values: Any, choices: Sequence[str], name: str) -> None:
    """Refuse the first item of ``values`` outside ``choices`` in one line."""
    for item in values:
        if item not in choices:
            raise input_error(name, "items among " + ", ".join(choices), item)


def check_design_head(data: Any, where: str) -> None:
    """A design.json mapping's frame, before its parameters are read: an object of this
    format that has parameters."""
    if not isinstance(data, dict):
        raise input_error(where, "a JSON object", data)
    found = data.get("format", DESIGN_FORMAT)
    if found != DESIGN_FORMAT:
        raise input_error(f"{where}.format", repr(DESIGN_FORMAT), found)
    if "parameters" not in data:
        raise InputError(f"{where}: missing key 'parameters'")


def _check_frontier_rates(frontier: Any, where: str = "") -> None:
    """design.json's ``frontier.K_max`` (1/s) and ``frontier.s_max``: numbers >= 0 when given
    (``where``: the file, prefixed to the message when given)."""
    if not isinstance(frontier, Mapping):
        return
    prefix = f"{where}: " if where else ""
    for key, expected in (("K_max", "a number >= 0 (1/s)"), ("s_max", "a number >= 0")):
        value = frontier.get(key)
        if value is None:
            continue
        number = as_finite_float(value, f"{prefix}frontier.{key}")
        if number < 0:
            raise input_error(f"{prefix}frontier.{key}", expected, value)


def _design_fields(data: Mapping[str, Any], where: str) -> dict[str, Any]:
    """A design.json mapping's ``fields`` as ``{kind: legendre coefficients}`` (as written)."""
    fields_in = data.get("fields") or {}
    if not isinstance(fields_in, dict):
        raise input_error(f"{where}.fields", "an object", fields_in)
    out = {}
    for kind, spec in fields_in.items():
        if not isinstance(spec, dict) or "legendre" not in spec:
            raise input_error(f"{where}.fields.{kind}", "an object with key 'legendre'", spec)
        out[kind] = spec["legendre"]
    return out


__all__ = [
    "DESIGN_FORMAT",
    "FIELD_KINDS",
    "REALISABLE",
    "RECORD_KEYS",
    "Design",
    "read_design",
    "write_design",
]

#: A JSON object as design.json holds it.
JSONObject = dict[str, Any]

#: design.json's record keys beside the contract's (CONTRACT.md: "further keys"), in the order
#: they are written; each is a :class:`Design` attribute of the same name.
RECORD_KEYS = (
    "units",
    "provenance",
    "solver",
    "objective",
    "residuals",
    "forward_accuracy",
    "timings",
    "candidates",
    "conditions",
    "notes",
    "region",
    "field_limits",
    "time_rate",
    "material_errors",
    "balance",
    "buildability",
    "realism",
    "physical_design",
    "frontier",
    "tolerance",
    "larmor_why",
    "inertia",
    "holder",
    "support",
    "verdict",
)


def _renamed(key: str, value: Any) -> Any:
    """A record block as this version names its keys: ``buildability.buildable`` (files
    written before the rename) is read as ``buildability.parts_within_limits``."""
    if key == "buildability" and isinstance(value, dict) and OLD_WITHIN_LIMITS_KEY in value:
        value = dict(value)
        old = value.pop(OLD_WITHIN_LIMITS_KEY)
        value.setdefault(WITHIN_LIMITS_KEY, old)
    return value


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
    units, provenance, solver, objective, residuals, forward_accuracy, timings, candidates,
    conditions, notes, region, field_limits, time_rate, material_errors, balance, buildability,
    realism, physical_design, frontier, tolerance, larmor_why
        The record of how the body was obtained and judged: design.json's keys of the same
        names beside the contract's (:data:`RECORD_KEYS`; None when the file has none). Each
        block holds its JSON mapping as written (``buildability``: the limits report,
        :mod:`chargedesign.physical.limits`; ``realism``: the realism budget; ``frontier``:
        the largest rate within the limits; ``tolerance``: the tolerance report).
        ``time_rate`` is the physical design's rate s; ``larmor_why`` why the Larmor reading
        was chosen.
    further_keys : dict
        design.json keys this version does not know (other tools' additions), kept verbatim.
    larmor : LarmorReading or None
        How the body realises the theorem's n (design.json ``larmor``): ``charges`` (the
        paper's reading) or ``frame`` (the elements realise n = 0; the motion is read in axes
        turning at ``larmor.rate``). None (a file without the key) means ``charges``.
    """

    parameters: Parameters
    fields: dict[str, tuple[float, ...]] = field(default_factory=dict)
    realises: list[str] = field(default_factory=list)
    continuous: list[Any] = field(default_factory=list)
    #: a design.json ``medium`` mapping given here is read into a Medium (__post_init__)
    medium: Medium | dict[str, Any] | None = None
    materials: dict[str, Any] = field(default_factory=dict)
    larmor: LarmorReading | None = None
    # ---- the record (design.json keys beside the contract's, in RECORD_KEYS order)
    units: dict[str, str] | None = None
    provenance: JSONObject | None = None
    solver: JSONObject | None = None
    objective: JSONObject | None = None
    residuals: JSONObject | None = None
    forward_accuracy: JSONObject | None = None
    timings: dict[str, float] | None = None
    candidates: JSONObject | None = None
    conditions: JSONObject | None = None
    notes: list[str] | None = None
    region: JSONObject | None = None
    field_limits: dict[str, float] | None = None
    time_rate: float | None = None
    material_errors: JSONObject | None = None
    balance: JSONObject | None = None
    buildability: JSONObject | None = None
    realism: JSONObject | None = None
    physical_design: JSONObject | None = None
    frontier: JSONObject | None = None
    tolerance: JSONObject | None = None
    larmor_why: str | None = None
    #: the whole inertia about O (points, the parts' own, the holder's; chargedesign.physical.
    #: holder.whole_inertia) and the holder (its material, radius, bores), or None
    inertia: JSONObject | None = None
    holder: JSONObject | None = None
    #: how the body is held and whether its support passes (physical.support.support_record)
    support: JSONObject | None = None
    #: the verdict, judged once when the design is accepted (chargedesign.verdict)
    verdict: JSONObject | None = None
    further_keys: JSONObject = field(default_factory=dict)

    def __post_init__(self) -> None:
        super().__post_init__()
        if self.time_rate is not None:
            self.time_rate = as_finite_float(self.time_rate, "time_rate")
        if self.larmor is not None and not isinstance(self.larmor, LarmorReading):
            self.larmor = LarmorReading.from_dict(self.larmor)
        self.medium = Medium.from_dict(self.medium) if self.medium is not None else None
        self.materials = materials_from_dict(self.materials)
        check_mass_materials(self.materials, self.mass_materials, bool(len(self.mass_values)))
        for kind in self.fields:
            check_choice(kind, FIELD_KINDS, f"fields.{kind}")
        self.fields = {k: _legendre(v, f"fields.{k}.legendre") for k, v in self.fields.items()}
        check_items(self.realises, REALISABLE, "realises")
        check_instance(self.continuous, (list, tuple), "continuous", "a list of bodies")
        self.continuous = [
            ContinuousBody.coerce(b, f"continuous[{i}]") for i, b in enumerate(self.continuous)
        ]

    @property
    def larmor_reading(self) -> str:
        """``charges`` or ``frame`` (``charges`` when the file names none)."""
        return self.larmor.reading if self.larmor is not None else "charges"

    @property
    def body_parameters(self) -> Parameters:
        """The parameters the elements themselves realise (``n = 0`` for ``frame``)."""
        return body_parameters(self.parameters, self.larmor)

    @property
    def general_case(self) -> dict[str, Any] | None:
        """design.json's ``case`` record of a general case's body (a case not of the theorem's
        form: its recorded parameters are C alone, no rate), None for the theorem's body (a
        theorem's scene, or a case of its form, whose parameters are the theorem's)."""
        record = self.further_keys.get("case")
        p = self.parameters
        if not isinstance(record, dict) or any((p.n, p.K, p.kappa, p.lam, p.rho)):
            return None
        return record

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
        if self.medium is not None:
            out["medium"] = Medium.from_dict(self.medium).to_dict()
        if self.materials:
            out["materials"] = {
                k: [dict(x) for x in v] if isinstance(v, list) else dict(v)
                for k, v in self.materials.items()
            }
        if self.larmor is not None:
            out["larmor"] = self.larmor.to_dict()
        for key in RECORD_KEYS:
            value = getattr(self, key)
            if value is not None:
                out.setdefault(key, value)
        for key, value in self.further_keys.items():
            out.setdefault(key, value)
        return out

    def record(self) -> JSONObject:
        """The record keys this design carries (design.json's keys beside the contract's)."""
        return {k: getattr(self, k) for k in RECORD_KEYS if getattr(self, k) is not None}

    @classmethod
    def from_dict(cls, data: Any, where: str = "design") -> Design:
        check_design_head(data, where)
        _check_frontier_rates(data.get("frontier"))  # the rates the K law reads (>= 0)
        params = Parameters.from_mapping(data["parameters"], f"{where}.parameters")
        fields_out = _design_fields(data, where)

        known = {"format", "parameters", "fields", "charges", "masses", "dipoles", "realises"}
        known |= {"continuous", "medium", "materials", "larmor", *RECORD_KEYS}
        return cls(
            parameters=params,
            fields=fields_out,
            **ElementSet.arrays_from_blocks(data, where),
            realises=list(data.get("realises", [])),
            **{k: _renamed(k, data[k]) for k in RECORD_KEYS if k in data},
            further_keys={k: v for k, v in data.items() if k not in known},
            continuous=data.get("continuous") or [],
            medium=data.get("medium"),
            materials=data.get("materials") or {},
            larmor=(
                LarmorReading.from_dict(data["larmor"], f"{where}.larmor")
                if "larmor" in data
                else None
            ),
        )

    # ---- result protocol (chargedesign.results) and pictures (chargedesign.viz)
    def __repr__(self) -> str:
        return compact_repr(type(self).__name__, design_summary(self))

    def __str__(self) -> str:
        """The main figures, one a line (the report: :func:`chargedesign.report.render_report`
        or ``str`` of the :class:`~chargedesign.designer.DesignResult`)."""
        return design_text(self)

    def _repr_html_(self) -> str:
        return html_table(type(self).__name__, design_summary(self), self._html_picture())

    def _html_picture(self) -> str:
        from chargedesign.viz import design_picture  # viz loads PyVista (VTK): only when drawn

        return design_picture(self)

    def to_pyvista(self, **kwargs: Any) -> Any:
        """The body as a ``pyvista.MultiBlock`` (see :func:`chargedesign.viz.design_blocks`)."""
        from chargedesign.viz import design_blocks  # viz loads PyVista (VTK): only when drawn

        return design_blocks(self, **kwargs)

    def plot(self, plotter: Any = None, **kwargs: Any) -> Any:
        """Draw the body into ``plotter`` (a new one when None); see
        :func:`chargedesign.viz.plot_design`."""
        from chargedesign.viz import plot_design  # viz loads PyVista (VTK): only when drawn

        return plot_design(self, plotter, **kwargs)


def read_design(path: str | os.PathLike[str], *, required: tuple[str, ...] = ()) -> Design:
    """Read a design.json file; bad files raise InputError naming the file and the reason.

    The file is read safely (chargedesign.readers: size, depth, no NaN/inf, no huge
    integers) and every number the body is built from passes the input range
    (docs/reliability.md); fields longer than ``MAX_FIELD_DEGREE`` are refused.
    """
    p = Path(path)
    try:
        data = read_json_file(p, "design file")
    except InputError:
        # a scene, a case file, a CSV handed in for a design: say which (readers.FILE_KINDS)
        refuse_other_kind(p, None if p.suffix.lower() == ".json" else sniff_kind(p), "design")
        raise
    refuse_other_kind(p, json_kind(data), "design")  # a testbed.json, a simulation summary ...
    check_design_numbers(data, str(p), required=required)  # the whole file (``required``: keys
    # a verdict needs, e.g. check's ``realises``)
    return Design.from_dict(data, where=str(p))


def write_design(design: Design, path: str | os.PathLike[str]) -> None:
    """Write design.json atomically."""
    write_json_atomic(path, design.to_dict())
