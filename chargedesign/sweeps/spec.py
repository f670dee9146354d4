"""Sweep files: the base scene, the command, and the points (a grid and/or a random sample).

```toml
scene = "scene.toml"          # the base scene, relative to this file (omitted: the default)
command = "design"            # design | check | simulate | frontier | tolerance
chunk = 0                     # points per task (0: automatic)
[grid]                        # dotted scene keys -> lists of values; the product is swept
"body.radius" = [0.01, 0.02, 0.04]
"fields.magnetic.a1" = [1.0, 2.0]
[random]                      # optional: `samples` draws (per grid point)
samples = 10
seed = 0
"parameters.n" = {uniform = [0.1, 1.0]}
"body.spacing" = {log_uniform = [0.1, 0.3]}
"fields.magnetic.a2" = {choice = [0.5, 1.0]}
[options]                     # keyword options of the command (e.g. tolerance: position = "20um")
```

Every key is checked against the scene before anything runs: one-line errors name the key
(unknown scene key, empty grid, wrong command, bad random spec). The file's own structure is
read at the boundary (:mod:`chargedesign.scene.sweep_file`); this module checks what the
points mean for the stages (each point's whole scene, its candidates, its work).
``command`` names a built-in command only; a file never names code to import or run. A
function of your own is passed from Python: ``load_sweep(path, command=function)`` or
``cd.sweep(path, out, command=function)``.
"""

from __future__ import annotations

import itertools
import os
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.candidates import candidates_from_region
from chargedesign.designer.pipeline import larmor_of_scene
from chargedesign.errors import InputError
from chargedesign.limits import MAX_PERIODS, OPTION_RANGES
from chargedesign.readers import read_toml_file
from chargedesign.scene import KNOWN_TABLES, scene_from_dict, validated
from chargedesign.scene.keys import KEY
from chargedesign.scene.sweep_file import (
    base_scene,
    check_point_count,
    check_point_value,
    check_sweep_keys,
    grid_lists,
    random_points,
    random_table,
    scene_with,
    sweep_tables,
)
from chargedesign.simulation.api import setup_from_scene
from chargedesign.simulation.axes import resolve_axes
from chargedesign.sweeps.registry import check_command, resolve
from chargedesign.tolerancing import ErrorModel, MaterialErrors
from chargedesign.validation import check_error_spreads, check_periods, input_error
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS


@dataclass
class SweepSpec:
    """A parsed, validated sweep.

    Attributes
    ----------
    source : str
        The sweep file (or ``<dict>``).
    scene_data : dict
        The base scene's TOML mapping; ``scene_source`` its path (relative paths inside it,
        e.g. ``body.design``, resolve against it) or ``<default>``.
    command : str or callable
        A built-in command's name (:data:`chargedesign.sweeps.COMMANDS`), or a function
        ``(scene, point_dir, **options) -> dict`` passed from Python (never from a file).
    keys : list of str
        The swept dotted keys, in order.
    points : list of dict
        One mapping ``key -> value`` per point.
    chunk : int
        Points per task (0: automatic).
    options : dict
        Keyword options for the command.
    """

    source: str
    scene_data: dict[str, Any]
    scene_source: str
    command: str | Callable[..., dict[str, Any]]
    keys: list[str]
    points: list[dict[str, Any]]
    chunk: int = 0
    options: dict[str, Any] = field(default_factory=dict)

    def point_ids(self) -> list[str]:
        width = max(4, len(str(max(len(self.points) - 1, 0))))
        return [f"p{i:0{width}d}" for i in range(len(self.points))]


def validate_scene_key(
    data: dict[str, Any], key: str, source: str, scene_source: str = "<sweep>"
) -> None:
    """Raise an InputError naming ``key`` when the scene's owners reject it (``scene_source``:
    the base scene's path, which its relative paths resolve against)."""

    parts = key.split(".")
    if len(parts) < 2 or not all(parts):
        raise InputError(
            f"{source}: grid key {key!r}: expected a dotted scene key such as body.radius"
        )
    if parts[0] not in KNOWN_TABLES:
        raise InputError(
            f"{source}: unknown scene key {key!r} (scene tables: {', '.join(KNOWN_TABLES)})"
        )
    try:
        # every table by its owner (chargedesign.scene.validate_tables), and a region's points
        scene = validated(scene_from_dict(data, source=scene_source))
        if parts[0] == "body" and scene.region is not None and "shape" in scene.region.table:
            candidates_from_region(scene.region.spec(), base_dir=scene.base_dir)
    except InputError as exc:
        raise InputError(f"{source}: scene key {key!r}: {exc}") from None
    except (TypeError, ValueError) as exc:
        raise InputError(f"{source}: scene key {key!r}: {exc}") from None


def check_options(command: Any, options: Mapping[str, Any], source: str) -> None:
    """``[options]``: names the command takes (its signature), numbers within the input range."""
    import inspect

    check_point_value(dict(options), f"{source}: options")
    try:
        inspect.signature(resolve(command)).bind(None, None, **options)
    except TypeError as exc:
        raise InputError(f"{source}: options: {exc}") from None
    except ValueError:  # pragma: no cover - a callable without a signature
        return
    if isinstance(command, str):
        _check_command_options(command, options, f"{source}: options.")


def _check_command_options(command: str, options: Mapping[str, Any], prefix: str) -> None:
    """A built-in command's options within the ranges its command-line options have
    (chargedesign.limits.OPTION_RANGES) and, for ``tolerance``, its errors parsed and within
    theirs: a bad option was found only when its point ran, after the others had written
    (``position = "1e31"``), or not at all (``samples = 1e9``)."""

    ranges = OPTION_RANGES.get(command, {})
    for name, value in options.items():
        bounds = ranges.get(name)
        if bounds is None or isinstance(value, bool) or not isinstance(value, (int, float)):
            continue
        if not bounds.holds(value):
            raise InputError(f"{prefix}{name}: expected a value in {bounds.text()}, got {value!r}")
    if command == "tolerance":
        errors = {k: options.get(k) for k in ("position", "charge", "dipole", "mass")}
        try:
            model = ErrorModel.parse(**errors)
        except InputError as exc:
            raise InputError(f"{prefix}{str(exc).removeprefix('--')}") from None
        check_error_spreads(model, prefix)
        materials = {k: options[k] for k in MATERIAL_ERROR_KEYS if k in options}
        MaterialErrors.parse(prefix.removesuffix("."), **materials)


def validate_points(
    scene_data: Mapping[str, Any],
    scene_source: str,
    points: list[dict[str, Any]],
    command: Any,
    source: str,
    options: Mapping[str, Any] | None = None,
) -> None:
    """Every point's whole scene, before any point runs: its tables by their owners
    (chargedesign.scene.scene_from_dict), for a command that designs its ``[body]`` region's
    candidates (each distinct region once), and for ``simulate`` the work of its motion
    (:func:`chargedesign.validation.check_periods`, the cap the ``simulate`` command applies).
    A point that would fail on its input is refused here, with the point and its values
    named, not found after others ran."""

    designs = command in ("design", "check", "tolerance", "frontier")
    base = None if scene_source.startswith("<") else Path(scene_source).parent
    seen: set[str] = set()
    solvers: list[str] = []
    width = max(4, len(str(max(len(points) - 1, 0))))
    for i, point in enumerate(points):
        try:
            check_point_value(point, f"point p{i:0{width}d}")
            scene = validated(scene_from_dict(scene_with(scene_data, point), scene_source))
            region = scene.region
            key = repr(sorted(region.table.items())) if region is not None else ""
            if designs and region is not None and "shape" in region.table and key not in seen:
                seen.add(key)
                candidates_from_region(region.spec(), base_dir=base)
            if designs:
                _check_solver(scene.design.solver, solvers)
            if command == "simulate":
                _check_motion_work(scene, (options or {}).get(KEY.t_end))
                _check_axes(scene)
            elif command == "tolerance":
                _check_drift_work(scene, options or {})
                _check_material_work(scene, options or {})
        except (InputError, TypeError, ValueError) as exc:
            values = ", ".join(f"{k} = {v!r}" for k, v in point.items())
            raise InputError(f"{source}: point p{i:0{width}d} ({values}): {exc}") from None


def _check_motion_work(scene: Any, t_end: Any) -> None:
    """A simulate point's periods of its fastest rate within MAX_PERIODS (a ``t_end = 1e8`` on a
    unit-scale body ran unbounded after the other points had written their outputs)."""

    if t_end is not None:
        option = "options.t_end"
    else:
        t_end, option = scene.simulation.t_end, "simulation.t_end"
    check_periods(t_end, scene.parameters, scene.table("initial"), MAX_PERIODS, option)


def _check_solver(name: str, installed: list[str]) -> None:
    """``design.solver``: ``auto`` or a solver cvxpy has installed (the designer reads it in
    upper case). A name that named nothing failed only when its point ran, after the others
    had written (issue 32). ``installed`` caches cvxpy's list once it is read."""

    if name.upper() == "AUTO":
        return
    if not installed:
        import cvxpy  # heavy: loaded only for a sweep whose scene names a solver

        installed[:] = sorted(cvxpy.installed_solvers())
    if name.upper() not in installed:
        raise input_error(
            "design.solver", f"auto or an installed solver ({', '.join(installed)})", name
        )


def _check_axes(scene: Any) -> None:
    """``simulation.axes = "turning"`` needs a frame body: a design.json read in the frame
    reading, or a ``[body]`` region designed in it (``[design] larmor``, else frame with
    ``[medium]``: the designer's rule, :func:`.larmor_of_scene`). It was refused only when its
    point ran, after the others had written (issue 32)."""

    if scene.simulation.axes != "turning":
        return  # inertial axes (or the default) suit every body
    setup = setup_from_scene(scene)  # a referenced design.json is read (one-line errors)
    larmor = setup.larmor
    effects = scene.simulation.effects
    if setup.design_scene is not None and (effects is None or set(effects) - {"theorem"}):
        # a region the run designs first (the theorem effect alone designs nothing)
        larmor = larmor_of_scene(scene.design, scene.parameters, scene.physical is not None)[0]
    resolve_axes("turning", larmor, "simulation.axes")


def _check_drift_work(scene: Any, options: Mapping[str, Any]) -> None:
    """A tolerance point's drift simulation (run when it has errors and ``simulate``) within
    MAX_PERIODS of the scene's parameters, as ``tolerance --t-end`` is."""

    errors = any(options.get(k) is not None for k in ("position", "charge", "dipole", "mass"))
    if errors and options.get("simulate", True):
        t_end = options.get(KEY.t_end, 100.0)
        check_periods(t_end, scene.parameters, None, MAX_PERIODS, "options.t_end")


def _check_material_work(scene: Any, options: Mapping[str, Any]) -> None:
    """A tolerance point with the materials' errors needs what their analysis needs: a
    physical design (``[medium]``) in a magnetic field of degree <= 2."""

    given = [k for k in MATERIAL_ERROR_KEYS if options.get(k) is not None]
    if not given:
        return
    if scene.physical is None:
        raise InputError(
            f"options.{given[0]}: material errors need a physical design (a scene with [medium])"
        )
    if any(scene.fields.get("magnetic", ())[2:]):
        raise InputError(
            f"options.{given[0]}: material errors are analysed for magnetic fields of degree <= 2"
        )


def _chosen_command(
    data: Mapping[str, Any], source: str, command: Callable[..., dict[str, Any]] | None
) -> str | Callable[..., dict[str, Any]]:
    """The command run at every point: the function passed, or the file's named command."""

    if command is not None:
        if not callable(command):
            raise InputError(f"command=: expected a function, got {type(command).__name__}")
        if "command" in data:
            raise InputError(
                f"{source}: names command {data['command']!r} and a function was passed as "
                "command=: give one of them"
            )
        return command
    if "command" not in data:
        raise InputError(f"{source}: missing key 'command'")
    # compared with the registry's names only: nothing named by a file is imported
    check_command(data["command"], f"{source}: command")
    chosen: str = data["command"]
    return chosen


def _check_grid_values(
    keys: list[str],
    value_lists: list[list[Any]],
    scene_data: Mapping[str, Any],
    scene_source: str,
    source: str,
) -> None:
    """Every value of every grid key, checked alone against the base scene."""
    for key, values in zip(keys, value_lists, strict=True):
        for i, value in enumerate(values):
            check_point_value(value, f"{source}: grid key {key!r}[{i}]")
            validate_scene_key(scene_with(scene_data, {key: value}), key, source, scene_source)


def _check_random_values(
    points: list[dict[str, Any]],
    random_keys: Mapping[str, Any],
    scene_data: Mapping[str, Any],
    scene_source: str,
    source: str,
) -> None:
    """Every draw of every random key, and the key (its first draw) against the base scene."""
    for key in random_keys:
        for i, p in enumerate(points):
            check_point_value(p[key], f"{source}: random key {key!r} (draw {i})")
        validate_scene_key(scene_with(scene_data, {key: points[0][key]}), key, source, scene_source)


def sweep_from_dict(
    data: Mapping[str, Any],
    source: str = "<dict>",
    base_dir: Path | None = None,
    command: Callable[..., dict[str, Any]] | None = None,
    max_points: int | None = None,
) -> SweepSpec:
    """Validate a sweep mapping (see the module docstring); every point's scene is validated
    before any runs (:func:`validate_points`).

    Parameters
    ----------
    data : mapping
        The sweep file's tables.
    source : str
        Its name, for error messages.
    base_dir : Path, optional
        Where a relative ``scene`` path resolves.
    command : callable, optional
        A function of your own, ``(scene, point_dir, **options) -> dict``, run at every
        point instead of a built-in command (the file must then not name one).
    max_points : int, optional
        Raise the cap on points (default :data:`chargedesign.limits.MAX_SWEEP_POINTS`).
    """
    check_sweep_keys(data, source)
    chosen = _chosen_command(data, source, command)
    scene_data, scene_source = base_scene(data, source, base_dir)
    chunk, options, grid, random = sweep_tables(data, source)
    keys, value_lists = grid_lists(grid, source)
    random_keys, n_random, seed = random_table(random, grid, source)
    # the work, counted before any point is built
    check_point_count(keys, value_lists, random_keys, n_random, max_points, source)
    _check_grid_values(keys, value_lists, scene_data, scene_source, source)
    points = [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*value_lists)]
    if random_keys:
        rng = np.random.default_rng(seed)
        points = random_points(points, random_keys, n_random, rng, source)
        _check_random_values(points, random_keys, scene_data, scene_source, source)
    check_options(chosen, options, source)
    validate_points(scene_data, scene_source, points, chosen, source, options)
    return SweepSpec(
        source=source,
        scene_data=scene_data,
        scene_source=scene_source,
        command=chosen,
        keys=keys + list(random_keys),
        points=points,
        chunk=chunk,
        options=dict(options),
    )


def load_sweep(
    path: str | os.PathLike[str],
    command: Callable[..., dict[str, Any]] | None = None,
    max_points: int | None = None,
) -> SweepSpec:
    """Read and validate a sweep file (one-line errors naming the key).

    ``command``: a function of your own to run at every point; ``max_points``: raise the cap
    on points (see :func:`sweep_from_dict`).
    """
    p = Path(path)
    return sweep_from_dict(
        read_toml_file(p, "sweep file"), str(p), p.parent, command=command, max_points=max_points
    )
