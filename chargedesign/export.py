"""Export and import a design's geometry: JSON (canonical), CSV (tables), VTK PolyData (.vtp).

- ``stl`` and ``step``: the holder (design.json ``holder``, :mod:`chargedesign.physical.
  holder`), write-only. STL (ASCII, metres: every ``solid`` line says ``units=m``): the
  holder's outer sphere (outward normals) and one closed shell per bore (inward normals), each
  bore a ``solid`` named after its part; each shell's vertices are scaled so that its volume
  is the sphere's, so the mesh encloses exactly the recorded ``volume_m3``; a sidecar
  ``PATH.bores.json`` lists the bores. STEP (ISO 10303-21, millimetres) through build123d, the
  optional extra ``[cad]``: the holder as one solid (the sphere less its bores) and each part
  as a named solid in its bore.
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
from chargedesign.physical.holder import Holder

# the reading half (a user's file: the boundary) and the names both halves use
from chargedesign.readers import (
    CSV_WRITTEN,
    EXPORT_ELEMENT_KEYS,
    MAX_DATA_BYTES,
    SIZES_KEY,
    UTF8_SUFFIX,
    VTP_FIELD,
    check_input_file,
    format_from_path,
    read_csv_export,
    read_vtk_export,
    resolve_format,
)

UNITS = "positions m, charge C, mass kg, dipole moment A m^2"
#: point-data ``kind`` codes of the VTP export
KIND_CODES = {"charge": 0, "mass": 1, "dipole": 2, "continuous charge": 3, "continuous mass": 4}


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
        "stl": _write_stl,
        "step": _write_step,
    }
    if fmt in HOLDER_FORMATS:
        holder = _holder_of(design)
        if fmt == "step":
            _cad_module()  # refused before anything is written
        if fmt == "stl":
            sidecar = target.with_name(target.name + ".bores.json")
            write_file_atomic(sidecar, lambda tmp: _write_bores(holder, tmp))
    write_file_atomic(target, lambda tmp: writers[fmt](design, tmp))
    return target


def import_design(path: str | os.PathLike[str]) -> Design:
    """Read a design from a ``.json``, ``.csv``, ``.vtp`` or ``.vtu`` file written by
    :func:`export_design`, validated whole as ``check`` validates it (its ``case`` record
    too, :func:`check_case_record`).

    The round trip is exact: positions, values and moments come back bit-identical.
    """
    fmt = format_from_path(path)
    if fmt in HOLDER_FORMATS:
        raise InputError(f"{path}: a .{fmt} file holds the holder's shape only; read design.json")
    p = check_input_file(path, "file", MAX_DATA_BYTES)
    if fmt == "json":
        return check_case_record(read_design(p))
    data = read_csv_export(p) if fmt == "csv" else read_vtk_export(p)  # .vtp and .vtu alike
    return check_case_record(Design.from_dict(data, where=str(p)))


def load_any_design(path: str | os.PathLike[str]) -> Design:
    """A design from ``.csv``, ``.vtp`` or ``.vtu`` exports, else from design.json (whatever the
    name), validated whole (:func:`check_case_record`)."""
    if Path(path).suffix.lower() in (".csv", ".vtp", ".vtu"):
        return import_design(path)
    return check_case_record(read_design(path))


def check_case_record(design: Design) -> Design:
    """``design`` once its ``case`` record (when present) passes the validation ``check`` and
    ``simulate`` give it: its ``table`` read again by the case parser, so an export never
    carries a case those commands refuse (an ``__import__`` call in ``V``)."""
    record = design.further_keys.get("case")
    if record is None:
        return design
    if not isinstance(record, dict) or not isinstance(record.get("table"), dict):
        raise InputError("design.case: expected an object with the [case] table under 'table'")
    # sympy is loaded only for a design that carries a case (it stays out of the CLI's start)
    from chargedesign.scene.case_file import case_from_table

    case_from_table(record["table"], "design.case.table")
    return design


# ---------------------------------------------------------------------------------------------
# the holder: stl and step

#: the formats that write the holder (not the design's elements)
HOLDER_FORMATS = ("stl", "step")
#: subdivisions of the icosahedron each sphere of the STL is made of (20 * 4^k facets)
STL_SUBDIVISIONS = 3
#: the optional extra that writes STEP
CAD_EXTRA = "cad"


def _holder_of(design: Design) -> Holder:
    if not design.holder:
        raise InputError(
            "design: no holder in design.json (design it with a [holder] table) to export"
        )
    return Holder.from_record(design.holder)


def icosphere(subdivisions: int = STL_SUBDIVISIONS) -> tuple[np.ndarray, np.ndarray]:
    """Unit-sphere vertices (v, 3) and outward triangles (f, 3) of a subdivided icosahedron."""
    t = (1.0 + 5.0**0.5) / 2.0
    verts = [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
        (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1),
    ]  # fmt: skip
    faces = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
        (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
        (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
    ]  # fmt: skip
    points = [np.array(v, float) / np.linalg.norm(v) for v in verts]
    for _ in range(subdivisions):
        middle: dict[tuple[int, int], int] = {}
        new = []
        for a, b, c in faces:
            ab, bc, ca = (_midpoint(points, middle, i, j) for i, j in ((a, b), (b, c), (c, a)))
            new += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        faces = new
    return np.array(points), np.array(faces, dtype=int)


def _midpoint(points: list[np.ndarray], middle: dict[tuple[int, int], int], i: int, j: int) -> int:
    """The index of the unit vector between points i and j (added once per edge)."""
    key = (min(i, j), max(i, j))
    if key not in middle:
        m = points[i] + points[j]
        points.append(m / np.linalg.norm(m))
        middle[key] = len(points) - 1
    return middle[key]


def _sphere_mesh(centre: np.ndarray, radius: float, inward: bool) -> np.ndarray:
    """Triangles (f, 3, 3) of a sphere whose enclosed volume is exactly ``4/3 pi r^3``."""
    unit, faces = icosphere()
    tri = unit[faces]
    volume = float(np.sum(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])))) / 6
    scale = radius * (4.0 / 3.0 * np.pi / volume) ** (1.0 / 3.0)
    tri = centre + scale * tri
    return tri[:, ::-1] if inward else tri


def _stl_solid(name: str, tri: np.ndarray) -> str:
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    normals /= np.linalg.norm(normals, axis=1)[:, None]
    lines = [f"solid {name}"]
    for n, t in zip(normals, tri, strict=True):
        lines.append(f"  facet normal {n[0]:.9g} {n[1]:.9g} {n[2]:.9g}")
        lines.append("    outer loop")
        lines += [f"      vertex {v[0]:.12g} {v[1]:.12g} {v[2]:.12g}" for v in t]
        lines.append("    endloop")
        lines.append("  endfacet")
    lines.append(f"endsolid {name}")
    return "\n".join(lines) + "\n"


def _part_label(part: str) -> str:
    return part.replace(" ", "_")


def _write_stl(design: Design, path: Path) -> None:
    holder = _holder_of(design)
    text = _stl_solid(
        f"holder units=m material={holder.material} radius_m={holder.radius!r}",
        _sphere_mesh(np.zeros(3), holder.radius, inward=False),
    )
    for centre, radius, part in zip(
        holder.bore_centres, holder.bore_radii, holder.bore_parts, strict=True
    ):
        text += _stl_solid(
            f"bore part={_part_label(part)} units=m radius_m={float(radius)!r}",
            _sphere_mesh(centre, float(radius), inward=True),
        )
    path.write_text(text, encoding="ascii")


def _write_bores(holder: Holder, path: Path) -> None:
    record = {"units": "m", **holder.record()}
    path.write_text(json.dumps(record, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def _cad_module() -> Any:
    """build123d, the optional extra ``[cad]`` (imported here: it is large and optional)."""
    try:
        import build123d
    except ImportError:
        raise InputError(
            f"--format step needs the optional extra: pip install 'chargedesign[{CAD_EXTRA}]' "
            "(build123d)"
        ) from None
    return build123d


def _write_step(design: Design, path: Path) -> None:
    cad = _cad_module()
    holder = _holder_of(design)
    mm = 1e3
    body = cad.Solid.make_sphere(holder.radius * mm)
    parts = []
    for centre, radius, part in zip(
        holder.bore_centres, holder.bore_radii, holder.bore_parts, strict=True
    ):
        sphere = cad.Pos(*(float(x) * mm for x in centre)) * cad.Solid.make_sphere(
            float(radius) * mm
        )
        body = body - sphere
        sphere.label = _part_label(part)
        parts.append(sphere)
    body.label = f"holder_{holder.material}"
    compound = cad.Compound(children=[body, *parts])
    compound.label = "chargedesign_holder"
    cad.export_step(compound, str(path), unit=cad.Unit.MM)


# ---------------------------------------------------------------------------------------------
# json


def _write_json(design: Design, path: Path) -> None:
    path.write_text(
        json.dumps(design.to_dict(), indent=2, allow_nan=False) + "\n", encoding="utf-8"
    )


def _header(design: Design) -> dict[str, Any]:
    """Everything of the design except its elements (parameters, fields, realises, the record),
    plus the physical per-element arrays of a physical design under :data:`SIZES_KEY`."""
    data = design.to_dict()
    out = {k: v for k, v in data.items() if k not in EXPORT_ELEMENT_KEYS}
    sizes = {
        block: {k: v for k, v in data[block].items() if k not in ("positions", "values", "moments")}
        for block in EXPORT_ELEMENT_KEYS
    }
    sizes = {block: keys for block, keys in sizes.items() if keys}
    if sizes:
        out[SIZES_KEY] = sizes
    return out


# ---------------------------------------------------------------------------------------------
# csv


def _write_csv(design: Design, path: Path) -> None:
    header = _header(design)
    header["csv_units"] = UNITS + "; columns kind, x, y, z (m), value (C or kg), mx, my, mz (A m^2)"
    buffer = io.StringIO()
    writer = csv.writer(buffer, lineterminator="\n")
    writer.writerow(CSV_WRITTEN)
    writer.writerow(["design", "", "", "", "", "", "", "", json.dumps(header, allow_nan=False)])
    for kind, positions, values in (
        ("charge", design.charge_positions, design.charge_values),
        ("mass", design.mass_positions, design.mass_values),
    ):
        for position, value in zip(positions, values, strict=True):
            writer.writerow(
                [kind, *map(repr, map(float, position)), repr(float(value)), "", "", "", ""]
            )
    for position, moment in zip(design.dipole_positions, design.dipole_moments, strict=True):
        writer.writerow(
            ["dipole", *map(repr, map(float, position)), "", *map(repr, map(float, moment)), ""]
        )
    path.write_text(buffer.getvalue(), encoding="utf-8")


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
            # a kernel guard: design.json's input range (1e30) keeps every read design's
            # norms finite, so only a Design built in Python reaches it
            raise ValueError(
                f"{name}: expected vectors whose length fits in float64 (VTK stores norms), "
                f"got array of shape {vectors.shape} and dtype {vectors.dtype}"
            )
