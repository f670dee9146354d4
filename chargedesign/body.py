"""A designed body: point charges, magnetic dipoles and masses, with its target parameters and
fields; read and written as ``design.json`` (format ``chargedesign.design/1``, see CONTRACT.md).
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.files import write_json_atomic
from chargedesign.params import Parameters
from chargedesign.validation import as_array, as_points, as_weights, input_error

DESIGN_FORMAT = "chargedesign.design/1"
FIELD_KINDS = ("magnetic", "electric", "gravity")
REALISABLE = ("mu", "V", "inertia")


def _legendre(value: Any, name: str) -> tuple[float, ...]:
    if isinstance(value, (list, tuple)) and len(value) == 0:
        return ()
    return tuple(float(x) for x in as_array(value, name, (None,)))


def validate_elements(body: Any) -> None:
    """Validate and convert, in place, the six element arrays of a body-like object.

    ``charge_positions`` (n, 3) with ``charge_values`` (n,), ``mass_positions`` (m, 3) with
    ``mass_values`` (m,), ``dipole_positions`` (k, 3) with ``dipole_moments`` (k, 3); errors name
    the design.json key (``charges.values``, ...).
    """
    body.charge_positions = as_points(body.charge_positions, "charges.positions")
    body.charge_values = as_weights(
        body.charge_values, "charges.values", len(body.charge_positions)
    )
    body.mass_positions = as_points(body.mass_positions, "masses.positions")
    body.mass_values = as_weights(body.mass_values, "masses.values", len(body.mass_positions))
    body.dipole_positions = as_points(body.dipole_positions, "dipoles.positions")
    body.dipole_moments = as_points(
        body.dipole_moments, "dipoles.moments", len(body.dipole_positions)
    )


@dataclass
class Design:
    """Elements in body axes (SI units) plus what they are meant to realise.

    Attributes
    ----------
    parameters : Parameters
        The theorem's parameters the body targets.
    fields : dict[str, tuple[float, ...]]
        ``legendre`` coefficients per field kind (``magnetic``, ``electric``, ``gravity``);
        ``Phi = sum_k f_k R^k P_k(Z/R)``, f_k in the field's units per m^(k-1).
    charge_positions : ndarray, shape (n, 3)
        Charge positions in m. ``charge_values``: ndarray, shape (n,), in C.
    mass_positions : ndarray, shape (m, 3)
        Mass positions in m. ``mass_values``: ndarray, shape (m,), in kg (>= 0).
    dipole_positions : ndarray, shape (k, 3)
        Dipole positions in m. ``dipole_moments``: ndarray, shape (k, 3), in A m^2 (body axes).
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
    charge_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    charge_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    mass_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    mass_values: np.ndarray = field(default_factory=lambda: np.zeros(0))
    dipole_positions: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    dipole_moments: np.ndarray = field(default_factory=lambda: np.zeros((0, 3)))
    realises: list[str] = field(default_factory=list)
    extra: dict[str, Any] = field(default_factory=dict)
    continuous: list[Any] = field(default_factory=list)

    def __post_init__(self) -> None:
        validate_elements(self)
        if np.any(self.mass_values < 0):
            raise input_error("masses.values", "nonnegative masses", self.mass_values.min())
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

    @property
    def n_elements(self) -> int:
        return len(self.charge_values) + len(self.mass_values) + len(self.dipole_moments)

    def to_dict(self) -> dict[str, Any]:
        """The contract's JSON mapping (plus ``extra`` keys)."""
        out: dict[str, Any] = {
            "format": DESIGN_FORMAT,
            "parameters": self.parameters.as_dict(),
            "fields": {k: {"legendre": list(v)} for k, v in self.fields.items()},
            "charges": {
                "positions": self.charge_positions.tolist(),
                "values": self.charge_values.tolist(),
            },
            "masses": {
                "positions": self.mass_positions.tolist(),
                "values": self.mass_values.tolist(),
            },
            "dipoles": {
                "positions": self.dipole_positions.tolist(),
                "moments": self.dipole_moments.tolist(),
            },
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

        def block(name: str, keys: tuple[str, str]) -> tuple[Any, Any]:
            b = data.get(name) or {}
            if not isinstance(b, dict):
                raise input_error(f"{where}.{name}", "an object", b)
            return b.get(keys[0], []), b.get(keys[1], [])

        cp, cv = block("charges", ("positions", "values"))
        mp, mv = block("masses", ("positions", "values"))
        dp, dm = block("dipoles", ("positions", "moments"))
        known = {"format", "parameters", "fields", "charges", "masses", "dipoles", "realises"}
        known.add("continuous")
        return cls(
            parameters=params,
            fields=fields_out,
            charge_positions=cp,
            charge_values=cv,
            mass_positions=mp,
            mass_values=mv,
            dipole_positions=dp,
            dipole_moments=dm,
            realises=list(data.get("realises", [])),
            extra={k: v for k, v in data.items() if k not in known},
            continuous=data.get("continuous") or [],
        )


def read_design(path: str | os.PathLike[str]) -> Design:
    """Read a design.json file; bad files raise InputError naming the file and the reason.

    The file is read safely (chargedesign.readers: size, depth, no NaN/inf, no huge
    integers) and every number the body is built from passes the input range
    (docs/reliability.md); fields longer than ``MAX_FIELD_DEGREE`` are refused.
    """
    from chargedesign.readers import read_json_file
    from chargedesign.validation import check_design_numbers

    p = Path(path)
    data = read_json_file(p, "design file")
    check_design_numbers(data, str(p))
    return Design.from_dict(data, where=str(p))


def write_design(design: Design, path: str | os.PathLike[str]) -> None:
    """Write design.json atomically."""
    write_json_atomic(path, design.to_dict())
