"""design.json's continuous bodies, read at the boundary: every check of a ``continuous``
entry and its density, with the one-line error naming the key and the reason.

:meth:`chargedesign.quadrature.ContinuousBody.from_dict` builds the body from the checked
fields; the quadrature itself trusts them.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.scene.keys import KEY
from chargedesign.validation import as_array, as_finite_float, input_error, parse_moment_key

KINDS = ("charge", "mass")
SHAPES = ("ball", "shell", "cylinder", "box")
DENSITY_TYPES = ("uniform", "polynomial")
#: size keys each shape needs (all in m)
SIZE_KEYS = {
    "ball": ("radius",),
    "shell": ("radius",),
    "cylinder": ("radius", "height"),
    "box": (KEY.half_size,),
}
#: the keys of one continuous body
CONTINUOUS_KEYS = ("kind", "shape", "radius", "height", KEY.half_size, "center", "density")


def _density_values(kind: Any, value: Any, coefficients: Any) -> dict[str, Any]:
    """A density's checked fields (``type``, ``value``, ``coefficients``): ``kind`` is one of
    :data:`DENSITY_TYPES` and ``coefficients`` a mapping (:func:`density_fields` checked them)."""
    value = as_finite_float(value, "density.value")
    coeffs: dict[str, float] = {}
    for key, coef in coefficients.items():
        if not isinstance(key, str):
            raise input_error("density.coefficients", "string keys such as 'xxz'", key)
        parse_moment_key(key)
        coeffs[key] = as_finite_float(coef, f"density.coefficients.{key or '(constant)'}")
    return {"type": kind, "value": value, "coefficients": coeffs}


def density_fields(data: Any, where: str = "density") -> dict[str, Any]:
    """The checked fields of a density's design.json mapping (uniform ``value`` or
    polynomial ``coefficients``)."""
    if not isinstance(data, Mapping):
        raise input_error(where, "an object with key 'type'", data)
    kind = data.get("type")
    if kind == "uniform":
        if "value" not in data:
            raise InputError(f"{where}: missing key 'value'")
        return _density_values("uniform", data["value"], {})
    if kind == "polynomial":
        coeffs = data.get("coefficients")
        if not isinstance(coeffs, Mapping):
            raise input_error(f"{where}.coefficients", "an object of moment keys", coeffs)
        return _density_values("polynomial", 0.0, dict(coeffs))
    raise input_error(f"{where}.type", "one of " + ", ".join(DENSITY_TYPES), kind)


def _body_values(
    kind: Any,
    shape: Any,
    center: Any,
    density: dict[str, Any],
    sizes: dict[str, Any],
) -> dict[str, Any]:
    """A continuous body's checked fields; ``density`` holds a density's checked fields."""
    if kind not in KINDS:
        raise input_error("continuous.kind", "one of " + ", ".join(KINDS), kind)
    if shape not in SHAPES:
        raise input_error("continuous.shape", "one of " + ", ".join(SHAPES), shape)
    out: dict[str, Any] = {
        "kind": kind,
        "shape": shape,
        "center": as_array(center, "continuous.center", (3,)),
        "density": density,
        "radius": None,
        "height": None,
        KEY.half_size: None,
    }
    needed = SIZE_KEYS[shape]
    for key in ("radius", "height"):
        value = sizes.get(key)
        if key in needed:
            if value is None:
                raise InputError(f"continuous: a {shape} needs '{key}'")
            out[key] = as_finite_float(value, f"continuous.{key}", positive=True)
        elif value is not None:
            raise InputError(f"continuous: a {shape} takes no '{key}'")
    raw = sizes.get(KEY.half_size)
    if KEY.half_size in needed:
        if raw is None:
            raise InputError("continuous: a box needs 'half_size'")
        if isinstance(raw, (int, float)) and not isinstance(raw, bool):
            raw = [raw] * 3
        half = as_array(raw, "continuous.half_size", (3,))
        if np.any(half <= 0.0):
            raise input_error("continuous.half_size", "three numbers > 0", half)
        out[KEY.half_size] = half
    elif raw is not None:
        raise InputError(f"continuous: a {shape} takes no 'half_size'")
    if kind == "mass" and density["type"] == "uniform" and density["value"] < 0:
        raise input_error("continuous.density.value", "a mass density >= 0", density["value"])
    return out


def continuous_fields(data: Any, where: str = "continuous") -> dict[str, Any]:
    """The checked fields of one ``continuous`` entry of design.json:
    ``{"kind", "shape", size keys, "center", "density"}`` (``density`` as checked fields)."""
    if not isinstance(data, Mapping):
        raise input_error(where, "an object with keys kind, shape, density", data)
    known = set(CONTINUOUS_KEYS)
    unknown = sorted(set(data) - known)
    if unknown:
        raise input_error(where, "keys among " + ", ".join(sorted(known)), unknown[0])
    for key in ("kind", "shape", "density"):
        if key not in data:
            raise InputError(f"{where}: missing key '{key}'")
    try:
        return _body_values(
            data["kind"],
            data["shape"],
            data.get("center", [0.0, 0.0, 0.0]),
            density_fields(data["density"], f"{where}.density"),
            {key: data.get(key) for key in ("radius", "height", KEY.half_size)},
        )
    except InputError as exc:
        raise InputError(f"{where}: {exc}") from exc
