"""Safe readers for every file a user hands in: TOML scenes, JSON designs, text and binary
data, point files (``.npy``, ``.csv``, ``.txt``) and meshes (through PyVista).

Each reader refuses, with one line naming the file and the reason (never its content):

- anything but a regular file (a FIFO would block, a device never ends);
- TOML's ``nan`` and ``inf`` are left to the caller's check by key (``check_tree``);
- a file larger than its limit (:data:`MAX_TOML_BYTES`, :data:`MAX_JSON_BYTES`,
  :data:`MAX_DATA_BYTES`);
- bytes that are not UTF-8, and every :class:`OSError` (permissions, I/O errors);
- JSON nested deeper than :data:`MAX_DEPTH` (measured before parsing, so no RecursionError),
  integers with more than 40 digits (refused before conversion), and the non-standard
  constants ``NaN``, ``Infinity`` and ``-Infinity`` or numbers that overflow to them.
"""

from __future__ import annotations

import csv
import io
import json
import os
import re
import stat
import tomllib
import zipfile
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.files import import_held
from chargedesign.formatting import PLAIN, fmt
from chargedesign.validation import (
    as_array,
    as_points,
    check_design_numbers,
    check_input_array,
    input_error,
)
from chargedesign.vocabulary import DESIGN_FORMAT, EXPORT_FORMATS

#: largest scene (TOML) file read, bytes
MAX_TOML_BYTES = 4 * 1024 * 1024
#: largest design.json read, bytes (250 000 elements take about 40 MB)
MAX_JSON_BYTES = 128 * 1024 * 1024
#: largest data file (CSV/NPY points, exports) read, bytes
MAX_DATA_BYTES = 128 * 1024 * 1024
#: deepest nesting of arrays and objects in a JSON or TOML file
MAX_DEPTH = 64
_MAX_INT_DIGITS = 40

_JSON_STRING = re.compile(r'"(?:[^"\\]|\\.)*"', re.DOTALL)
_TOML_SKIP = re.compile(
    r'"""[\s\S]*?"""|\'\'\'[\s\S]*?\'\'\'|"(?:[^"\\\n]|\\.)*"|\'[^\'\n]*\'|#[^\n]*'
)


def _mib(n: int) -> str:
    return f"{fmt(n / (1024 * 1024), PLAIN)} MiB"


def check_input_file(path: str | os.PathLike[str], what: str, limit: int = MAX_DATA_BYTES) -> Path:
    """``path`` is a regular file of at most ``limit`` bytes (for readers that open it
    themselves, e.g. VTK); one-line InputError otherwise."""
    p = Path(path)
    try:
        info = os.stat(p)
    except FileNotFoundError as exc:
        raise InputError(f"{p}: no such {what}") from exc
    except OSError as exc:
        raise InputError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from exc
    if stat.S_ISDIR(info.st_mode):
        raise InputError(f"{p}: is a directory, expected a {what}")
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"{p}: not a regular file (a FIFO, device or socket), expected a {what}")
    if info.st_size > limit:
        raise InputError(f"{p}: the {what} is larger than the {_mib(limit)} limit")
    return p


def read_bytes(path: str | os.PathLike[str], what: str, limit: int = MAX_DATA_BYTES) -> bytes:
    """The bytes of a regular file of at most ``limit`` bytes; one-line InputError otherwise."""
    p = check_input_file(path, what, limit)
    try:
        with open(p, "rb") as handle:
            data = handle.read(limit + 1)
    except OSError as exc:
        raise InputError(f"{p}: cannot read the {what} ({exc.strerror or exc})") from exc
    if len(data) > limit:
        raise InputError(f"{p}: the {what} is larger than the {_mib(limit)} limit")
    return data


def read_text(path: str | os.PathLike[str], what: str, limit: int = MAX_DATA_BYTES) -> str:
    """A UTF-8 text file (see :func:`read_bytes`); undecodable bytes give one line, no content."""
    data = read_bytes(path, what, limit)
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        raise InputError(f"{Path(path)}: the {what} is not UTF-8 text (byte {exc.start})") from exc


def _depth(text: str, pattern: re.Pattern[str]) -> int:
    """Deepest nesting of brackets and braces outside strings (and comments)."""
    stripped = pattern.sub("", text).encode("utf-8", "replace")
    codes = np.frombuffer(stripped, dtype=np.uint8)
    steps = np.zeros(len(codes), dtype=np.int64)
    steps[(codes == ord("[")) | (codes == ord("{"))] = 1
    steps[(codes == ord("]")) | (codes == ord("}"))] = -1
    return int(np.cumsum(steps).max(initial=0))


def loads_json(text: str, where: str) -> Any:
    """Parse JSON text with the limits of this module (depth, integer size, no NaN/inf)."""
    if _depth(text, _JSON_STRING) > MAX_DEPTH:
        raise InputError(f"{where}: JSON nested deeper than {MAX_DEPTH} levels")

    def parse_int(s: str) -> int:
        if len(s.lstrip("-")) > _MAX_INT_DIGITS:
            raise InputError(
                f"{where}: an integer of {len(s.lstrip('-'))} digits (at most "
                f"{_MAX_INT_DIGITS} are read)"
            )
        return int(s)

    def parse_float(s: str) -> float:
        value = float(s)
        if value in (float("inf"), float("-inf")):
            raise InputError(f"{where}: a number overflows a float ({s[:30]})")
        return value

    def parse_constant(s: str) -> Any:
        raise InputError(f"{where}: {s} is not a JSON number (use finite numbers)")

    try:
        return json.loads(
            text, parse_int=parse_int, parse_float=parse_float, parse_constant=parse_constant
        )
    except json.JSONDecodeError as exc:
        raise InputError(f"{where}: not valid JSON ({exc})") from exc
    except RecursionError as exc:  # pragma: no cover - the depth check comes first
        raise InputError(f"{where}: JSON nested too deeply") from exc


def read_json_file(path: str | os.PathLike[str], what: str = "JSON file") -> Any:
    """A JSON file, read safely (size, depth, integer size, no NaN/inf); one-line errors."""
    text = read_text(path, what, MAX_JSON_BYTES)
    return loads_json(text, str(Path(path)))


def loads_toml(text: str, where: str) -> dict[str, Any]:
    """Parse TOML text with a nesting limit (numbers are checked by key afterwards:
    :func:`chargedesign.validation.check_tree`)."""
    if _depth(text, _TOML_SKIP) > MAX_DEPTH:
        raise InputError(f"{where}: TOML nested deeper than {MAX_DEPTH} levels")

    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"{where}: not valid TOML ({exc})") from exc
    except RecursionError as exc:
        raise InputError(f"{where}: TOML nested too deeply") from exc
    except ValueError as exc:  # e.g. an integer beyond Python's digit limit
        if isinstance(exc, InputError):
            raise
        raise InputError(f"{where}: not valid TOML ({type(exc).__name__})") from exc


def read_toml_file(path: str | os.PathLike[str], what: str = "scene file") -> dict[str, Any]:
    """A TOML file, read safely (size, encoding, depth, finite numbers); one-line errors."""
    text = read_text(path, what, MAX_TOML_BYTES)
    return loads_toml(text, str(Path(path)))


def read_point_file(path: str | os.PathLike[str], name: str = "body.path") -> np.ndarray:
    """Points from a ``.npy`` (shape (n, 3)) or ``.csv`` / ``.txt`` file (x, y, z per line).

    Text files may be comma or whitespace separated, with ``#`` comments and one header
    line of names (e.g. ``x,y,z``). The file is read safely (a regular file of at most
    ``MAX_DATA_BYTES``, UTF-8); errors name the file, the line and the reason, never the
    file's content (it may be any file). Bool, complex and object arrays are refused.

    Returns
    -------
    ndarray, shape (n, 3)
    """
    p = Path(path)
    if not os.path.lexists(p):
        raise InputError(f"{name}: no such file {p}")
    suffix = p.suffix.lower()
    if suffix not in (".npy", ".csv", ".txt"):
        raise input_error(name, "a .csv, .txt or .npy file", str(p))
    if suffix == ".npy":
        raw = read_bytes(p, f"point file ({name})")
        try:
            data = np.load(io.BytesIO(raw), allow_pickle=False)
        except (OSError, ValueError, EOFError) as exc:
            raise InputError(
                f"{name}: {p} is not a readable .npy array ({type(exc).__name__})"
            ) from exc
        if not isinstance(data, np.ndarray) or data.dtype.kind not in "iuf":
            kind = getattr(getattr(data, "dtype", None), "name", type(data).__name__)
            raise InputError(f"{name}: {p} holds {kind} values; expected real numbers")
    else:
        data = _read_text_points(p, read_text(p, f"point file ({name})"))
    pts = as_points(data, f"{name} ({p.name})")
    check_input_array(pts, f"{name} ({p.name})")
    return pts


def _read_text_points(path: Path, text: str) -> np.ndarray:
    rows = []
    for number, raw in enumerate(text.splitlines(), start=1):
        line = raw.split("#", 1)[0].strip()
        if not line:
            continue
        fields_ = [f for f in line.replace(",", " ").replace(";", " ").split() if f]
        try:
            rows.append([float(f) for f in fields_])
        except ValueError as exc:
            if not rows and all(not _is_number(f) for f in fields_):
                continue  # a header line of names
            # the line itself is not echoed: the file may be anything
            raise InputError(f"{path}: line {number}: expected three numbers") from exc
        if len(rows[-1]) != 3:
            raise InputError(
                f"{path}: line {number}: expected three numbers, got {len(rows[-1])} fields"
            )
    return np.array(rows, dtype=np.float64).reshape(-1, 3)


def _is_number(text: str) -> bool:
    try:
        float(text)
    except ValueError:
        return False
    return True


def read_mesh(path: Path, name: str = "body.path") -> Any:
    """A mesh file that PyVista can read (a regular file within :data:`MAX_DATA_BYTES`;
    several blocks combined), with at least one point; errors name the file, never its
    content."""

    pv = import_held("pyvista")
    if not path.is_file():
        raise InputError(f"{name}: no such file {path}")
    check_input_file(path, f"mesh file ({name})")
    try:
        mesh = pv.read(path)
    except Exception as exc:  # pyvista/vtk raise many types for unreadable files
        raise InputError(f"{name}: PyVista cannot read {path} ({type(exc).__name__})") from exc
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine()
    if mesh.n_points == 0:
        raise InputError(f"{name}: the mesh {path} has no points")
    return mesh


def read_trajectory(
    source: str | os.PathLike[str] | Mapping[str, Any],
) -> tuple[np.ndarray, np.ndarray]:
    """``t`` (shape (T,), s, nondecreasing) and ``rotation`` (shape (T, 3, 3), body to space)
    from a simulation's ``.npz`` file or a mapping of arrays.

    Rotations must be orthonormal with determinant +1 to 1e-6.
    """
    where = "trajectory"
    if isinstance(source, Mapping):
        data: Mapping[str, Any] = source
    else:
        where = str(source)
        p = Path(source)
        if not p.is_file():
            raise InputError(f"{p}: no such trajectory file")
        if not zipfile.is_zipfile(p):
            raise InputError(f"{p}: not a .npz trajectory file (numpy.savez archive)")
        try:
            with np.load(p, allow_pickle=False) as npz:
                data = {k: npz[k] for k in npz.files}
        except (OSError, ValueError, zipfile.BadZipFile) as exc:
            raise InputError(f"{p}: unreadable .npz trajectory ({exc})") from exc
    for key in ("t", "rotation"):
        if key not in data:
            raise InputError(f"{where}: missing key {key!r} (a simulation's .npz has it)")
    t = as_array(data["t"], f"{where}.t", (None,))
    if len(t) == 0:
        raise input_error(f"{where}.t", "at least one time", t)
    if np.any(np.diff(t) < 0):
        raise input_error(f"{where}.t", "nondecreasing times", t)
    rotation = as_array(data["rotation"], f"{where}.rotation", (len(t), 3, 3))
    gram = np.einsum("tji,tjk->tik", rotation, rotation)
    if not np.allclose(gram, np.eye(3), rtol=0.0, atol=1e-6) or np.any(np.linalg.det(rotation) < 0):
        raise input_error(f"{where}.rotation", "rotation matrices (R^T R = I, det R = +1)", "not")
    return t, rotation


# ---------------------------------------------------------------------------------------------
# exports (:mod:`chargedesign.export` writes them): the format a file name calls for, and the
# CSV, VTP and VTU files read back into design.json's mapping

CSV_COLUMNS = ("kind", "x", "y", "z", "value", "mx", "my", "mz")
#: the columns written: the element columns and the ``design`` column of the header row
CSV_WRITTEN = (*CSV_COLUMNS, "design")
VTP_FIELD = "chargedesign_design"
#: suffix of field data holding text as UTF-8 bytes (``.vtu``, which meshio reads)
UTF8_SUFFIX = "_utf8"
EXPORT_ELEMENT_KEYS = ("charges", "masses", "dipoles")


#: header key of the physical per-element arrays (carrier radii and masses, magnet volumes and
#: masses), in element order; the tables and VTK arrays carry positions and values only
SIZES_KEY = "element_sizes"


def format_from_path(path: str | os.PathLike[str]) -> str:
    """The export format a file name calls for (``.json``, ``.csv``, ``.vtp``, ``.vtu``)."""
    suffix = Path(path).suffix.lower().lstrip(".")
    if suffix not in EXPORT_FORMATS:
        raise input_error(
            f"{path}: format",
            "a file name ending in " + ", ".join("." + f for f in EXPORT_FORMATS),
            suffix,
        )
    return suffix


def resolve_format(fmt: str | None, path: str | os.PathLike[str]) -> str:
    """``fmt`` checked against :data:`EXPORT_FORMATS`, or the format the file name calls for."""
    if fmt is None:
        return format_from_path(path)
    if fmt not in EXPORT_FORMATS:
        raise input_error("format", "one of " + ", ".join(EXPORT_FORMATS), fmt)
    return fmt


def export_mapping(header: Any, elements: dict[str, dict[str, Any]], where: str) -> dict[str, Any]:
    """design.json's mapping from an export's header and element arrays, its numbers checked
    against the input range (:func:`chargedesign.validation.check_design_numbers`)."""
    if not isinstance(header, dict):
        raise input_error(where, "a JSON object describing the design", header)
    header = dict(header)
    sizes = header.pop(SIZES_KEY, None) or {}
    if not isinstance(sizes, dict):
        raise input_error(f"{where}: {SIZES_KEY}", "a JSON object", sizes)
    merged = {block: dict(arrays) for block, arrays in elements.items()}
    for block, arrays in sizes.items():
        if block not in EXPORT_ELEMENT_KEYS or not isinstance(arrays, dict):
            raise input_error(f"{where}: {SIZES_KEY}.{block}", "charges, masses or dipoles", block)
        merged.setdefault(block, {}).update(arrays)
    data = {**header, **merged}
    check_design_numbers(data, where)  # the same input range as design.json
    return data


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


def read_csv_export(path: Path) -> dict[str, Any]:
    """design.json's mapping of a CSV export (the plain form, or the earlier ``# design.KEY``
    comment header)."""
    text = read_text(path, "CSV export")
    refuse_other_kind(path, text_kind(path, text), "design_export")
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
    return export_mapping(header, elements, str(path))


def read_vtk_export(path: Path) -> dict[str, Any]:
    """design.json's mapping of a VTP or VTU export (its field data and point data)."""
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
    return export_mapping(header, elements, str(path))


# ------------------------------------------------------------------ the kinds of file
#: every kind of file the tool writes (and the inputs it reads), as a reader names it; a
#: command meant for one refuses another in one line naming both (:func:`refuse_other_kind`)
FILE_KINDS: dict[str, str] = {
    "design": "a design.json",
    "design_export": "a design export (csv)",
    "testbed": "a testbed.json",
    "simulation": "a simulation summary",
    "ensemble": "an ensemble summary",
    "atlas": "a Poincare atlas summary",
    "check": "a check report",
    "frontier": "a frontier result",
    "sweep": "a sweep summary",
    "bifurcation": "a bifurcation csv",
    "trajectory": "a trajectory.csv",
    "scene": "a scene (TOML)",
    "case": "a case file (TOML)",
    "sweep_file": "a sweep file",
}
#: the ``format`` key of the files that carry one
SWEEP_FORMAT = "chargedesign.sweep/1"


def json_kind(data: Any) -> str | None:
    """The kind (a key of :data:`FILE_KINDS`) of a JSON file's content, None when it names
    none (an old design.json without ``format`` reads on, checked by its keys)."""
    if not isinstance(data, Mapping):
        return None
    keys = set(data)
    form = data.get("format")
    if form == DESIGN_FORMAT:
        return "design"
    if form == SWEEP_FORMAT or {"points", "ran", "failed", "not_run"} <= keys:
        return "sweep"
    if "platform" in keys and keys & {"wheels", "ballast", "control"}:
        return "testbed"
    if "I4_rel_drift" in keys and "effects" in keys:
        return "ensemble" if "trajectories" in keys else "simulation"
    if {"energy", "levels", "orbits"} <= keys:
        return "atlas"
    if "mu_rel_err" in keys and "V_rel_err" in keys:
        return "check"
    if "s_max" in keys and "binding" in keys:
        return "frontier"
    return None


def csv_kind(header: str) -> str | None:
    """The kind of a CSV file from its first row that is not a comment (None: unknown)."""
    cells = [c.strip() for c in header.split(",")]
    if cells[:1] == ["t"] and {"p", "q", "r", "gamma1"} <= set(cells):
        return "trajectory"
    if cells[:4] == ["h", "k", "branch", "type"]:
        return "bifurcation"
    if cells[:1] == ["point"] and "status" in cells:
        return "sweep"
    if cells[:1] == ["kind"]:
        return "design_export"
    return None


def toml_kind(data: Mapping[str, Any]) -> str:
    """The kind of a TOML file's tables: a sweep file, a case file or a scene."""
    if "grid" in data or ("command" in data and "scene" in data):
        return "sweep_file"
    if "case" in data:
        return "case"
    return "scene"


def text_kind(path: str | os.PathLike[str], text: str) -> str | None:
    """The kind of a file that is no JSON: a CSV by its header row, TOML by its tables."""
    suffix = Path(path).suffix.lower()
    lines = [line for line in text.splitlines() if line.strip() and not line.startswith("#")]
    if suffix == ".csv" or (lines and "," in lines[0] and "=" not in lines[0]):
        return csv_kind(lines[0]) if lines else None
    try:
        return toml_kind(tomllib.loads(text))
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        return None


def refuse_other_kind(path: str | os.PathLike[str], found: str | None, expected: str) -> None:
    """One line naming both kinds when a file of one kind is handed to a command meant for
    another: ``sim/summary.json is a simulation summary, not a design.json`` (exit 2)."""
    if found is not None and found != expected:
        raise InputError(f"{path} is {FILE_KINDS[found]}, not {FILE_KINDS[expected]}")


def sniff_kind(path: str | os.PathLike[str]) -> str | None:
    """The kind of the file at ``path`` (None: unreadable or unknown; its reader then says
    why). Reads at most :data:`MAX_TOML_BYTES` of text; a JSON file is parsed whole."""
    p = Path(path)
    try:
        if p.suffix.lower() == ".json":
            return json_kind(read_json_file(p))
        return text_kind(p, read_text(p, "file", MAX_TOML_BYTES))
    except InputError:
        return None
