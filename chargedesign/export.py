"""Export and import a design's geometry: JSON (canonical), CSV (tables), VTK PolyData (.vtp).

- ``json``: the contract's ``design.json`` mapping (:meth:`Design.to_dict`), lossless.
- ``csv``: a plain header row ``kind, x, y, z, value, mx, my, mz, design`` (``pandas.read_csv``
  and ``csv.DictReader`` read it as it is), then one row of kind ``design`` whose ``design``
  cell holds, as JSON, the parameters, fields, realises, continuous bodies, units and the
  remaining keys (provenance), then one row per element. Numbers are written with ``repr``
  (the shortest form that reads back to the same float): lossless. Files of the earlier form
  (a ``# design.KEY: JSON`` comment header) are still read.
- ``vtp`` (and ``vtu``, the same content as an UnstructuredGrid, which meshio also reads):
  points (float64) with one vertex cell per element and point-data arrays ``kind``
  (0 charge, 1 mass, 2 dipole), ``value`` (C or kg; 0 for dipoles), ``charge``, ``mass``,
  ``moment`` (A m^2, zero except for dipoles); field data ``chargedesign_design`` holds the
  rest of the design as a JSON string (continuous bodies included). Continuous bodies are
  also appended as triangulated surfaces for viewing (``kind`` 3 for charge, 4 for mass;
  ``value`` the density at each surface point; ``body`` their index, -1 for elements).
  Lossless.

The physical per-element arrays of a physical design (``charges.radii``, ``charges.masses``,
``dipoles.volumes``, ``dipoles.masses``) travel in the header of the csv, vtp and vtu files
under ``element_sizes`` (in element order), so every format stays lossless.

All writes are atomic (:func:`chargedesign.files.atomic_path`).
"""

from __future__ import annotations

import csv
import io
import json
import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.body import Design, read_design
from chargedesign.errors import InputError
from chargedesign.files import import_held, write_file_atomic
from chargedesign.readers import MAX_DATA_BYTES, check_input_file, loads_json, read_text
from chargedesign.validation import check_design_numbers, input_error
from chargedesign.vocabulary import EXPORT_FORMATS

FORMATS = EXPORT_FORMATS
CSV_COLUMNS = ("kind", "x", "y", "z", "value", "mx", "my", "mz")
#: the columns written: the element columns and the ``design`` column of the header row
CSV_WRITTEN = (*CSV_COLUMNS, "design")
UNITS = "positions m, charge C, mass kg, dipole moment A m^2"
#: point-data ``kind`` codes of the VTP export
KIND_CODES = {"charge": 0, "mass": 1, "dipole": 2, "continuous charge": 3, "continuous mass": 4}
VTP_FIELD = "chargedesign_design"
#: suffix of field data holding text as UTF-8 bytes (``.vtu``, which meshio reads)
UTF8_SUFFIX = "_utf8"
_ELEMENT_KEYS = ("charges", "masses", "dipoles")


def format_from_path(path: str | os.PathLike[str]) -> str:
    """The export format a file name calls for (``.json``, ``.csv``, ``.vtp``, ``.vtu``)."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in FORMATS:
        raise input_error(
            f"{path}: format",
            "a file name ending in " + ", ".join("." + f for f in FORMATS),
            suffix,
        )
    return suffix


def resolve_format(fmt: str | None, path: str | os.PathLike[str]) -> str:
    """``fmt`` checked against :data:`FORMATS`, or the format the file name calls for."""
    if fmt is None:
        return format_from_path(path)
    if fmt not in FORMATS:
        raise input_error("format", "one of " + ", ".join(FORMATS), fmt)
    return fmt


def export_design(design: Design, fmt: str | None, path: str | os.PathLike[str]) -> Path:
    """Write ``design`` in format ``fmt`` (``json``, ``csv``, ``vtp``, ``vtu``; None: from the
    suffix).

    Returns
    -------
    Path
        The written file.
    """
    fmt = resolve_format(fmt, path)
    target = Path(path)
    writers: dict[str, Callable[[Design, Path], None]] = {
        "json": _write_json,
        "csv": _write_csv,
        "vtp": _write_vtp,
        "vtu": _write_vtu,
    }
    write_file_atomic(target, lambda tmp: writers[fmt](design, tmp))
    return target


def import_design(path: str | os.PathLike[str]) -> Design:
    """Read a design from a ``.json``, ``.csv``, ``.vtp`` or ``.vtu`` file written by
    :func:`export_design`.

    The round trip is exact: positions, values and moments come back bit-identical.
    """
    fmt = format_from_path(path)
    p = check_input_file(path, "file", MAX_DATA_BYTES)
    if fmt == "json":
        return read_design(p)
    if fmt == "csv":
        return _read_csv(p)
    return _read_vtp(p)  # .vtp and .vtu alike


def load_any_design(path: str | os.PathLike[str]) -> Design:
    """A design from ``.csv``, ``.vtp`` or ``.vtu`` exports, else from design.json (whatever the
    name)."""
    if Path(path).suffix.lower() in (".csv", ".vtp", ".vtu"):
        return import_design(path)
    return read_design(path)


# ---------------------------------------------------------------------------------------------
# json


def _write_json(design: Design, path: Path) -> None:
    path.write_text(
        json.dumps(design.to_dict(), indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )


#: header key of the physical per-element arrays (carrier radii and masses, magnet volumes and
#: masses), in element order; the tables and VTK arrays carry positions and values only
SIZES_KEY = "element_sizes"


def _header(design: Design) -> dict[str, Any]:
    """Everything of the design except its elements (parameters, fields, realises, the record),
    plus the physical per-element arrays of a physical design under :data:`SIZES_KEY`."""
    data = design.to_dict()
    out = {k: v for k, v in data.items() if k not in _ELEMENT_KEYS}
    sizes = {
        block: {k: v for k, v in data[block].items() if k not in ("positions", "values", "moments")}
        for block in _ELEMENT_KEYS
    }
    sizes = {block: keys for block, keys in sizes.items() if keys}
    if sizes:
        out[SIZES_KEY] = sizes
    return out


def _from_header(header: Any, elements: dict[str, dict[str, Any]], where: str) -> Design:
    if not isinstance(header, dict):
        raise input_error(where, "a JSON object describing the design", header)
    header = dict(header)
    sizes = header.pop(SIZES_KEY, None) or {}
    if not isinstance(sizes, dict):
        raise input_error(f"{where}: {SIZES_KEY}", "a JSON object", sizes)
    merged = {block: dict(arrays) for block, arrays in elements.items()}
    for block, arrays in sizes.items():
        if block not in _ELEMENT_KEYS or not isinstance(arrays, dict):
            raise input_error(f"{where}: {SIZES_KEY}.{block}", "charges, masses or dipoles", block)
        merged.setdefault(block, {}).update(arrays)
    data = {**header, **merged}
    check_design_numbers(data, where)  # the same input range as design.json
    return Design.from_dict(data, where=where)


# ---------------------------------------------------------------------------------------------
# csv


def _write_csv(design: Design, path: Path) -> None:
    header = {k: v for k, v in _header(design).items()}
    header["csv_units"] = UNITS + "; columns kind, x, y, z (m), value (C or kg), mx, my, mz (A m^2)"
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_WRITTEN)
    writer.writerow(["design", "", "", "", "", "", "", "", json.dumps(header, allow_nan=False)])
    for position, value in zip(design.charge_positions, design.charge_values, strict=True):
        writer.writerow(
            ["charge", *map(repr, map(float, position)), repr(float(value)), "", "", "", ""]
        )
    for position, value in zip(design.mass_positions, design.mass_values, strict=True):
        writer.writerow(
            ["mass", *map(repr, map(float, position)), repr(float(value)), "", "", "", ""]
        )
    for position, moment in zip(design.dipole_positions, design.dipole_moments, strict=True):
        writer.writerow(
            ["dipole", *map(repr, map(float, position)), "", *map(repr, map(float, moment)), ""]
        )
    path.write_text(buffer.getvalue(), encoding="utf-8")


def _csv_header(path: Path, text: str) -> tuple[dict[str, Any], list[str]]:
    """The ``# design.KEY: JSON`` header lines, parsed, and the other (CSV) lines."""
    header: dict[str, Any] = {}
    body_lines = []
    for number, line in enumerate(text.splitlines(), start=1):
        if not line.startswith("#"):
            body_lines.append(line)
            continue
        key, sep, value = line[1:].strip().partition(": ")
        if not sep or not key.startswith("design."):
            continue  # descriptive lines (units, columns)
        key = key.removeprefix("design.")
        header[key] = loads_json(value, f"{path}: line {number}: header {key!r}")
    return header, body_lines


def _plain_form_rows(path: Path, rows: list[list[str]], header: dict[str, Any]) -> list[list[str]]:
    """The element rows of the plain form, its design row's JSON merged into ``header``."""
    # the plain form: the design row carries the header as JSON in the last column
    kept = [rows[0][: len(CSV_COLUMNS)]]
    for number, row in enumerate(rows[1:], start=2):
        if row and row[0] == "design":
            try:
                found = json.loads(row[-1])
            except json.JSONDecodeError as exc:
                raise InputError(f"{path}: row {number}: design cell is not JSON ({exc})") from exc
            if not isinstance(found, dict):
                raise input_error(f"{path}: row {number}: design", "a JSON object", found)
            found.pop("csv_units", None)
            header.update(found)
        else:
            kept.append(row[: len(CSV_COLUMNS)])
    return kept


def _csv_elements(path: Path, rows: list[list[str]]) -> dict[str, dict[str, list[Any]]]:
    """The charges, masses and dipoles of the element rows (after the column row)."""
    elements: dict[str, dict[str, list[Any]]] = {
        "charges": {"positions": [], "values": []},
        "masses": {"positions": [], "values": []},
        "dipoles": {"positions": [], "moments": []},
    }
    for number, row in enumerate(rows[1:], start=2):
        if not row:
            continue
        try:
            kind = row[0]
            position = [float(v) for v in row[1:4]]
            if kind in ("charge", "mass"):
                block = elements["charges" if kind == "charge" else "masses"]
                block["values"].append(float(row[4]))
            elif kind == "dipole":
                block = elements["dipoles"]
                block["moments"].append([float(v) for v in row[5:8]])
            else:
                raise InputError(f"{path}: row {number}: kind: expected charge, mass or dipole")
        except (ValueError, IndexError) as exc:
            if isinstance(exc, InputError):
                raise
            raise InputError(
                f"{path}: row {number}: not a valid element row ({type(exc).__name__})"
            ) from exc
        block["positions"].append(position)
    return elements


def _read_csv(path: Path) -> Design:
    text = read_text(path, "CSV export")
    header, body_lines = _csv_header(path, text)
    rows = list(csv.reader(body_lines))
    if rows and tuple(rows[0]) == CSV_WRITTEN:
        rows = _plain_form_rows(path, rows, header)
    if not rows or tuple(rows[0]) != CSV_COLUMNS:
        # the file's own text is not echoed (it may not be an export at all)
        raise InputError(f"{path}: columns: expected {', '.join(CSV_WRITTEN)} (header row)")
    elements = _csv_elements(path, rows)
    if "parameters" not in header:
        raise InputError(f"{path}: no design row with the parameters (header missing)")
    return _from_header(header, elements, str(path))


# ---------------------------------------------------------------------------------------------
# vtp


def _write_vtp(design: Design, path: Path) -> None:
    _polydata(design).save(str(path), binary=True)


def _write_vtu(design: Design, path: Path) -> None:
    """The VTP content as an UnstructuredGrid (``.vtu``: meshio reads it)."""
    pv = import_held("pyvista")

    polydata = _polydata(design)
    grid = polydata.cast_to_unstructured_grid() if polydata.n_points else pv.UnstructuredGrid()
    grid.field_data.clear()
    # meshio reads no string arrays: the header and units as UTF-8 bytes (uint8)
    for name, text in ((VTP_FIELD, json.dumps(_header(design), allow_nan=False)), ("units", UNITS)):
        grid.field_data[f"{name}{UTF8_SUFFIX}"] = np.frombuffer(text.encode("utf-8"), np.uint8)
    grid.save(str(path), binary=True)


def _polydata(design: Design) -> Any:
    """The elements as points with vertex cells, continuous bodies as triangles (see module)."""
    from chargedesign.viz import continuous_body_mesh  # viz loads PyVista (VTK): only here

    pv = import_held("pyvista")

    counts = (len(design.charge_values), len(design.mass_values), len(design.dipole_moments))
    n = sum(counts)
    _check_vtk_lengths(design)
    points = [design.charge_positions, design.mass_positions, design.dipole_positions]
    kind = [np.repeat(np.array([0, 1, 2], dtype=np.int8), counts)]
    value = [design.charge_values, design.mass_values, np.zeros(counts[2])]
    moment = [np.zeros((counts[0] + counts[1], 3)), design.dipole_moments]
    body = [np.full(n, -1, dtype=np.int32)]
    verts = np.column_stack([np.ones(n, dtype=np.int64), np.arange(n, dtype=np.int64)]).ravel()
    faces = []
    offset = n
    for index, continuous in enumerate(design.continuous):
        mesh = continuous_body_mesh(continuous)
        mesh_points = np.asarray(mesh.points, dtype=np.float64)
        triangles = np.asarray(mesh.faces, dtype=np.int64).reshape(-1, 4)  # rows: 3, i, j, k
        faces.append(np.column_stack([triangles[:, :1], triangles[:, 1:] + offset]).ravel())
        offset += len(mesh_points)
        points.append(mesh_points)
        kind.append(np.full(len(mesh_points), KIND_CODES[f"continuous {continuous.kind}"], np.int8))
        value.append(continuous.density.evaluate(mesh_points))
        moment.append(np.zeros((len(mesh_points), 3)))
        body.append(np.full(len(mesh_points), index, dtype=np.int32))

    polydata = pv.PolyData()
    if offset:
        polydata = pv.PolyData(
            np.concatenate(points).astype(np.float64, copy=False),
            verts=verts if n else None,
            faces=np.concatenate(faces) if faces else None,
        )
        kinds = np.concatenate(kind)
        values = np.concatenate(value)
        polydata.point_data["kind"] = kinds
        polydata.point_data["value"] = values
        polydata.point_data["charge"] = np.where(kinds == 0, values, 0.0)
        polydata.point_data["mass"] = np.where(kinds == 1, values, 0.0)
        polydata.point_data["moment"] = np.concatenate(moment)
        polydata.point_data["body"] = np.concatenate(body)
    polydata.field_data[VTP_FIELD] = [json.dumps(_header(design), allow_nan=False)]
    polydata.field_data["units"] = [UNITS]
    return polydata


def _check_vtk_lengths(design: Design) -> None:
    """VTK writes each vector array's norm range into the file; an infinite norm is unreadable."""
    for name, vectors in (
        ("charges.positions", design.charge_positions),
        ("masses.positions", design.mass_positions),
        ("dipoles.positions", design.dipole_positions),
        ("dipoles.moments", design.dipole_moments),
    ):
        with np.errstate(over="ignore"):
            lengths = np.sqrt(np.sum(vectors * vectors, axis=1))
        if not np.all(np.isfinite(lengths)):
            raise input_error(
                name, "vectors whose length fits in float64 (VTK stores norms)", vectors
            )


def _read_vtp(path: Path) -> Design:
    pv = import_held("pyvista")

    try:
        polydata = pv.read(str(path))
    except Exception as exc:  # VTK readers raise assorted types on bad files
        raise InputError(f"{path}: not a readable VTK file ({exc})") from exc
    fields: Any = polydata.field_data if isinstance(polydata, pv.DataSet) else {}
    if VTP_FIELD in fields:
        text = str(fields[VTP_FIELD][0]) if len(fields[VTP_FIELD]) else ""
    elif VTP_FIELD + UTF8_SUFFIX in fields:
        text = np.asarray(fields[VTP_FIELD + UTF8_SUFFIX], np.uint8).tobytes().decode("utf-8")
    else:
        raise InputError(f"{path}: not a chargedesign export (no field data {VTP_FIELD!r})")
    try:
        header = loads_json(text, f"{path}: field data {VTP_FIELD!r}")
    except IndexError as exc:
        raise InputError(f"{path}: field data {VTP_FIELD!r} is empty") from exc
    elements: dict[str, dict[str, Any]] = {}
    if polydata.n_points:
        points = np.asarray(polydata.points, dtype=np.float64)
        try:
            kind = np.asarray(polydata.point_data["kind"])
            value = np.asarray(polydata.point_data["value"], dtype=np.float64)
            moment = np.asarray(polydata.point_data["moment"], dtype=np.float64)
        except KeyError as exc:
            raise InputError(f"{path}: point data {exc} missing") from exc
        for name, code, second in (
            ("charges", 0, "values"),
            ("masses", 1, "values"),
            ("dipoles", 2, "moments"),
        ):
            rows = kind == code
            elements[name] = {
                "positions": points[rows],
                second: moment[rows] if second == "moments" else value[rows],
            }
    return _from_header(header, elements, str(path))
