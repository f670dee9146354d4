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
from chargedesign.limits import MAX_CANDIDATES as MAX_CANDIDATES
from chargedesign.readers import read_mesh
from chargedesign.readers import read_point_file as read_point_file
from chargedesign.sampling import fibonacci_sphere
from chargedesign.scene.keys import KEY
from chargedesign.scene.tables import RegionSpec, region_from_table
from chargedesign.validation import as_array, as_points, input_error
from chargedesign.vocabulary import BODY_SHAPES

SHAPES = BODY_SHAPES
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


def _point_set(value: Any, name: str) -> np.ndarray:
    """Points given from outside (ndarray, shape (n, 3), m), checked: at least one."""
    points = as_points(value, name)
    if len(points) == 0:
        raise InputError(f"{name}: the set is empty")
    return points


def geometry_of(points: Any, *, spacing: float | None = None) -> Geometry:
    """Shape measures of ``points`` (ndarray, shape (n, 3), m); see :class:`Geometry`.

    ``spacing`` (m), when known (lattices), saves the nearest-neighbour search.
    """
    return _geometry(_point_set(points, "candidates"), spacing)


def _geometry(pts: np.ndarray, spacing: float | None) -> Geometry:
    """:func:`geometry_of` of points already checked (float64, shape (n, 3), n >= 1)."""
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
    sample = None if len(points) <= 20_000 else np.arange(0, len(points), len(points) // 20_000)
    return float(np.median(nearest_distances(points, sample)))


# Up to this many points the nearest neighbours are found by blocks of exact differences in
# numpy, beyond it by scipy's KD-tree. Both compute each distance as the square root of
# (dx^2 + dy^2) + dz^2, so they give the same bits (tests/designer/test_highs_and_neighbours.py).
# Measured (docs/benchmarks.md, "Linear programs without scipy.optimize"): at 257 points the
# blocks take 3 ms, against 0.5 ms for the tree plus 60-160 ms to import scipy.spatial; at
# 2,000 points 95 ms against 2 ms; at 9,765 points 2.2 s against 17 ms.
NEAREST_BY_BLOCKS_MAX = 1024


def nearest_distances(points: np.ndarray, of: np.ndarray | None = None) -> np.ndarray:
    """The distance (m) from each point ``of`` (indices into ``points``; None: every point) to
    its nearest other point of ``points`` (n >= 2): the candidates' cells and spacing."""
    rows_of = np.arange(len(points)) if of is None else np.asarray(of)
    if len(points) > NEAREST_BY_BLOCKS_MAX:
        from scipy.spatial import cKDTree

        dist, _ = cKDTree(points).query(points[rows_of], k=2)
        return np.asarray(dist[:, 1])
    nearest = np.empty(len(rows_of))
    block = max(1, 2**17 // len(points))  # a few MB of differences at a time
    for start in range(0, len(rows_of), block):
        rows = rows_of[start : start + block]
        d2 = np.sum((points[rows][:, None, :] - points[None, :, :]) ** 2, axis=2)
        d2[np.arange(len(rows)), rows] = np.inf  # itself
        nearest[start : start + len(rows)] = np.sqrt(np.min(d2, axis=1))
    return nearest


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
    # counted in floats before any integer is made: a spacing of 1e-30 gives 1e29 lattice
    # steps, which overflowed int64 into one wrong point (issue 32)
    lo_steps = np.ceil((center - half_extent) / spacing - 1e-9)
    hi_steps = np.floor((center + half_extent) / spacing + 1e-9)
    counts = hi_steps - lo_steps + 1
    if np.any(counts <= 0):
        return np.zeros((0, 3))
    if not float(np.prod(counts)) <= 8 * MAX_CANDIDATES:  # a nan count is refused too
        raise input_error(
            "body.spacing", f"a spacing giving at most {MAX_CANDIDATES} candidates", spacing
        )
    lo, hi = lo_steps.astype(np.int64), hi_steps.astype(np.int64)
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
    mesh = read_mesh(p, name)
    if sample == "surface":
        surface = mesh if isinstance(mesh, pv.PolyData) else mesh.extract_surface()
        return unique_points(np.asarray(surface.points, dtype=np.float64) * scale)
    if spacing is None:  # a scene's region is checked for it (region_from_table)
        raise ValueError("mesh_points: sample = 'volume' needs a spacing")
    bounds = np.asarray(mesh.bounds, dtype=np.float64).reshape(3, 2) * scale
    center = bounds.mean(axis=1)
    half = 0.5 * (bounds[:, 1] - bounds[:, 0])

    def inside(d: np.ndarray) -> np.ndarray:
        pts = (d + center) / scale
        if isinstance(mesh, pv.PolyData):
            if not (mesh.n_cells > 0 and _is_closed(mesh)):
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


# --------------------------------------------------------------------------- a region


Shaped = tuple[np.ndarray, dict[str, Any], "dict[str, Any] | None"]


def _lattice_shape(region: RegionSpec, center: np.ndarray) -> Shaped:
    """Points, description and outline of a ball, box or cylinder (lattices through O)."""
    spacing = region.spacing
    assert spacing is not None, "a lattice region has a spacing (region_from_table)"
    if region.shape == "ball":
        radius = region.radius
        assert radius is not None
        desc = {"radius": radius, "spacing": spacing}
        return ball_points(radius, spacing, center), desc, {"shape": "ball", "radius": radius}
    if region.shape == "box":
        half = np.array(region.half_size, dtype=np.float64)
        desc = {KEY.half_size: half.tolist(), "spacing": spacing}
        outline = {"shape": "box", KEY.half_size: desc[KEY.half_size]}
        return box_points(half, spacing, center), desc, outline
    radius, height = region.radius, region.height
    assert radius is not None and height is not None
    desc = {"radius": radius, "height": height, "spacing": spacing}
    outline = {"shape": "cylinder", "radius": radius, "height": height}
    return cylinder_points(radius, height, spacing, center), desc, outline


def _shell_shape(region: RegionSpec, center: np.ndarray) -> Shaped:
    radius, n_points = region.radius, region.n_points
    assert radius is not None and n_points is not None
    desc: dict[str, Any] = {}
    if region.symmetric and region.centred:
        # symmetric by construction: no closure needed (it would not add points)
        pts = shell_points(radius, n_points, symmetric=True)
        desc["symmetric_rule"] = "Fibonacci points of x > y > 0, z > 0 and their 16 images"
    else:
        pts = shell_points(radius, n_points, symmetric=False, center=center)
    desc |= {"radius": radius, KEY.n_points: n_points}
    return pts, desc, {"shape": "shell", "radius": radius}


def _file_shape(region: RegionSpec, center: np.ndarray, base_dir: Any) -> Shaped:
    """Points of a ``points`` file or a ``mesh`` (relative paths against ``base_dir``)."""
    path = Path(str(region.path))
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    desc: dict[str, Any] = {"path": str(path), "scale": region.scale}
    outline: dict[str, Any] | None = {"shape": "points"}
    if region.shape == "points":
        pts = read_point_file(path) * region.scale
    else:
        pts = mesh_points(path, sample=region.sample, spacing=region.spacing, scale=region.scale)
        desc |= {"sample": region.sample}
        if region.spacing is not None:
            desc["spacing"] = region.spacing
        outline = None
    # a file's points are checked where they enter (finite, scaled); the others are built here
    return as_points(pts + center, "candidates"), desc, outline


def candidates_from_region(
    region: RegionSpec, *, base_dir: str | os.PathLike[str] | None = None
) -> CandidateSet:
    """Candidate points of a checked ``[body]`` region (:func:`.region_from_table`).

    Parameters
    ----------
    region : RegionSpec
        The shape and its sizes, m.
    base_dir : path-like, optional
        Directory that a relative ``path`` is resolved against (the scene's folder).

    Returns
    -------
    CandidateSet

    Raises
    ------
    InputError
        A set that is empty or too large for its sizes, or a file that cannot be read.
    """
    center = np.array(region.center, dtype=np.float64)
    if region.shape in ("ball", "box", "cylinder"):
        pts, desc, outline = _lattice_shape(region, center)
    elif region.shape == "shell":
        pts, desc, outline = _shell_shape(region, center)
    else:
        pts, desc, outline = _file_shape(region, center, base_dir)
    if region.symmetric and not region.natural:
        # lattices through O (and the symmetric shell rule) are closed already
        pts = symmetrise(pts)
    return _candidate_set(pts, {"shape": region.shape, **desc}, outline, center, region.symmetric)


def candidates_from_table(
    table: Mapping[str, Any], *, base_dir: str | os.PathLike[str] | None = None
) -> CandidateSet:
    """Candidate points from a scene's ``[body]`` table (keys in docs/design.md): its values
    checked by the scene (:func:`chargedesign.scene.tables.region_from_table`), then
    :func:`candidates_from_region`.

    Raises
    ------
    InputError
        A missing, unknown or malformed key (the message names it), or an empty set.
    """
    return candidates_from_region(region_from_table(table), base_dir=base_dir)


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
    geometry = _geometry(pts, lattice)  # built from checked sizes, or checked on entry
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
    pts = _point_set(points, name)
    geometry = _geometry(pts, None)
    return CandidateSet(
        points=pts,
        description={"shape": "points", "n": len(pts), "geometry": geometry.to_dict()},
        region=None,
        geometry=geometry,
        notes=tuple(planarity_notes(geometry)),
    )
