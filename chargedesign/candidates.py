"""Candidate point sets: where the design stage may place charges, dipoles and masses.

A scene's ``[body]`` table names a shape and its sizes (SI units, m); :func:`candidates_from_table`
turns it into an array of points in body axes (origin O, the fixed point). Lattice shapes
(``ball``, ``box``, ``cylinder``) use the cubic lattice ``spacing * Z^3`` through O, so they are
symmetric about O by construction; ``shell`` uses a Fibonacci rule on the sphere; ``points``
reads a file; ``mesh`` samples a PyVista-readable mesh (surface vertices or interior lattice).

``symmetric = true`` closes the set under the body's natural symmetries about O: the sign
changes ``x -> -x``, ``y -> -y``, ``z -> -z`` and the swap ``x <-> y`` (a group of 16).

:func:`geometry_of` measures how flat a set is (singular values of the centred cloud), so
that a planar or nearly planar set is named rather than silently designed on: moments across
the plane cannot be produced (exactly planar) or need huge weights (nearly planar; the
condition number grows like ``h^-4`` for a slab of half-thickness ``h``).
"""

from __future__ import annotations

import math
import os
from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.errors import InputError
from chargedesign.files import import_held
from chargedesign.formatting import CELL, PRECISE, ROUGH, fmt
from chargedesign.readers import check_input_file, read_bytes, read_text
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene.keys import REGION_KEYS
from chargedesign.scene.tables import check_region_keys
from chargedesign.validation import (
    as_array,
    as_finite_float,
    as_points,
    check_input_array,
    input_error,
)
from chargedesign.vocabulary import BODY_SHAPES

SHAPES = BODY_SHAPES
#: keys each shape accepts (besides ``shape``): the scene's declaration
SHAPE_KEYS: dict[str, tuple[str, ...]] = REGION_KEYS
#: a [body] region's key check (the scene's)
check_body_keys = check_region_keys
#: refuse sets larger than this (the condition matrices are dense, rows x points: 250 000
#: points and 40 conditions take 80 MB per copy)
MAX_CANDIDATES = 250_000
#: relative thickness (smallest / largest singular value of the centred cloud) below which a
#: set is called planar (exactly, up to rounding) ...
PLANAR_RATIO = 1e-9
#: ... and below which it is called nearly planar (a warning: moments across the plane are
#: weak, the weights needed grow like thickness^-2 or faster)
NEARLY_PLANAR_RATIO = 1e-2
#: points closer than this (relative to the set's size) are merged when symmetrising
_MERGE_RTOL = 1e-9


@dataclass(frozen=True)
class Geometry:
    """Shape measures of a point cloud.

    Attributes
    ----------
    size : float
        Largest distance of a point from O, m (the length scale of the design problem).
    centroid : ndarray, shape (3,)
        Mean of the points, m.
    singular_values : ndarray, shape (3,)
        RMS extents of the centred cloud along its principal directions (descending), m.
    directions : ndarray, shape (3, 3)
        Rows: the principal directions (unit vectors), matching ``singular_values``.
    spacing : float
        Median nearest-neighbour distance, m (0 for a single point).
    """

    size: float
    centroid: np.ndarray
    singular_values: np.ndarray
    directions: np.ndarray
    spacing: float

    @property
    def thickness_ratio(self) -> float:
        """Smallest over largest RMS extent (0: planar; 1: round)."""
        top = float(self.singular_values[0])
        return float(self.singular_values[2]) / top if top > 0 else 0.0

    @property
    def dimension(self) -> int:
        """0 (one point), 1 (a line), 2 (a plane) or 3: extents above PLANAR_RATIO * largest."""
        top = float(self.singular_values[0])
        if top <= PLANAR_RATIO * max(self.size, 1e-300):
            return 0
        return int(np.sum(self.singular_values > PLANAR_RATIO * top))

    def plane_text(self) -> str:
        """The plane (or line or point) the set lies in, e.g. ``"the plane z = 0"``."""
        c = self.centroid
        if self.dimension == 0:
            return (
                f"the single point ({fmt(c[0], PRECISE)}, {fmt(c[1], PRECISE)},"
                f" {fmt(c[2], PRECISE)}) m"
            )
        if self.dimension == 1:
            d = self.directions[0]
            return (
                f"the line through ({fmt(c[0], PRECISE)}, {fmt(c[1], PRECISE)},"
                f" {fmt(c[2], PRECISE)}) m along "
                f"({fmt(d[0])}, {fmt(d[1])}, {fmt(d[2])})"
            )
        normal = self.directions[2]
        offset = float(normal @ c)
        axis = int(np.argmax(np.abs(normal)))
        if abs(abs(normal[axis]) - 1.0) < 1e-9:
            value = offset * math.copysign(1.0, normal[axis])
            value = 0.0 if abs(value) <= 1e-12 * max(self.size, 1e-300) else value
            return f"the plane {'xyz'[axis]} = {fmt(value, CELL)}"
        if offset < 0:
            normal, offset = -normal, -offset
        terms = " + ".join(f"{fmt(v)} {a}" for v, a in zip(normal, "xyz", strict=True) if v != 0)
        return f"the plane {terms} = {fmt(offset, PRECISE)}"

    def to_dict(self) -> dict[str, Any]:
        return {
            "size_m": self.size,
            "spacing_m": self.spacing,
            "thickness_ratio": self.thickness_ratio,
            "rms_extents_m": self.singular_values.tolist(),
        }


@dataclass(frozen=True)
class CandidateSet:
    """Candidate positions and what they are.

    Attributes
    ----------
    points : ndarray, shape (n, 3)
        Positions in body axes, m.
    description : dict
        The validated ``[body]`` keys plus the count (JSON-ready).
    region : dict or None
        The region outline for pictures (``shape`` ball/shell/box/cylinder/points, sizes in m;
        None for meshes).
    geometry : Geometry
    notes : tuple of str
        Warnings, e.g. a nearly planar set.
    """

    points: np.ndarray
    description: dict[str, Any]
    region: dict[str, Any] | None
    geometry: Geometry
    notes: tuple[str, ...] = field(default_factory=tuple)

    def __len__(self) -> int:
        return len(self.points)


# --------------------------------------------------------------------------- geometry


def geometry_of(points: Any, *, spacing: float | None = None) -> Geometry:
    """Shape measures of ``points`` (ndarray, shape (n, 3), m); see :class:`Geometry`.

    ``spacing`` (m), when known (lattices), saves the nearest-neighbour search.
    """
    pts = as_points(points, "candidates")
    if len(pts) == 0:
        raise InputError("candidates: the set is empty")
    size = float(np.max(np.linalg.norm(pts, axis=1)))
    centroid = pts.mean(axis=0)
    centred = pts - centroid
    # SVD of the (n, 3) cloud, not an eigen-decomposition of its scatter matrix: the scatter
    # matrix squares the thickness ratio and would blur planar (1e-16) with thin (1e-8)
    _, s, vt = np.linalg.svd(centred / math.sqrt(len(pts)), full_matrices=False)
    singular = np.zeros(3)
    singular[: len(s)] = s
    directions = np.eye(3)
    directions[: len(vt)] = vt
    return Geometry(
        size=size,
        centroid=centroid,
        singular_values=singular,
        directions=directions,
        spacing=_median_spacing(pts) if spacing is None else float(spacing),
    )


def _median_spacing(points: np.ndarray) -> float:
    if len(points) < 2:
        return 0.0
    from scipy.spatial import cKDTree

    sample = points if len(points) <= 20_000 else points[:: len(points) // 20_000]
    dist, _ = cKDTree(points).query(sample, k=2)
    return float(np.median(dist[:, 1]))


def planarity_notes(geometry: Geometry) -> list[str]:
    """Warnings for degenerate sets (empty list for a well-spread cloud)."""
    if geometry.dimension < 3:
        return [f"candidates all lie in {geometry.plane_text()}"]
    ratio = geometry.thickness_ratio
    if ratio < NEARLY_PLANAR_RATIO:
        return [
            f"candidates are nearly planar (thickness / width = {fmt(ratio, ROUGH)}, close to "
            f"{geometry.plane_text()}): moments across that plane need weights growing like "
            "(width / thickness)^2 or faster"
        ]
    return []


# --------------------------------------------------------------------------- symmetry


def symmetry_images(points: np.ndarray) -> np.ndarray:
    """All 16 images of ``points`` (n, 3) under sign changes of x, y, z and the swap x <-> y.

    Returns
    -------
    ndarray, shape (16 n, 3)
    """
    images = []
    for swap in (False, True):
        base = points[:, [1, 0, 2]] if swap else points
        for sx in (1.0, -1.0):
            for sy in (1.0, -1.0):
                for sz in (1.0, -1.0):
                    images.append(base * np.array([sx, sy, sz]))
    return np.concatenate(images)


def unique_points(points: np.ndarray, rtol: float = _MERGE_RTOL) -> np.ndarray:
    """``points`` with near-duplicates (closer than ``rtol`` times the set's size) merged.

    The first of each cluster is kept; the result is sorted lexicographically (z, y, x) so
    that equal sets give equal arrays.
    """
    if len(points) == 0:
        return points
    scale = max(float(np.max(np.abs(points))), 1e-300)
    keys = np.round(points / (rtol * scale)).astype(np.int64)
    # lexsort + neighbour comparison: much faster than np.unique(axis=0) on 10^6 rows
    order = np.lexsort((keys[:, 0], keys[:, 1], keys[:, 2]))
    sorted_keys = keys[order]
    new = np.ones(len(order), dtype=bool)
    new[1:] = np.any(sorted_keys[1:] != sorted_keys[:-1], axis=1)
    return points[order[new]]


def symmetrise(points: np.ndarray) -> np.ndarray:
    """The union of the 16 symmetry images of ``points`` (near-duplicates merged)."""
    return unique_points(symmetry_images(points))


# --------------------------------------------------------------------------- shapes


def lattice_in(
    inside: Any, half_extent: np.ndarray, spacing: float, center: np.ndarray
) -> np.ndarray:
    """Points of the lattice ``spacing * Z^3`` (through O) with ``inside(points - center)``.

    Parameters
    ----------
    inside : callable
        ``inside(offsets) -> ndarray of bool`` for offsets (k, 3) from ``center``, m.
    half_extent : ndarray, shape (3,)
        Half-widths of a box around ``center`` that contains the shape, m.
    spacing : float
        Lattice spacing, m.
    center : ndarray, shape (3,)
        Shape centre, m.
    """
    lo = np.ceil((center - half_extent) / spacing - 1e-9).astype(np.int64)
    hi = np.floor((center + half_extent) / spacing + 1e-9).astype(np.int64)
    counts = hi - lo + 1
    if np.any(counts <= 0):
        return np.zeros((0, 3))
    total = int(np.prod(counts.astype(np.float64)))
    if total > 8 * MAX_CANDIDATES:
        raise input_error(
            "body.spacing",
            f"a spacing giving at most {MAX_CANDIDATES} candidates",
            spacing,
        )
    axes = [np.arange(lo[i], hi[i] + 1) * spacing for i in range(3)]
    grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return grid[inside(grid - center)]


def ball_points(radius: float, spacing: float, center: Any = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Lattice points in the closed ball ``|r - center| <= radius`` (all in m).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    c = as_array(center, "center", (3,))
    tol = 1e-9 * radius

    def inside(d: np.ndarray) -> np.ndarray:
        return np.einsum("ij,ij->i", d, d) <= (radius + tol) ** 2

    return lattice_in(inside, np.full(3, radius), spacing, c)


def box_points(half_size: Any, spacing: float, center: Any = (0.0, 0.0, 0.0)) -> np.ndarray:
    """Lattice points in the box ``|r_i - center_i| <= half_size_i`` (all in m).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    half = np.broadcast_to(np.asarray(half_size, dtype=np.float64), (3,)).copy()
    c = as_array(center, "center", (3,))
    tol = 1e-9 * float(np.max(half))

    def inside(d: np.ndarray) -> np.ndarray:
        return np.all(np.abs(d) <= half + tol, axis=1)

    return lattice_in(inside, half, spacing, c)


def cylinder_points(
    radius: float, height: float, spacing: float, center: Any = (0.0, 0.0, 0.0)
) -> np.ndarray:
    """Lattice points in the cylinder along body z: ``rho <= radius``, ``|z| <= height / 2``.

    Returns
    -------
    ndarray, shape (n, 3)
    """
    c = as_array(center, "center", (3,))
    tol = 1e-9 * max(radius, height)

    def inside(d: np.ndarray) -> np.ndarray:
        rho2 = d[:, 0] ** 2 + d[:, 1] ** 2
        return (rho2 <= (radius + tol) ** 2) & (np.abs(d[:, 2]) <= 0.5 * height + tol)

    return lattice_in(inside, np.array([radius, radius, 0.5 * height]), spacing, c)


def shell_points(
    radius: float, n_points: int, *, symmetric: bool = True, center: Any = (0.0, 0.0, 0.0)
) -> np.ndarray:
    """About ``n_points`` points on the sphere ``|r - center| = radius`` (m).

    ``symmetric=True`` keeps the Fibonacci points strictly inside the fundamental domain
    ``x > y > 0, z > 0`` of the 16 symmetries and adds their images, so the count is a
    multiple of 16 close to ``n_points``; otherwise the plain Fibonacci rule.

    Returns
    -------
    ndarray, shape (k, 3)
    """
    c = as_array(center, "center", (3,))
    if symmetric:
        base = fibonacci_sphere(n_points)
        keep = (base[:, 0] > base[:, 1]) & (base[:, 1] > 0) & (base[:, 2] > 0)
        base = base[keep]
        if len(base) == 0:
            base = np.array([[0.8, 0.36, 0.48]])  # one point inside the fundamental domain
            base /= np.linalg.norm(base)
        unit = symmetry_images(base)
    else:
        unit = fibonacci_sphere(n_points)
    return c + radius * unit


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
    import io

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


def mesh_points(
    path: str | os.PathLike[str],
    *,
    sample: str = "surface",
    spacing: float | None = None,
    scale: float = 1.0,
    name: str = "body.path",
) -> np.ndarray:
    """Candidate points from a mesh file that PyVista can read (units: ``scale`` m per unit).

    Parameters
    ----------
    path : path-like
        Surface (``.stl``, ``.vtp``, ``.obj``, ``.ply``, ...) or volume (``.vtu``, ...) mesh.
    sample : {"surface", "volume"}
        ``surface``: the vertices of the mesh's outer surface. ``volume``: the lattice points
        (``spacing``) inside the mesh (a closed surface, or the cells of a volume mesh).
    spacing : float, optional
        Lattice spacing for ``volume``, m (required there).
    scale : float
        Metres per mesh unit.

    Returns
    -------
    ndarray, shape (n, 3)
    """

    pv = import_held("pyvista")

    p = Path(path)
    if not p.is_file():
        raise InputError(f"{name}: no such file {p}")
    check_input_file(p, f"mesh file ({name})")
    try:
        mesh = pv.read(p)
    except Exception as exc:  # pyvista/vtk raise many types for unreadable files
        raise InputError(f"{name}: PyVista cannot read {p} ({type(exc).__name__})") from exc
    if isinstance(mesh, pv.MultiBlock):
        mesh = mesh.combine()
    if mesh.n_points == 0:
        raise InputError(f"{name}: the mesh {p} has no points")
    if sample == "surface":
        surface = mesh if isinstance(mesh, pv.PolyData) else mesh.extract_surface()
        return unique_points(np.asarray(surface.points, dtype=np.float64) * scale)
    if spacing is None:
        raise InputError("body.spacing: required for sample = 'volume'")
    bounds = np.asarray(mesh.bounds, dtype=np.float64).reshape(3, 2) * scale
    center = bounds.mean(axis=1)
    half = 0.5 * (bounds[:, 1] - bounds[:, 0])

    def inside(d: np.ndarray) -> np.ndarray:
        pts = (d + center) / scale
        if isinstance(mesh, pv.PolyData):
            if mesh.n_cells == 0 or not _is_closed(mesh):
                raise InputError(
                    f"{name}: the surface in {p} is not closed; its interior is undefined "
                    "(use sample = 'surface')"
                )
            probe = pv.PolyData(pts)
            if hasattr(probe, "select_interior_points"):  # pyvista >= 0.47
                marked = probe.select_interior_points(mesh, check_surface=False)
                return np.asarray(marked["selected_points"], dtype=bool)
            marked = probe.select_enclosed_points(mesh, check_surface=False)
            return np.asarray(marked["SelectedPoints"], dtype=bool)
        return np.asarray(mesh.find_containing_cell(pts)) >= 0

    return lattice_in(inside, half, spacing, center)


def _is_closed(surface: Any) -> bool:
    edges = surface.extract_feature_edges(
        boundary_edges=True, non_manifold_edges=True, feature_edges=False, manifold_edges=False
    )
    return bool(edges.n_cells == 0)


# --------------------------------------------------------------------------- the table


def _number(table: Mapping[str, Any], key: str, *, default: Any = None) -> float:
    value = table.get(key, default)
    if value is None:
        raise InputError(f"body.{key}: required for shape = {table.get('shape')!r}")
    return as_finite_float(value, f"body.{key}", positive=True)


def _vector3(table: Mapping[str, Any], key: str, *, positive: bool) -> np.ndarray:
    value = table[key]
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        out = np.full(3, as_finite_float(value, f"body.{key}", positive=positive))
    else:
        out = as_array(value, f"body.{key}", (3,))
        if positive and np.any(out <= 0):
            raise input_error(f"body.{key}", "three numbers > 0", value)
    return out


def _bool(table: Mapping[str, Any], key: str, default: bool) -> bool:
    value = table.get(key, default)
    if not isinstance(value, bool):
        raise input_error(f"body.{key}", "true or false", value)
    return value


Shaped = tuple[np.ndarray, dict[str, Any], "dict[str, Any] | None"]


def _lattice_shape(table: Mapping[str, Any], shape: str, center: np.ndarray) -> Shaped:
    """Points, description and region of a ball, box or cylinder (lattices through O)."""
    if shape == "ball":
        radius = _number(table, "radius")
        spacing = _number(table, "spacing", default=radius / 4.0)
        desc = {"radius": radius, "spacing": spacing}
        return ball_points(radius, spacing, center), desc, {"shape": "ball", "radius": radius}
    if shape == "box":
        if "half_size" in table and "size" in table:
            raise InputError("body.size: give either half_size or size, not both")
        if "half_size" in table:
            half = _vector3(table, "half_size", positive=True)
        elif "size" in table:
            half = 0.5 * _vector3(table, "size", positive=True)
        else:
            raise InputError("body.half_size: required for shape = 'box' (or give size)")
        spacing = _number(table, "spacing", default=float(np.min(half)) / 2.0)
        desc = {"half_size": half.tolist(), "spacing": spacing}
        return (
            box_points(half, spacing, center),
            desc,
            {"shape": "box", "half_size": desc["half_size"]},
        )
    radius = _number(table, "radius")
    height = _number(table, "height")
    spacing = _number(table, "spacing", default=min(radius, 0.5 * height) / 4.0)
    desc = {"radius": radius, "height": height, "spacing": spacing}
    region = {"shape": "cylinder", "radius": radius, "height": height}
    return cylinder_points(radius, height, spacing, center), desc, region


def _shell_shape(
    table: Mapping[str, Any], center: np.ndarray, symmetric: bool, centred: bool
) -> Shaped:
    radius = _number(table, "radius")
    n_raw = table.get("n_points", 200)
    if isinstance(n_raw, bool) or not isinstance(n_raw, int) or not 4 <= n_raw <= MAX_CANDIDATES:
        raise input_error("body.n_points", f"an integer in 4..{MAX_CANDIDATES}", n_raw)
    desc: dict[str, Any] = {}
    if symmetric and centred:
        # symmetric by construction: no closure needed (it would not add points)
        pts = shell_points(radius, n_raw, symmetric=True)
        desc["symmetric_rule"] = "Fibonacci points of x > y > 0, z > 0 and their 16 images"
    else:
        pts = shell_points(radius, n_raw, symmetric=False, center=center)
    desc |= {"radius": radius, "n_points": n_raw}
    return pts, desc, {"shape": "shell", "radius": radius}


def _file_shape(table: Mapping[str, Any], shape: str, center: np.ndarray, base_dir: Any) -> Shaped:
    """Points of a ``points`` file or a ``mesh`` (relative paths against ``base_dir``)."""
    raw = table.get("path")
    if not isinstance(raw, str) or not raw:
        raise input_error("body.path", "a file name (string)", raw)
    path = Path(raw)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    scale = _number(table, "scale", default=1.0)
    desc: dict[str, Any] = {"path": str(path), "scale": scale}
    if shape == "points":
        return read_point_file(path) * scale + center, desc, {"shape": "points"}
    sample = table.get("sample", "surface")
    if sample not in ("surface", "volume"):
        raise input_error("body.sample", "'surface' or 'volume'", sample)
    spacing_m = _number(table, "spacing") if "spacing" in table else None
    if sample == "volume" and spacing_m is None:
        raise InputError("body.spacing: required for shape = 'mesh', sample = 'volume'")
    pts = mesh_points(path, sample=sample, spacing=spacing_m, scale=scale)
    desc |= {"sample": sample}
    if spacing_m is not None:
        desc["spacing"] = spacing_m
    return pts + center, desc, None


def _shape_of(table: Any) -> str:
    """The region's shape (``ball`` when a table gives sizes only), checked."""
    if not isinstance(table, Mapping):
        raise input_error("body", "a table with key 'shape'", table)
    shape = table.get("shape", "ball" if table else None)
    if shape is None:
        raise InputError(
            "body: the scene has no [body] table; give one with shape = "
            + " | ".join(SHAPES)
            + " (where the design may place elements)"
        )
    if shape not in SHAPES:
        raise input_error("body.shape", "one of " + ", ".join(SHAPES), shape)
    check_body_keys(table)
    return str(shape)


def _naturally_symmetric(table: Mapping[str, Any], shape: str, centred: bool) -> bool:
    """Whether the shape's own rule is closed under the symmetries already (then
    ``symmetric`` defaults on). Lattices through O are, unless a box's |x| and |y| sizes
    differ (closing under x <-> y would add points outside it)."""
    if shape == "box" and centred:
        half_xy = table.get("half_size", table.get("size"))
        return not isinstance(half_xy, (list, tuple)) or (
            len(half_xy) == 3 and half_xy[0] == half_xy[1]
        )
    return centred and shape in ("ball", "cylinder", "shell")


def candidates_from_table(
    table: Mapping[str, Any], *, base_dir: str | os.PathLike[str] | None = None
) -> CandidateSet:
    """Candidate points from a scene's ``[body]`` table (keys in docs/design.md).

    Parameters
    ----------
    table : mapping
        ``shape`` (ball | box | cylinder | shell | points | mesh) and its keys; lengths in m.
    base_dir : path-like, optional
        Directory that relative ``path`` keys are resolved against (the scene's folder).

    Returns
    -------
    CandidateSet

    Raises
    ------
    InputError
        A missing, unknown or malformed key (the message names it), or an empty set.
    """
    shape = _shape_of(table)
    center = _vector3(table, "center", positive=False) if "center" in table else np.zeros(3)
    centred = not np.any(center)
    natural = _naturally_symmetric(table, shape, centred)
    symmetric = _bool(table, "symmetric", natural)
    if shape in ("ball", "box", "cylinder"):
        pts, desc, region = _lattice_shape(table, shape, center)
    elif shape == "shell":
        pts, desc, region = _shell_shape(table, center, symmetric, centred)
    else:
        pts, desc, region = _file_shape(table, shape, center, base_dir)
    if symmetric and not natural:
        # lattices through O (and the symmetric shell rule) are closed already
        pts = symmetrise(pts)
    return _candidate_set(pts, {"shape": shape, **desc}, region, center, symmetric)


def _candidate_set(
    pts: np.ndarray,
    desc: dict[str, Any],
    region: dict[str, Any] | None,
    center: np.ndarray,
    symmetric: bool,
) -> CandidateSet:
    """The set of a shape's points: size checked, geometry measured, planarity named."""
    shape = desc["shape"]
    if len(pts) == 0:
        raise InputError(f"body: shape {shape!r} with these sizes holds no candidate point")
    if len(pts) > MAX_CANDIDATES:
        raise input_error(
            "body", f"at most {MAX_CANDIDATES} candidates (a coarser spacing)", len(pts)
        )
    pts = np.ascontiguousarray(pts, dtype=np.float64)
    lattice = desc.get("spacing") if shape in ("ball", "box", "cylinder") else None
    geometry = geometry_of(pts, spacing=lattice)
    if np.any(center):
        desc["center"] = center.tolist()
        if region is not None:
            region["center"] = center.tolist()
    desc |= {"symmetric": symmetric, "n": len(pts)}
    desc["geometry"] = geometry.to_dict()
    return CandidateSet(
        points=pts,
        description=desc,
        region=region,
        geometry=geometry,
        notes=tuple(planarity_notes(geometry)),
    )


def candidates_from_points(points: Any, name: str = "candidates") -> CandidateSet:
    """Wrap an array of points (n, 3), m, as a :class:`CandidateSet`."""
    pts = as_points(points, name)
    if len(pts) == 0:
        raise InputError(f"{name}: the set is empty")
    geometry = geometry_of(pts)
    return CandidateSet(
        points=pts,
        description={"shape": "points", "n": len(pts), "geometry": geometry.to_dict()},
        region=None,
        geometry=geometry,
        notes=tuple(planarity_notes(geometry)),
    )
