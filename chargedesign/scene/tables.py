"""Typed forms of the scene tables that name no stage: ``[tolerance]`` and ``[body]``.

``[body]`` means one of two things: a region the design places elements in
(:class:`BodyRegion`, ``shape = ...``), or the body to simulate (:class:`BodyReference`, a
``design = PATH`` or inline ``charges``/``masses``/``dipoles``). A region's values are read
into a :class:`RegionSpec` (:meth:`BodyRegion.spec`; a scene's:
:meth:`~chargedesign.scene.Scene.region_spec`) when a stage first needs its points, as they
always were: the candidate sets (:mod:`chargedesign.candidates`) are built from the checked
values and check nothing of the table themselves.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import cached_property
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.limits import MAX_CANDIDATES
from chargedesign.scene.keys import (
    BODY_REFERENCE_KEYS,
    KEY,
    REGION_KEYS,
    check_table,
    check_value,
    default_of,
)
from chargedesign.validation import as_array, as_finite_float, check_keys, input_error
from chargedesign.vocabulary import BODY_SHAPES, MATERIAL_ERROR_KEYS

Vector = tuple[float, float, float]


def material_errors_from_table(table: Any, where: str = "tolerance") -> dict[str, float]:
    """``[tolerance]``: every material error (relative, in [0, 1); absent ones are 0)."""
    check_table(table, "tolerance", where)
    out = dict.fromkeys(MATERIAL_ERROR_KEYS, 0.0)
    for key, value in table.items():
        out[key] = check_value("tolerance", key, value, f"{where}.{key}")
    return out


@dataclass(frozen=True)
class RegionSpec:
    """A ``[body]`` region's values, checked (lengths in m): what the candidate sets are
    built from.

    Attributes
    ----------
    shape : str
        One of :data:`~chargedesign.vocabulary.BODY_SHAPES`.
    center : tuple of 3 floats
        Offset of the shape.
    symmetric : bool
        Close the set under the 16 symmetries about O.
    natural : bool
        The shape's own rule is closed under them already (lattices through O, a centred
        shell, a square box): closing then adds nothing.
    radius, height, spacing : float or None
        The sizes the shape has (a lattice's ``spacing`` with its default filled in; a
        mesh's is None unless given).
    half_size : tuple of 3 floats or None
        A box's half edge lengths (``size`` is read as twice them).
    n_points : int or None
        A shell's number of Fibonacci points.
    path : str or None
        A points or mesh file as the scene writes it (relative to the scene's folder).
    scale : float
        Metres per file unit.
    sample : {"surface", "volume"}
        A mesh's surface vertices or its interior lattice.
    """

    shape: str
    center: Vector = (0.0, 0.0, 0.0)
    symmetric: bool = True
    natural: bool = True
    radius: float | None = None
    height: float | None = None
    spacing: float | None = None
    half_size: Vector | None = None
    n_points: int | None = None
    path: str | None = None
    scale: float = default_of("body", "scale")
    sample: str = default_of("body", "sample")

    @property
    def centred(self) -> bool:
        return not any(self.center)


@dataclass(frozen=True)
class BodyRegion:
    """``[body]`` with a shape: where the design may place elements (its keys checked against
    the shape when the scene is read, its values when :meth:`spec` is first asked for)."""

    table: Mapping[str, Any] = field(default_factory=dict)

    def __post_init__(self) -> None:
        check_region_keys(self.table)

    @property
    def shape(self) -> str:
        return str(self.table.get("shape", default_of("body", "shape")))

    def spec(self) -> RegionSpec:
        """The region's values, checked once, when first asked for (:func:`region_from_table`
        without its second look at the keys, checked as the region was made)."""
        return self._spec

    @cached_property
    def _spec(self) -> RegionSpec:
        return _region_values(self.table, _shape_name(self.table))


def _size(table: Mapping[str, Any], key: str, default: float | None = None) -> float:
    """A positive size the shape needs (its default, where it has one)."""
    value = table.get(key, default)
    if value is None:
        raise InputError(f"body.{key}: required for shape = {table.get('shape')!r}")
    return float(check_value("body", key, value))


def _vector3(table: Mapping[str, Any], key: str, *, positive: bool) -> Vector:
    """A vector key, or one number for all three components (``half_size = 0.05``)."""
    value = table[key]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        x = as_finite_float(value, f"body.{key}", positive=positive)
        return (x, x, x)
    out = as_array(value, f"body.{key}", (3,))
    if positive and np.any(out <= 0):
        raise input_error(f"body.{key}", "three numbers > 0", value)
    return (float(out[0]), float(out[1]), float(out[2]))


def _shape_name(table: Any) -> str:
    """The region's shape (``ball`` when a table gives sizes only), one of the shapes."""
    if not isinstance(table, Mapping):
        raise input_error("body", "a table with key 'shape'", table)
    shape = table.get("shape", default_of("body", "shape") if table else None)
    if shape is None:
        raise InputError(
            "body: the scene has no [body] table; give one with shape = "
            + " | ".join(BODY_SHAPES)
            + " (where the design may place elements)"
        )
    if shape not in BODY_SHAPES:
        raise input_error("body.shape", "one of " + ", ".join(BODY_SHAPES), shape)
    return str(shape)


def _naturally_symmetric(table: Mapping[str, Any], shape: str, centred: bool) -> bool:
    """Whether the shape's own rule is closed under the symmetries already (then
    ``symmetric`` defaults on). Lattices through O are, unless a box's |x| and |y| sizes
    differ (closing under x <-> y would add points outside it)."""
    if shape == "box" and centred:
        half_xy = table.get(KEY.half_size, table.get("size"))
        return not isinstance(half_xy, (list, tuple)) or (
            len(half_xy) == 3 and half_xy[0] == half_xy[1]
        )
    return centred and shape in ("ball", "cylinder", "shell")


def _lattice_sizes(table: Mapping[str, Any], shape: str) -> dict[str, Any]:
    """A ball's, box's or cylinder's sizes and lattice spacing (its default filled in)."""
    if shape == "ball":
        radius = _size(table, "radius")
        return {"radius": radius, "spacing": _size(table, "spacing", radius / 4.0)}
    if shape == "box":
        if KEY.half_size in table and "size" in table:
            raise InputError("body.size: give either half_size or size, not both")
        if KEY.half_size in table:
            half = _vector3(table, KEY.half_size, positive=True)
        elif "size" in table:
            full = _vector3(table, "size", positive=True)
            half = (0.5 * full[0], 0.5 * full[1], 0.5 * full[2])
        else:
            raise InputError("body.half_size: required for shape = 'box' (or give size)")
        return {KEY.half_size: half, "spacing": _size(table, "spacing", min(half) / 2.0)}
    radius = _size(table, "radius")
    height = _size(table, "height")
    spacing = _size(table, "spacing", min(radius, 0.5 * height) / 4.0)
    return {"radius": radius, "height": height, "spacing": spacing}


def _shell_sizes(table: Mapping[str, Any]) -> dict[str, Any]:
    """A shell's radius and number of points."""
    radius = _size(table, "radius")
    n_points = table.get("n_points", default_of("body", "n_points"))
    if isinstance(n_points, bool) or not isinstance(n_points, int):
        raise input_error("body.n_points", f"an integer in 4..{MAX_CANDIDATES}", n_points)
    if not 4 <= n_points <= MAX_CANDIDATES:
        raise input_error("body.n_points", f"an integer in 4..{MAX_CANDIDATES}", n_points)
    return {"radius": radius, "n_points": n_points}


def _file_keys(table: Mapping[str, Any], shape: str) -> dict[str, Any]:
    """A points or mesh region's file, scale and (mesh) sampling."""
    raw = table.get("path")
    if not isinstance(raw, str) or not raw:
        raise input_error("body.path", "a file name (string)", raw)
    out: dict[str, Any] = {"path": raw, "scale": _size(table, "scale", default_of("body", "scale"))}
    if shape == "points":
        return out
    sample = table.get("sample", default_of("body", "sample"))
    if sample not in ("surface", "volume"):
        raise input_error("body.sample", "'surface' or 'volume'", sample)
    spacing = _size(table, "spacing") if "spacing" in table else None
    if sample == "volume" and spacing is None:
        raise InputError("body.spacing: required for shape = 'mesh', sample = 'volume'")
    return out | {"sample": sample, "spacing": spacing}


def region_from_table(table: Any) -> RegionSpec:
    """A ``[body]`` region's values, checked in the order a reader meets them (shape and its
    keys, center, symmetric, then the shape's sizes); each error is one line naming the key.

    Raises
    ------
    InputError
        A missing, unknown or malformed key.
    """
    shape = _shape_name(table)
    check_region_keys(table)
    return _region_values(table, shape)


def _region_values(table: Mapping[str, Any], shape: str) -> RegionSpec:
    """The values of a region whose shape and keys are checked."""
    center = _vector3(table, "center", positive=False) if "center" in table else (0.0, 0.0, 0.0)
    natural = _naturally_symmetric(table, shape, not any(center))
    symmetric = table.get("symmetric", natural)
    if not isinstance(symmetric, bool):
        raise input_error("body.symmetric", "true or false", symmetric)
    if shape in ("ball", "box", "cylinder"):
        sizes = _lattice_sizes(table, shape)
    elif shape == "shell":
        sizes = _shell_sizes(table)
    else:
        sizes = _file_keys(table, shape)
    return RegionSpec(shape, center, symmetric, natural, **sizes)


@dataclass(frozen=True)
class BodyReference:
    """``[body]`` naming the body to simulate: ``design = PATH`` or inline elements."""

    table: Mapping[str, Any] = field(default_factory=dict)

    @property
    def design_path(self) -> Any:
        return self.table.get("design")


def check_region_keys(table: Mapping[str, Any]) -> None:
    """Unknown keys of a ``[body]`` region (for its shape) are one-line errors naming the key.

    A missing or unknown shape is left to the candidate sets.
    """
    if not isinstance(table, Mapping):
        return
    shape = table.get("shape", "ball" if table else None)
    if not isinstance(shape, str) or shape not in REGION_KEYS:
        return
    # carrier_radius belongs to the physical parts (chargedesign.scene.physical)
    allowed = set(REGION_KEYS[shape]) | {"shape", KEY.carrier_radius}
    unknown = sorted(set(table) - allowed)
    if unknown:
        raise input_error(
            f"body.{unknown[0]}",
            f"a key of shape {shape!r} (" + ", ".join(REGION_KEYS[shape]) + ")",
            unknown[0],
        )


def body_from_table(table: Any) -> BodyRegion | BodyReference | None:
    """``[body]`` as a region or a reference (None: the scene has no ``[body]``)."""
    if table is None:
        return None
    if not isinstance(table, Mapping):
        raise input_error("body", "a table", table)
    if "shape" in table or not set(table) & set(BODY_REFERENCE_KEYS):
        return BodyRegion(dict(table))  # its keys checked as it is made
    check_keys(table, BODY_REFERENCE_KEYS, "body")
    return BodyReference(dict(table))
