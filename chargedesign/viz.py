"""3-D pictures of a designed body with PyVista: a still image, a window, an animation.

What is drawn (see docs/visualisation.md):

- charges as spheres coloured by their value on a blue-white-red scale (blue negative, red
  positive, white zero; a scalar bar in C), sphere volume proportional to ``|q|``;
- masses as grey spheres, volume proportional to the mass;
- dipoles as green arrows centred on their positions, length proportional to ``|sigma|``;
- the candidate region's outline (wireframe) and any continuous bodies (translucent meshes);
- the body axes ``x, y, z`` (dark grey arrows, labelled) and the field axis: space ``Z`` as
  ``gamma`` in body axes (gold arrow, labelled ``Z (field)``);
- a legend listing only the kinds of element present.

Still images are drawn in the body frame. :func:`animate` draws the space frame instead: the
field axis ``Z`` stands still and the body turns, ``X = R(t) r``.

Rendering is off screen for files. On Linux without a display, VTK is pointed at its EGL
render window when the EGL library is installed (``VTK_DEFAULT_OPENGL_WINDOW``, unless the
user set it); otherwise VTK picks its own fallback (OSMesa).
"""

from __future__ import annotations

import ctypes.util
import math
import os
import sys
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Protocol

import numpy as np

from chargedesign.elements import ElementSet
from chargedesign.files import check_output_path, deferred_signals, write_file_atomic
from chargedesign.formatting import PLAIN, PRECISE, fmt
from chargedesign.physical.materials import sphere_radius
from chargedesign.results import png_bytes, png_html
from chargedesign.scene.keys import KEY

with deferred_signals():
    # VTK's modules, rendering included (``pyvista.Plotter`` loads them), load with SIGINT
    # and SIGTERM held: a signal inside their C++ initialisation crashed the interpreter
    # (a segfault, seen when `chargedesign design` was terminated as it began its picture)
    import pyvista as pv
    from pyvista import Plotter as _Plotter  # noqa: F401
from chargedesign.limits import MAX_SHOW_ELEMENTS
from chargedesign.quadrature import ContinuousBody
from chargedesign.readers import read_trajectory
from chargedesign.validation import as_array, as_finite_float, input_error


class DrawnDesign(Protocol):
    """What the pictures read of a design: :class:`chargedesign.body.Design` is one.

    The body module draws through this one (``Design.plot``, ``Design.to_pyvista``, the
    notebook picture), so this module names the members it reads and imports no design
    module: its elements (:class:`~chargedesign.elements.ElementSet`'s arrays, SI units, body
    axes), the continuous bodies and the candidate region the design records.
    """

    @property
    def charge_positions(self) -> np.ndarray: ...
    @property
    def charge_values(self) -> np.ndarray: ...
    @property
    def dipole_positions(self) -> np.ndarray: ...
    @property
    def dipole_moments(self) -> np.ndarray: ...
    @property
    def mass_positions(self) -> np.ndarray: ...
    @property
    def mass_values(self) -> np.ndarray: ...
    @property
    def n_elements(self) -> int: ...
    @property
    def continuous(self) -> Sequence[ContinuousBody]: ...
    @property
    def region(self) -> Mapping[str, Any] | None: ...
    @property
    def further_keys(self) -> Mapping[str, Any]: ...
    def carrier_radii(self) -> np.ndarray: ...
    def magnet_volumes(self) -> np.ndarray: ...
    def point_elements(self) -> ElementSet: ...


# Colours: element kinds never share a hue, so a picture can be checked for them.
POSITIVE_COLOR = (1.0, 0.0, 0.0)
NEGATIVE_COLOR = (0.0, 0.0, 1.0)
MASS_COLOR = (0.55, 0.55, 0.55)
DIPOLE_COLOR = (0.13, 0.55, 0.13)
FIELD_COLOR = (0.85, 0.65, 0.13)
AXES_COLOR = (0.25, 0.25, 0.25)
REGION_COLOR = (0.62, 0.62, 0.62)
BACKGROUND_COLOR = (1.0, 1.0, 1.0)

REGION_SHAPES = ("ball", "shell", "box", "cylinder", "points")

_SPHERE_FRACTION = 0.07  # largest element sphere radius, as a fraction of the body's size
_MIN_SPHERE_FRACTION = 0.018  # smallest drawn radius, so tiny elements stay visible
_ARROW_FRACTION = 0.35  # largest dipole arrow length, as a fraction of the body's size
_BODY_AXIS_FRACTION = 1.25
_FIELD_AXIS_FRACTION = 1.5
MAX_WINDOW = 8192
_MAX_FRAMES = 5000


# ---------------------------------------------------------------------------------------------
# inputs


def _misuse(name: str, expected: str, received: Any) -> ValueError:
    """A caller's error in the one error template's words: a ValueError, not an InputError
    (the command line checks what a user gives first, commands/show.py)."""
    return ValueError(str(input_error(name, expected, received)))


#: why no window opens (the command line says so before drawing, commands/show.py)
NO_DISPLAY = (
    "no display to open a window on ($DISPLAY and $WAYLAND_DISPLAY are unset); "
    "render to a file with --screenshot PNG"
)


def window_size_ok(value: Any) -> bool:
    """Two integers (width, height) in 16..MAX_WINDOW."""
    return (
        isinstance(value, (tuple, list))
        and len(value) == 2
        and all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in value)
        and all(16 <= int(v) <= MAX_WINDOW for v in value)
    )


#: what a window size must be, in the error's words
WINDOW_SIZE_EXPECTED = f"two integers (width, height) in 16..{MAX_WINDOW}"
#: the picture and animation files each kind of output takes
SCREENSHOT_SUFFIXES = (".png",)
ANIMATION_SUFFIXES = (".gif", ".mp4")


def _window_size(value: Any) -> tuple[int, int]:
    if not window_size_ok(value):
        raise _misuse("window_size", WINDOW_SIZE_EXPECTED, value)
    return int(value[0]), int(value[1])


def _unit_gamma(gamma: Any) -> np.ndarray:
    g = as_array((0.0, 0.0, 1.0) if gamma is None else gamma, "gamma", (3,))
    norm = float(np.linalg.norm(g))
    if norm == 0.0:
        raise _misuse("gamma", "a non-zero vector", gamma)
    return g / norm


def _region_spec(region: Any) -> dict[str, Any] | None:
    """Validate a candidate region (the scene's ``[body]`` table); None draws no outline."""
    if region is None:
        return None
    if not isinstance(region, Mapping):
        raise _misuse("region", "a table with key 'shape'", region)
    shape = region.get("shape")
    if shape not in REGION_SHAPES:
        raise _misuse("region.shape", "one of " + ", ".join(REGION_SHAPES), shape)
    return dict(region)


def region_from_design(design: DrawnDesign) -> dict[str, Any] | None:
    """The candidate region recorded in a design (design.json ``region``, or ``body`` in older
    files), if any."""
    for value in (design.region, design.further_keys.get("body")):
        if isinstance(value, Mapping) and value.get("shape") in REGION_SHAPES:
            return dict(value)
    return None


def _center(spec: Mapping[str, Any], where: str) -> np.ndarray:
    return as_array(spec.get("center", (0.0, 0.0, 0.0)), f"{where}.center", (3,))


def _half_sizes(value: Any, where: str) -> np.ndarray:
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        half = np.full(3, as_finite_float(value, where, positive=True))
    else:
        half = as_array(value, where, (3,))
    if np.any(half <= 0):
        raise _misuse(where, "half sizes > 0", value)
    return half


# ---------------------------------------------------------------------------------------------
# geometry


def region_mesh(region: Mapping[str, Any] | None) -> pv.PolyData | None:
    """Outline of a candidate region as line cells (None for no region or ``points``).

    Parameters
    ----------
    region : mapping or None
        The scene's ``[body]`` table: ``ball``/``shell`` with ``radius``, ``box`` with
        ``half_size`` (number or 3 numbers), ``cylinder`` with ``radius`` and ``height`` (along
        body ``z``, centred on ``center``, default O). Lengths in m.
    """
    spec = _region_spec(region)
    if spec is None or spec["shape"] == "points":
        return None
    shape = spec["shape"]
    center = _center(spec, "region")
    if shape in ("ball", "shell"):
        radius = as_finite_float(spec.get("radius"), "region.radius", positive=True)
        # three great circles and two parallels at z = +-r/2 (lighter than a full wireframe)
        circles = [_circle(center, np.eye(3)[i], radius) for i in range(3)]
        for z in (-0.5 * radius, 0.5 * radius):
            circles.append(
                _circle(center + np.array([0.0, 0.0, z]), np.eye(3)[2], math.sqrt(radius**2 - z**2))
            )
        return pv.merge(circles)
    if shape == "box":
        half = _half_sizes(spec.get(KEY.half_size), "region.half_size")
        lo, hi = center - half, center + half
        return pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2])).extract_feature_edges()
    radius = as_finite_float(spec.get("radius"), "region.radius", positive=True)
    height = as_finite_float(spec.get("height"), "region.height", positive=True)
    cylinder = pv.Cylinder(
        center=center, direction=(0.0, 0.0, 1.0), radius=radius, height=height, resolution=32
    )
    return cylinder.extract_feature_edges(feature_angle=20.0)


def continuous_body_mesh(body: ContinuousBody) -> pv.PolyData:
    """Triangulated surface of one continuous body (ball, shell, cylinder along z, box), m."""
    center = np.asarray(body.center, dtype=np.float64)
    if body.shape in ("ball", "shell"):
        mesh = pv.Sphere(
            radius=float(body.radius),  # type: ignore[arg-type]
            center=center,
            theta_resolution=32,
            phi_resolution=16,
        )
    elif body.shape == "cylinder":
        mesh = pv.Cylinder(
            center=center,
            direction=(0.0, 0.0, 1.0),
            radius=float(body.radius),  # type: ignore[arg-type]
            height=float(body.height),  # type: ignore[arg-type]
            resolution=48,
        )
    else:
        lo = center - np.asarray(body.half_size)
        hi = center + np.asarray(body.half_size)
        mesh = pv.Box(bounds=(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2]))
    return mesh.triangulate()


def continuous_body_color(body: ContinuousBody, mesh: pv.PolyData) -> Any:
    """Grey for mass; for charge red or blue when the density on the surface has one sign."""
    if body.kind == "mass":
        return MASS_COLOR
    density = body.density.evaluate(np.asarray(mesh.points, dtype=np.float64))
    if np.all(density > 0):
        return POSITIVE_COLOR
    if np.all(density < 0):
        return NEGATIVE_COLOR
    return "orchid"  # mixed signs (or zero): neither red nor blue


def _body_size(design: DrawnDesign, region: Mapping[str, Any] | None) -> float:
    """Characteristic length L of the picture, m: farthest element or region point from O."""
    sizes = [0.0]
    for points in (design.charge_positions, design.mass_positions, design.dipole_positions):
        if len(points):
            sizes.append(float(np.max(np.linalg.norm(points, axis=1))))
    meshes = [continuous_body_mesh(body) for body in design.continuous]
    outline = region_mesh(region)
    if outline is not None:
        meshes.append(outline)
    for mesh in meshes:
        if mesh.n_points:
            sizes.append(float(np.max(np.linalg.norm(mesh.points, axis=1))))
    size = max(sizes)
    return size if size > 0.0 else 1.0


def _sphere_radii(values: np.ndarray, size: float) -> np.ndarray:
    """Radii whose volumes grow like |value|, the largest ``_SPHERE_FRACTION * size``."""
    magnitude = np.abs(values)
    top = float(magnitude.max()) if len(magnitude) else 0.0
    relative = np.cbrt(magnitude / top) if top > 0 else np.zeros_like(magnitude)
    return size * np.maximum(_SPHERE_FRACTION * relative, _MIN_SPHERE_FRACTION)


def _toward_white(color: tuple[float, float, float], weight: float) -> tuple[float, float, float]:
    """``color`` at ``weight`` 1, white at 0."""
    r, g, b = (weight * c + (1.0 - weight) for c in color)
    return (r, g, b)


#: lightest tint of a non-zero charge (0: white), so a near-zero charge still shows its sign and
#: never looks like a grey mass
CHARGE_TINT_FLOOR = 0.3


def _tint(q: float, top: float) -> float:
    """Colour weight of a charge: ``CHARGE_TINT_FLOOR`` near 0, 1 at ``|q| = top``."""
    return CHARGE_TINT_FLOOR + (1.0 - CHARGE_TINT_FLOOR) * min(abs(q) / top, 1.0)


#: a charge below this fraction of the largest is round-off: drawn without a sign colour
ROUND_OFF_CHARGE = 1e-9


def significant_charges(values: Any) -> np.ndarray:
    """The charges with round-off (``|q| < ROUND_OFF_CHARGE max|q|``) set to 0: a 1e-12 C
    charge beside 1e-9 C ones carries no sign worth a colour."""
    q = np.asarray(values, dtype=np.float64)
    top = float(np.max(np.abs(q))) if q.size else 0.0
    return np.where(np.abs(q) < ROUND_OFF_CHARGE * top, 0.0, q)


def charge_colors(values: np.ndarray, top: float | None = None) -> np.ndarray:
    """RGB colour of each charge (shape (n, 3), 0..1): blue below 0, red above, white at 0
    (and at round-off, :func:`significant_charges`).

    Exact in the sign (a colour lookup table's bins could give a tiny charge the colour of
    the other sign); the weight is :func:`_tint`, as in :func:`charge_colormap`.
    """
    q = np.asarray(values, dtype=np.float64)
    if top is None:
        top = float(np.max(np.abs(q))) if q.size else 0.0
    q = np.where(np.abs(q) < ROUND_OFF_CHARGE * top, 0.0, q)
    out = np.ones((q.size, 3))
    if top <= 0.0:
        return out
    for i, v in enumerate(q):
        if v != 0.0:
            out[i] = _toward_white(POSITIVE_COLOR if v > 0 else NEGATIVE_COLOR, _tint(v, top))
    return out


def charge_colormap(values: np.ndarray) -> tuple[Any, tuple[float, float]]:
    """A diverging map over the values' range: blue negative, red positive, by sign first.

    The colour is linear in ``q`` from the lightest tint (``CHARGE_TINT_FLOOR`` of the full
    colour, at ``q -> 0``) to the full colour at ``+-max|q|``; the map breaks at 0 (light blue
    below, light red above), so the smallest charge still shows its sign. An absent sign draws
    no hue (the colour range is cut to ``[min(q, 0), max(q, 0)]``); all-zero charges are white.
    """
    from matplotlib.colors import LinearSegmentedColormap

    lo, hi = min(float(values.min()), 0.0), max(float(values.max()), 0.0)
    top = max(-lo, hi)
    if top == 0.0:  # all charges zero: white only
        white = [(0.0, BACKGROUND_COLOR), (1.0, BACKGROUND_COLOR)]
        return LinearSegmentedColormap.from_list("chargedesign_charge", white), (-1.0, 1.0)
    stops: list[tuple[float, tuple[float, float, float]]] = []
    if lo < 0:
        stops.append((lo, _toward_white(NEGATIVE_COLOR, _tint(lo, top))))
        stops.append((0.0, _toward_white(NEGATIVE_COLOR, CHARGE_TINT_FLOOR)))
    if hi > 0:
        stops.append((0.0, _toward_white(POSITIVE_COLOR, CHARGE_TINT_FLOOR)))
        stops.append((hi, _toward_white(POSITIVE_COLOR, _tint(hi, top))))
    nodes = [((v - lo) / (hi - lo), c) for v, c in stops]
    return LinearSegmentedColormap.from_list("chargedesign_charge", nodes), (lo, hi)


def _arrow(
    start: np.ndarray, vector: np.ndarray, shaft: float = 0.012, tip: float = 0.04
) -> pv.PolyData:
    """Arrow from ``start`` along ``vector``; ``shaft`` and ``tip`` radii relative to its length."""
    length = float(np.linalg.norm(vector))
    return pv.Arrow(
        start=start,
        direction=vector / length,
        scale=length,
        tip_length=0.12,
        tip_radius=tip,
        shaft_radius=shaft,
    )


def _circle(center: np.ndarray, normal: np.ndarray, radius: float, n: int = 72) -> pv.PolyData:
    """Closed polyline circle."""
    normal = normal / np.linalg.norm(normal)
    helper = np.array([1.0, 0.0, 0.0]) if abs(normal[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    u = np.cross(normal, helper)
    u /= np.linalg.norm(u)
    v = np.cross(normal, u)
    angles = np.linspace(0.0, 2.0 * np.pi, n, endpoint=False)
    points = center + radius * (np.outer(np.cos(angles), u) + np.outer(np.sin(angles), v))
    return pv.lines_from_points(points, close=True)


# ---------------------------------------------------------------------------------------------
# scene building


@dataclass
class _BodyActors:
    """Actors fixed to the body (moved together by the animation) and the axis label tips."""

    actors: list[Any]
    axis_tips: np.ndarray  # shape (3, 3): tips of the body axes x, y, z, body frame
    size: float
    blocks: Any = None  # the design_blocks drawn


def _nice_length(target: float) -> float:
    """A round length (1, 2 or 5 times a power of ten) at most ``target``, m."""
    if target <= 0 or not math.isfinite(target):
        return 1.0
    power = 10.0 ** math.floor(math.log10(target))
    for step in (5.0, 2.0, 1.0):
        if step * power <= target:
            return step * power
    return power


def _covering(point: np.ndarray, centres: np.ndarray, radii: np.ndarray) -> float:
    """Farthest reach from ``point`` of the spheres that contain it (0 when none does)."""
    if len(centres) == 0:
        return 0.0
    distance = np.linalg.norm(centres - point, axis=1)
    inside = distance <= radii * (1.0 + 1e-9)
    return float(np.max(distance[inside] + radii[inside])) if np.any(inside) else 0.0


def _labelled(mesh: pv.PolyData, data: Mapping[str, Any]) -> pv.PolyData:
    """``mesh`` with each ``data`` value as field data and as a constant point array."""
    for name, value in data.items():
        arr = np.atleast_1d(np.asarray(value, dtype=np.float64))
        mesh.field_data[name] = arr
        if arr.size == 1:
            mesh.point_data[name] = np.full(mesh.n_points, float(arr[0]))
    return mesh


def element_sizes(design: DrawnDesign, size: float) -> dict[str, Any]:
    """Drawn radii and how they were chosen, per kind of element (m).

    Carriers with a radius (``charges.radii``) are drawn at it; the others by ``|q|`` (sphere
    volume proportional to ``|q|``, the largest ``_SPHERE_FRACTION`` of the body's size).
    Ballast masses by their mass likewise; magnets with a volume as the sphere of that volume.
    """
    q = design.charge_values
    radii = design.carrier_radii()
    by_value = _sphere_radii(q, size) if len(q) else np.zeros(0)
    real = radii > 0
    charges = np.where(real, radii, by_value)
    masses = _sphere_radii(design.mass_values, size) if len(design.mass_values) else np.zeros(0)
    volumes = design.magnet_volumes()
    magnets = sphere_radius(volumes)
    if len(q) and np.all(real):
        charge_key = "carriers at their real radius"
    elif np.any(real):
        charge_key = "carriers with a radius at it, others: volume ~ charge magnitude"
    else:
        charge_key = "sphere volume ~ charge magnitude"
    return {
        "charges": charges,
        "masses": masses,
        "magnets": magnets,
        "charge_key": charge_key,
    }


def _sphere(center: np.ndarray, radius: float, resolution: int) -> pv.PolyData:
    """A sphere mesh of ``resolution`` in theta and phi."""
    return pv.Sphere(
        radius=float(radius),
        center=np.asarray(center, dtype=np.float64),
        theta_resolution=resolution,
        phi_resolution=resolution,
    )


def _sphere_blocks(
    design: DrawnDesign, sizes: Mapping[str, Any], out: pv.MultiBlock, resolution: int
) -> tuple[np.ndarray, np.ndarray]:
    """Add the charges', masses' and magnets' spheres to ``out``; their centres and radii."""
    spheres_c: list[np.ndarray] = []
    spheres_r: list[np.ndarray] = []
    kinds = (
        ("charges", "charge", "charge (C)", design.charge_positions, design.charge_values),
        ("masses", "mass", "mass (kg)", design.mass_positions, design.mass_values),
    )
    for block_name, element, label, positions, values in kinds:
        if not len(values):
            continue
        block = pv.MultiBlock()
        for i, (pos, value, r) in enumerate(zip(positions, values, sizes[block_name], strict=True)):
            mesh = _sphere(pos, r, resolution)
            block[f"{element} {i}"] = _labelled(mesh, {label: value, "radius (m)": r})
        out[block_name] = block
        spheres_c.append(positions)
        spheres_r.append(sizes[block_name])
    magnets = sizes["magnets"]
    if np.any(magnets > 0):
        block = pv.MultiBlock()
        for i, (pos, r) in enumerate(zip(design.dipole_positions, magnets, strict=True)):
            if r > 0:
                block[f"magnet {i}"] = _labelled(_sphere(pos, r, resolution), {"radius (m)": r})
        out["magnets"] = block
        spheres_c.append(design.dipole_positions[magnets > 0])
        spheres_r.append(magnets[magnets > 0])
    centres = np.concatenate(spheres_c) if spheres_c else np.zeros((0, 3))
    radii = np.concatenate(spheres_r) if spheres_r else np.zeros(0)
    return centres, radii


def _dipole_block(
    design: DrawnDesign, size: float, centres: np.ndarray, radii: np.ndarray, resolution: int
) -> pv.MultiBlock:
    """An arrow per dipole along its moment, sticking out of every sphere around its centre."""
    moments = design.dipole_moments
    strengths = np.linalg.norm(moments, axis=1)
    top = float(strengths.max())
    block = pv.MultiBlock()
    for i, (pos, moment, strength) in enumerate(
        zip(design.dipole_positions, moments, strengths, strict=True)
    ):
        data = {"moment (A m^2)": moment}
        if strength == 0.0:  # no direction: a small marker
            marker = _sphere(pos, _MIN_SPHERE_FRACTION * size, resolution)
            block[f"dipole {i}"] = _labelled(marker, data)
            continue
        half = max(
            0.5 * _ARROW_FRACTION * size * strength / top,
            1.35 * _covering(pos, centres, radii),
            _MIN_SPHERE_FRACTION * size * 2.0,
        )
        unit = moment / strength
        mesh = _arrow(pos - half * unit, 2.0 * half * unit, shaft=0.03, tip=0.08)
        block[f"dipole {i}"] = _labelled(mesh, data)
    return block


def _continuous_block(design: DrawnDesign) -> pv.MultiBlock:
    """The continuous bodies' surfaces, one mesh each."""
    block = pv.MultiBlock()
    for i, body in enumerate(design.continuous):
        block[f"{body.kind} {body.shape} {i}"] = continuous_body_mesh(body)
    return block


def _scale_bar(size: float, length: float) -> pv.PolyData:
    """A line of ``length`` below a body of ``size`` (field data ``length (m)``)."""
    y, z = -1.15 * size, -1.0 * size
    bar = pv.Line((-0.5 * length, y, z), (0.5 * length, y, z))
    bar.field_data["length (m)"] = np.array([length])
    return bar


def _block_legend(out: pv.MultiBlock, charge_key: str, length: float) -> list[str]:
    """One line per kind of block present: its colour and what its size means."""
    legend = []
    if "charges" in out.keys():
        legend.append(f"charges: red > 0, blue < 0 (diverging, by sign); {charge_key}")
    if "masses" in out.keys():
        legend.append("masses: translucent grey; volume ~ mass")
    if "magnets" in out.keys():
        legend.append("magnets: translucent green; the sphere of the magnet's volume")
    if "dipoles" in out.keys():
        legend.append("dipoles: green arrows along the moment, sticking out of any sphere")
    legend.append(f"scale bar: {fmt(length, PLAIN)} m")
    return legend


def design_blocks(
    design: DrawnDesign,
    *,
    region: Mapping[str, Any] | None = None,
    resolution: int = 16,
) -> pv.MultiBlock:
    """The body as a ``pyvista.MultiBlock`` in body axes (m), one mesh per element.

    Blocks (present only when the design has such elements):

    - ``charges``: a sphere per charge (named ``charge 0``, ...): its carrier's real radius
      (``charges.radii``) when given, else sized by ``|q|``; field and point data
      ``charge (C)``, field data ``radius (m)``;
    - ``dipoles``: an arrow per dipole along its moment, centred on it, long enough to stick
      out of every sphere that contains its centre; field data ``moment (A m^2)``;
    - ``magnets``: a sphere of each magnet's volume (``dipoles.volumes``, when given);
    - ``masses``: a sphere per ballast mass, sized by its mass; ``mass (kg)``;
    - ``continuous``: the continuous bodies' surfaces;
    - ``region``: the candidate region's outline (argument, else recorded in the design);
    - ``scale_bar``: a line of a round length (field data ``length (m)``) below the body.

    The MultiBlock's field data: ``size (m)`` (the body's size used for drawn sizes),
    ``legend`` (one line per kind present: its colour and what its size means).

    Parameters
    ----------
    design : Design
    region : mapping, optional
        The scene's ``[body]`` table; default: the one recorded in the design.
    resolution : int
        Sphere resolution (theta and phi).
    """
    region = _region_spec(region_from_design(design) if region is None else region)
    size = _body_size(design, region)
    sizes = element_sizes(design, size)
    out = pv.MultiBlock()
    out.field_data["size (m)"] = np.array([size])
    centres, radii = _sphere_blocks(design, sizes, out, resolution)
    if len(design.dipole_moments):
        out["dipoles"] = _dipole_block(design, size, centres, radii, resolution)
    if design.continuous:
        out["continuous"] = _continuous_block(design)
    outline = region_mesh(region)
    if outline is not None:
        out["region"] = outline
    length = _nice_length(0.5 * size)
    out.field_data["legend"] = _block_legend(out, sizes["charge_key"], length)
    out["scale_bar"] = _scale_bar(size, length)
    return out


def _combined(block: Any) -> pv.PolyData:
    """One mesh of a block's meshes (their point data kept)."""
    return pv.merge([block[i] for i in range(len(block))])


def _size_key(design: DrawnDesign, size: float) -> str:
    """One line telling what the drawn sizes mean."""
    parts = []
    q = design.charge_values
    if len(q):
        key = element_sizes(design, size)["charge_key"]
        parts.append(f"charges: {key} (largest {fmt(np.max(np.abs(q)))} C)")
    if len(design.mass_values):
        parts.append(f"masses: volume ~ mass (largest {fmt(np.max(design.mass_values))} kg)")
    if len(design.dipole_moments):
        top = float(np.max(np.linalg.norm(design.dipole_moments, axis=1)))
        parts.append(f"arrows: direction of sigma (largest {fmt(top)} A m^2)")
    return "; ".join(parts)


def _add_body(
    plotter: pv.Plotter,
    design: DrawnDesign,
    region: Mapping[str, Any] | None,
    *,
    sphere_resolution: int,
    scalar_bar: bool,
) -> tuple[_BodyActors, list[list[Any]]]:
    """Draw the body-fixed parts (from :func:`design_blocks`); return actors and legend."""
    blocks: Any = design_blocks(design, region=region, resolution=sphere_resolution)
    size = float(blocks.field_data["size (m)"][0])
    actors: list[Any] = []
    legend: list[list[Any]] = []
    names = set(blocks.keys())

    if "charges" in names:
        q = design.charge_values
        spheres = _combined(blocks["charges"])
        top = float(np.max(np.abs(q)))
        spheres.point_data["rgb"] = (
            255.0 * charge_colors(spheres.point_data["charge (C)"], top)
        ).astype(np.uint8)
        actors.append(plotter.add_mesh(spheres, scalars="rgb", rgb=True, smooth_shading=True))
        signed = significant_charges(q)  # round-off gets no sign in the map nor the legend
        cmap, clim = charge_colormap(signed)
        # the colour bar comes from an invisible copy mapped through the colour map
        actors.append(
            plotter.add_mesh(
                pv.PolyData(np.asarray(design.charge_positions, dtype=np.float64)),
                scalars=np.asarray(q, dtype=np.float64),
                cmap=cmap,
                clim=clim,
                opacity=0.0,
                show_scalar_bar=scalar_bar,
                scalar_bar_args={
                    "title": "charge (C)",
                    "color": "black",
                    "vertical": True,
                    "position_x": 0.84,
                    "position_y": 0.06,
                    "height": 0.45,
                    "width": 0.06,
                    "title_font_size": _font_size(plotter),
                    "label_font_size": _font_size(plotter),
                    "fmt": "%.2g",
                    "n_labels": 3,
                },
                render_points_as_spheres=False,
                point_size=0.0,
            )
        )
        if np.any(signed > 0):
            legend.append(["charge > 0", POSITIVE_COLOR, "circle"])
        if np.any(signed < 0):
            legend.append(["charge < 0", NEGATIVE_COLOR, "circle"])

    if "masses" in names:
        # translucent, so the dipoles and charges inside or behind them stay visible
        actors.append(
            plotter.add_mesh(
                _combined(blocks["masses"]),
                color=MASS_COLOR,
                opacity=0.35,
                smooth_shading=True,
            )
        )
        legend.append(["mass", MASS_COLOR, "circle"])

    if "magnets" in names:
        actors.append(
            plotter.add_mesh(
                _combined(blocks["magnets"]), color=DIPOLE_COLOR, opacity=0.3, smooth_shading=True
            )
        )
    if "dipoles" in names:
        actors.append(plotter.add_mesh(_combined(blocks["dipoles"]), color=DIPOLE_COLOR))
        legend.append(["dipole", DIPOLE_COLOR, "triangle"])

    for continuous in design.continuous:
        mesh = continuous_body_mesh(continuous)
        color = continuous_body_color(continuous, mesh)
        actors.append(plotter.add_mesh(mesh, color=color, opacity=0.3, smooth_shading=True))
    if design.continuous:
        legend.append(["continuous body", REGION_COLOR, "rectangle"])

    if "region" in names:
        actors.append(plotter.add_mesh(blocks["region"], color=REGION_COLOR, line_width=1.0))
        legend.append(["candidate region", REGION_COLOR, "rectangle"])

    tips = _BODY_AXIS_FRACTION * size * np.eye(3)
    axes = pv.merge([_arrow(np.zeros(3), tip) for tip in tips])
    actors.append(plotter.add_mesh(axes, color=AXES_COLOR))
    legend.append(["body axes", AXES_COLOR, "triangle"])
    return _BodyActors(actors=actors, axis_tips=tips, size=size, blocks=blocks), legend


def _add_scale_bar(plotter: pv.Plotter, blocks: Any) -> None:
    """The scale bar (a black line of a round length) and its label."""
    bar: Any = blocks["scale_bar"]
    length = float(bar.field_data["length (m)"][0])
    plotter.add_mesh(bar, color="black", line_width=3.0)
    _add_labels(
        plotter, [np.mean(bar.points, axis=0)], [f"{fmt(length, PLAIN)} m"], "scale_bar", "black"
    )


def _add_labels(
    plotter: pv.Plotter, points: Any, labels: Sequence[str], name: str, color: Any
) -> None:
    plotter.add_point_labels(
        np.asarray(points, dtype=np.float64),
        list(labels),
        name=name,
        show_points=False,
        shape=None,
        text_color=color,
        font_size=14,
        bold=True,
        always_visible=True,
        reset_camera=False,
    )


def caption_counts(design: DrawnDesign) -> str:
    """The picture's counts, as ``chargedesign check`` counts them: every mass of the body
    (carriers, magnets and ballast; the title once said 160 masses where check counted 208),
    the ballast among them."""
    masses = len(design.point_elements().mass_values)  # massless carriers left out, as check
    ballast = len(design.mass_values)
    mass_text = f"{masses} masses" + (f" ({ballast} ballast)" if ballast != masses else "")
    return f"{len(design.charge_values)} charges, {mass_text}, {len(design.dipole_moments)} dipoles"


def _caption_size(plotter: pv.Plotter) -> int:
    """The caption's size in points: legible at the default 1024 x 768 (once 9 points, about
    8 pixels high)."""
    return max(10, int(plotter.window_size[1]) // 60)


def _font_size(plotter: pv.Plotter) -> int:
    """Text size in points that suits the window height."""
    return max(8, int(plotter.window_size[1]) // 40)


def _add_legend(plotter: pv.Plotter, entries: list[list[Any]]) -> None:
    plotter.add_legend(  # type: ignore[call-arg]  # pyvista decorator confuses mypy
        labels=entries,
        bcolor=BACKGROUND_COLOR,
        border=True,
        size=(0.22, 0.035 * len(entries) + 0.01),
        loc="lower left",
    )


def _place_camera(plotter: pv.Plotter, size: float, direction: Sequence[float]) -> None:
    """A fixed camera looking at O from ``direction``, ``view up`` along z, fitting 1.9 L."""
    d = np.asarray(direction, dtype=np.float64)
    d /= np.linalg.norm(d)
    camera = plotter.camera
    distance = 1.9 * size / math.sin(math.radians(camera.view_angle) / 2.0)
    camera.focal_point = (0.0, 0.0, 0.0)
    camera.position = tuple(distance * d)
    camera.up = (0.0, 0.0, 1.0)
    plotter.reset_camera_clipping_range()


_VIEW_DIRECTION = (1.0, -1.6, 0.9)


def too_many_elements(design: DrawnDesign, max_elements: int | None = None) -> str | None:
    """Why a design has more elements than the cap drawn (each is a mesh; 200 000 take
    minutes), or None."""
    cap = MAX_SHOW_ELEMENTS if max_elements is None else int(max_elements)
    if design.n_elements > cap:
        return (
            f"the design has {design.n_elements} elements, more than the {cap} drawn at most "
            "(chargedesign.limits.MAX_SHOW_ELEMENTS; show --max-elements N raises it)"
        )
    return None


def check_element_count(design: DrawnDesign, max_elements: int | None = None) -> None:
    """Refuse to draw more elements than the cap (a caller's error: ``show`` checks first)."""
    problem = too_many_elements(design, max_elements)
    if problem is not None:
        raise ValueError(problem)


def _use_offscreen_backend() -> None:
    """Without a display on Linux, ask VTK for its EGL window (avoids a failed X attempt)."""
    if (
        sys.platform.startswith("linux")
        and not _has_display()
        and "VTK_DEFAULT_OPENGL_WINDOW" not in os.environ
        and ctypes.util.find_library("EGL")
    ):
        os.environ["VTK_DEFAULT_OPENGL_WINDOW"] = "vtkEGLRenderWindow"


def display_available() -> bool:
    """A window can open: a display, and PyVista not forced off screen."""
    return _has_display() and not pv.OFF_SCREEN


def mp4_missing(target: Path) -> str:
    """Why an MP4 cannot be written without imageio-ffmpeg."""
    return f"{target}: MP4 needs the imageio-ffmpeg package; write a .gif instead"


def _has_display() -> bool:
    if not sys.platform.startswith("linux"):
        return True
    return bool(os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY"))


def _draw_scene(
    plotter: pv.Plotter,
    design: DrawnDesign,
    *,
    region: Mapping[str, Any] | None,
    gamma: Any,
    sphere_resolution: int = 16,
    legend: bool = True,
    scalar_bar: bool = True,
    scale_bar: bool = True,
    camera: bool = True,
) -> _BodyActors:
    """Draw the body in its own frame with the field axis along ``gamma`` into ``plotter``."""
    g = _unit_gamma(gamma)
    region = _region_spec(region)
    body, entries = _add_body(
        plotter, design, region, sphere_resolution=sphere_resolution, scalar_bar=scalar_bar
    )
    size = body.size
    field_tip = _FIELD_AXIS_FRACTION * size * g
    plotter.add_mesh(_arrow(-field_tip, 2.0 * field_tip, shaft=0.004, tip=0.02), color=FIELD_COLOR)
    entries.append(["field axis Z", FIELD_COLOR, "triangle"])
    _add_labels(plotter, body.axis_tips * 1.06, ("x", "y", "z"), "body_axes", AXES_COLOR)
    _add_labels(plotter, [field_tip * 1.04], ["Z (field)"], "field_axis", FIELD_COLOR)
    if scale_bar:
        _add_scale_bar(plotter, body.blocks)
    if legend:
        _add_legend(plotter, entries)
    key = _size_key(design, size)
    plotter.add_text(
        caption_counts(design)
        + f"; gamma = ({fmt(g[0])}, {fmt(g[1])}, {fmt(g[2])})"
        + ("".join(f"\n{part}" for part in key.split("; ")) if key else ""),
        position="upper_left",
        font_size=_caption_size(plotter),
        color="black",
        name="caption",
    )
    if camera:
        _place_camera(plotter, size, _VIEW_DIRECTION)
    return body


def _body_plotter(
    design: DrawnDesign,
    *,
    region: Mapping[str, Any] | None,
    gamma: Any,
    window_size: tuple[int, int],
    off_screen: bool,
) -> pv.Plotter:
    """A plotter showing the body in its own frame with the field axis along ``gamma``."""
    _unit_gamma(gamma)
    _region_spec(region)
    if off_screen:
        _use_offscreen_backend()
    plotter = pv.Plotter(off_screen=off_screen, window_size=list(window_size))
    plotter.background_color = pv.Color(BACKGROUND_COLOR)
    try:
        _draw_scene(plotter, design, region=region, gamma=gamma)
    except BaseException:
        plotter.close()
        raise
    return plotter


def in_notebook() -> bool:
    """True inside a Jupyter kernel (IPython with a kernel attached)."""
    ipython = sys.modules.get("IPython")
    if ipython is None:
        return False
    try:
        shell = ipython.get_ipython()
    except Exception:
        return False
    return shell is not None and "IPKernelApp" in getattr(shell, "config", {})


def notebook_backend(backend: str | None = None) -> str:
    """Choose and set PyVista's Jupyter backend; return its name.

    ``trame`` when the trame packages are installed and a display (or EGL/OSMesa off-screen
    rendering) is available, else ``static`` (a still image rendered off screen: works with
    no display and no extra packages). ``backend`` forces one.
    """
    if backend is None:
        import importlib.util

        has_trame = all(
            importlib.util.find_spec(name) is not None for name in ("trame", "trame_vtk")
        )
        backend = "trame" if has_trame and _has_display() else "static"
    if backend == "static" or not _has_display():
        _use_offscreen_backend()
    pv.set_jupyter_backend(backend)
    return backend


def plot_design(
    design: DrawnDesign,
    plotter: pv.Plotter | None = None,
    *,
    region: Mapping[str, Any] | None = None,
    gamma: Any = None,
    show: bool | None = None,
    window_size: tuple[int, int] = (1024, 768),
    legend: bool = True,
    scalar_bar: bool = True,
    scale_bar: bool = True,
    jupyter_backend: str | None = None,
) -> pv.Plotter:
    """Draw the body into a PyVista plotter (a new one when ``plotter`` is None).

    Parameters
    ----------
    design : Design
    plotter : pyvista.Plotter, optional
        Draw into this plotter (its camera is left alone; the caller shows it). None: a new
        plotter (off screen without a display; in Jupyter with :func:`notebook_backend`) that
        is shown unless ``show=False``.
    region : mapping, optional
        Candidate region to outline; default: the one recorded in the design.
    gamma : array_like, shape (3,), optional
        Field axis (space ``Z``) in body axes, default ``(0, 0, 1)``.
    show : bool, optional
        Call ``plotter.show()`` (default: only for a plotter made here, and only where it can
        be seen: in a notebook or with a display).
    window_size : (int, int)
        Size of a new plotter, pixels.
    legend, scalar_bar, scale_bar : bool
        Draw the legend, the charge colour bar, the length scale bar.
    jupyter_backend : str, optional
        PyVista Jupyter backend (``static``, ``trame``, ...); default :func:`notebook_backend`.

    Returns
    -------
    pyvista.Plotter
    """
    _unit_gamma(gamma)
    if region is None:
        region = region_from_design(design)
    _region_spec(region)
    own = plotter is None
    notebook = own and in_notebook()
    if plotter is None:
        size = _window_size(window_size)
        off_screen = not _has_display() or bool(pv.OFF_SCREEN)
        if notebook:
            jupyter_backend = notebook_backend(jupyter_backend)
            off_screen = off_screen or jupyter_backend == "static"
        elif off_screen:
            _use_offscreen_backend()
        plotter = pv.Plotter(off_screen=off_screen, notebook=notebook, window_size=list(size))
        plotter.background_color = pv.Color(BACKGROUND_COLOR)
    _draw_scene(
        plotter,
        design,
        region=region,
        gamma=gamma,
        legend=legend,
        scalar_bar=scalar_bar,
        scale_bar=scale_bar,
        camera=own,
    )
    if show is None:
        show = own and (notebook or (_has_display() and not pv.OFF_SCREEN))
    if show:
        if notebook:
            plotter.show(jupyter_backend=jupyter_backend)
        else:
            plotter.show()
    return plotter


class Picture(np.ndarray):
    """An RGB image (ndarray, shape (height, width, 3), uint8) that notebooks display.

    A plain ``numpy.ndarray`` in every other respect; :meth:`save` writes it as PNG.
    """

    def _repr_png_(self) -> bytes:
        return png_bytes(np.asarray(self))

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the picture as PNG (atomically); returns the path."""
        import imageio.v3 as iio

        target = Path(path)
        if target.suffix.lower() != ".png":
            raise _misuse("picture path", "a file name ending in .png", str(target))
        image = np.asarray(self)
        write_file_atomic(target, lambda tmp: iio.imwrite(tmp, image, extension=".png"))
        return target


# ---------------------------------------------------------------------------------------------
# public API


def render_image(
    design: DrawnDesign,
    *,
    region: Mapping[str, Any] | None = None,
    gamma: Any = None,
    window_size: tuple[int, int] = (1024, 768),
    max_elements: int | None = None,
) -> Picture:
    """Render the body off screen and return the picture.

    Parameters
    ----------
    design : Design
    region : mapping, optional
        Candidate region to outline (the scene's ``[body]`` table); default: the one recorded
        in the design (design.json ``region``, or ``body`` in older files), else none.
    gamma : array_like, shape (3,), optional
        Space ``Z`` (field axis) in body axes; normalised; default ``(0, 0, 1)``.
    window_size : (int, int)
        Width and height in pixels.
    max_elements : int, optional
        Cap on the elements drawn (default ``MAX_SHOW_ELEMENTS``); more is a ValueError
        (the command line refuses it first).

    Returns
    -------
    Picture
        An ndarray, shape (height, width, 3), uint8, that Jupyter displays as an image
        (``_repr_png_``) and :meth:`Picture.save` writes as PNG. For an interactive or
        customised view draw into your own plotter with :func:`plot_design`; for the geometry
        use :func:`design_blocks`.
    """
    size = _window_size(window_size)
    check_element_count(design, max_elements)
    if region is None:
        region = region_from_design(design)
    # SIGINT/SIGTERM inside VTK's C++ rendering can crash the interpreter: hold them until the
    # picture is done and the plotter closed, then deliver them (KeyboardInterrupt as usual)
    with deferred_signals():
        plotter = _body_plotter(
            design, region=region, gamma=gamma, window_size=size, off_screen=True
        )
        try:
            image = plotter.screenshot(None, return_img=True)
        finally:
            plotter.close()
    return np.ascontiguousarray(np.asarray(image)[:, :, :3]).view(Picture)


def render_screenshot(
    design: DrawnDesign,
    path: str | os.PathLike[str],
    *,
    region: dict | None = None,
    window_size: tuple[int, int] = (1024, 768),
    gamma: Any = None,
    max_elements: int | None = None,
) -> Path:
    """Render the body off screen and write a PNG atomically.

    Parameters
    ----------
    design : Design
    path : path-like
        Output file; must end in ``.png``.
    region : dict, optional
        Candidate region to outline, e.g. ``{"shape": "ball", "radius": 1.0}`` (m); default:
        the one recorded in the design, else none.
    window_size : (int, int)
        Image width and height in pixels.
    gamma : array_like, shape (3,), optional
        Field axis (space ``Z``) in body axes, default ``(0, 0, 1)``.
    max_elements : int, optional
        Cap on the elements drawn (default ``MAX_SHOW_ELEMENTS``).

    Returns
    -------
    Path
        The written file.
    """
    target = Path(path)
    if target.suffix.lower() not in SCREENSHOT_SUFFIXES:
        raise _misuse("screenshot path", "a file name ending in .png", str(target))
    check_output_path(target)  # before rendering: no FIFO, device, socket or link
    image = render_image(
        design, region=region, gamma=gamma, window_size=window_size, max_elements=max_elements
    )
    return image.save(target)


def show_interactive(
    design: DrawnDesign,
    *,
    region: Mapping[str, Any] | None = None,
    gamma: Any = None,
    window_size: tuple[int, int] = (1024, 768),
    max_elements: int | None = None,
) -> None:
    """Open an interactive window (blocks until it is closed); in Jupyter, show the body in
    the notebook instead (:func:`plot_design` with :func:`notebook_backend`: ``static`` works
    with no display).

    Raises
    ------
    ValueError
        When there is no display (Linux without ``DISPLAY``/``WAYLAND_DISPLAY``, or PyVista
        forced off screen) outside a notebook: render to a file instead.
    """
    if in_notebook():
        plot_design(design, region=region, gamma=gamma, window_size=window_size, show=True)
        return
    if not display_available():
        raise ValueError(NO_DISPLAY)
    size = _window_size(window_size)
    check_element_count(design, max_elements)
    if region is None:
        region = region_from_design(design)
    plotter = _body_plotter(design, region=region, gamma=gamma, window_size=size, off_screen=False)
    plotter.show()


@dataclass
class Trajectory:
    """Times and body-to-space rotations of a simulated motion.

    Attributes
    ----------
    t : ndarray, shape (T,)
        Times in s, nondecreasing.
    rotation : ndarray, shape (T, 3, 3)
        Body-to-space rotation matrices ``R`` (``X = R r``).
    """

    t: np.ndarray
    rotation: np.ndarray


def load_trajectory(source: str | os.PathLike[str] | Mapping[str, Any]) -> Trajectory:
    """Read ``t`` and ``rotation`` from a simulation's ``.npz`` file or a mapping of arrays.

    Rotations must be orthonormal with determinant +1 to 1e-6.
    """
    return Trajectory(*read_trajectory(source))


def frame_rotations(trajectory: Trajectory, times: np.ndarray) -> np.ndarray:
    """Rotations at ``times`` by spherical interpolation between the samples."""
    from scipy.spatial.transform import Rotation, Slerp

    t, rotation = trajectory.t, trajectory.rotation
    if len(t) == 1 or t[-1] == t[0]:
        return np.repeat(rotation[:1], len(times), axis=0)
    keep = np.concatenate([[True], np.diff(t) > 0])  # Slerp needs strictly increasing times
    slerp = Slerp(t[keep], Rotation.from_matrix(rotation[keep]))
    return np.asarray(slerp(np.clip(times, t[0], t[-1])).as_matrix())


def animate(
    design: DrawnDesign,
    trajectory: str | os.PathLike[str] | Mapping[str, Any],
    out_path: str | os.PathLike[str],
    *,
    frames: int = 60,
    fps: float = 15.0,
    region: Mapping[str, Any] | None = None,
    window_size: tuple[int, int] = (480, 360),
    progress: Callable[[int, int], None] | None = None,
    max_elements: int | None = None,
) -> Path:
    """Animate a simulated motion: the body turning in the space frame, written as GIF (or MP4).

    The space axes ``X, Y, Z`` stand still (``Z``, the field axis, drawn gold and vertical);
    the body, its axes and region move as ``X = R(t) r``. A thin line traces the tip of the
    body's ``z`` axis up to the current time. Frames are evenly spaced in time from the first
    to the last sample; rotations between samples are interpolated (slerp).

    Parameters
    ----------
    design : Design
    trajectory : path-like or mapping
        A simulation's ``.npz`` (keys ``t``, shape (T,), in s; ``rotation``, shape (T, 3, 3),
        body to space) or a mapping with those keys.
    out_path : path-like
        ``.gif``; ``.mp4`` when the ``imageio-ffmpeg`` package is installed.
    frames : int
        Number of frames (>= 1).
    fps : float
        Frames per second of the written animation (> 0).
    region : mapping, optional
        Candidate region to outline; default: the one recorded in the design.
    window_size : (int, int)
        Frame width and height in pixels.
    progress : callable(done, total), optional
        Called after each rendered frame.

    Returns
    -------
    Path
        The written file.
    """
    import imageio.v3 as iio

    target = Path(out_path)
    suffix = target.suffix.lower()
    if suffix not in ANIMATION_SUFFIXES:
        raise _misuse("animation path", "a file name ending in .gif or .mp4", str(target))
    if suffix == ".mp4":
        try:
            import imageio_ffmpeg  # noqa: F401
        except ImportError as exc:
            raise ValueError(mp4_missing(target)) from exc
    if isinstance(frames, bool) or not isinstance(frames, (int, np.integer)):
        raise _misuse("frames", "an integer", frames)
    if not 1 <= frames <= _MAX_FRAMES:
        raise _misuse("frames", f"an integer in 1..{_MAX_FRAMES}", frames)
    fps = as_finite_float(fps, "fps", positive=True)
    size = _window_size(window_size)
    check_element_count(design, max_elements)
    check_output_path(target)
    traj = load_trajectory(trajectory)
    if region is None:
        region = region_from_design(design)
    region = _region_spec(region)

    times = np.linspace(traj.t[0], traj.t[-1], int(frames))
    rotations = frame_rotations(traj, times)
    images = _render_frames(design, traj, times, rotations, region, size, progress)

    def write(tmp: Path) -> None:
        if suffix == ".gif":
            iio.imwrite(tmp, images, extension=".gif", duration=1000.0 / fps, loop=0)
        else:
            iio.imwrite(tmp, images, extension=".mp4", fps=fps)

    write_file_atomic(target, write)
    return target


def _render_frames(
    design: DrawnDesign,
    traj: Trajectory,
    times: np.ndarray,
    rotations: np.ndarray,
    region: Mapping[str, Any] | None,
    window_size: tuple[int, int],
    progress: Callable[[int, int], None] | None,
) -> np.ndarray:
    _use_offscreen_backend()
    with deferred_signals():
        plotter = pv.Plotter(off_screen=True, window_size=list(window_size))
    try:
        return _frames(plotter, design, traj, times, rotations, region, progress)
    finally:
        with deferred_signals():
            plotter.close()


def _frame_image(
    plotter: pv.Plotter, body: _BodyActors, rotation: np.ndarray, done: np.ndarray, caption: str
) -> np.ndarray:
    """One frame: the body turned by ``rotation``, its axes, the trace so far and the caption."""
    matrix = np.eye(4)
    matrix[:3, :3] = rotation
    for actor in body.actors:
        actor.user_matrix = matrix
    _add_labels(plotter, body.axis_tips @ rotation.T * 1.06, ("x", "y", "z"), "body", AXES_COLOR)
    if len(done) >= 2:
        plotter.add_mesh(pv.lines_from_points(done), color=AXES_COLOR, line_width=1.5, name="trace")
    plotter.add_text(caption, position="upper_left", font_size=9, color="black", name="time")
    plotter.reset_camera_clipping_range()
    return np.asarray(plotter.screenshot(None, return_img=True))[:, :, :3]


def _frames(
    plotter: pv.Plotter,
    design: DrawnDesign,
    traj: Trajectory,
    times: np.ndarray,
    rotations: np.ndarray,
    region: Mapping[str, Any] | None,
    progress: Callable[[int, int], None] | None,
) -> np.ndarray:
    # each frame is drawn with SIGINT/SIGTERM held (VTK may crash if interrupted mid-render);
    # an interrupt is delivered between frames
    with deferred_signals():
        plotter.background_color = pv.Color(BACKGROUND_COLOR)
        body, legend = _add_body(plotter, design, region, sphere_resolution=12, scalar_bar=False)
        size = body.size
        space_tips = _FIELD_AXIS_FRACTION * size * np.eye(3)
        plotter.add_mesh(
            _arrow(-space_tips[2], 2.0 * space_tips[2], shaft=0.004, tip=0.02), color=FIELD_COLOR
        )
        plotter.add_mesh(
            pv.merge([pv.Line(-tip, tip) for tip in space_tips[:2]]), color=REGION_COLOR
        )
        _add_labels(plotter, space_tips * 1.04, ("X", "Y", "Z (field)"), "space", FIELD_COLOR)
        legend.append(["field axis Z", FIELD_COLOR, "triangle"])
        _add_legend(plotter, legend)
        _place_camera(plotter, size, _VIEW_DIRECTION)

        # the tip of the body z axis over the whole motion, decimated to at most 2000 points
        stride = max(1, len(traj.t) // 2000)
        trace_t = traj.t[::stride]
        trace = traj.rotation[::stride, :, 2] * body.axis_tips[2, 2]

    images = []
    for i, (time, rotation) in enumerate(zip(times, rotations, strict=True)):
        with deferred_signals():
            done = trace[trace_t <= time]
            caption = f"t = {fmt(time, PRECISE)} s   frame {i + 1}/{len(times)}"
            images.append(_frame_image(plotter, body, rotation, done, caption))
        if progress is not None:
            progress(i + 1, len(times))
    return np.stack(images)


def design_picture(design: DrawnDesign, width: int = 320, height: int = 240) -> str:
    """An inline HTML picture of a design for notebooks (empty when it cannot be rendered here)."""
    try:
        image = render_image(design, window_size=(width, height))
    except Exception:  # no OpenGL here: the table alone
        return ""
    return png_html(image, width)
