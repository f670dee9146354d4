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
from chargedesign.designer.physical_setup import check_physical_candidates
from chargedesign.designer.pipeline import larmor_of_scene
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.limits import MAX_PERIODS
from chargedesign.moment_conditions.case import case_target
from chargedesign.readers import read_toml_file
from chargedesign.scene import Scene
from chargedesign.scene.keys import KEY
from chargedesign.scene.sweep_file import (
    SweptKey,
    base_is_valid,
    base_scene,
    check_no_command_with_spec,
    check_option_names,
    check_option_ranges,
    check_point_count,
    check_point_value,
    check_points,
    check_scene_key,
    check_sweep_keys,
    chosen_command,
    grid_lists,
    named_as_option,
    point_scene,
    random_points,
    random_table,
    resolve_sweep_key,
    sweep_tables,
)
from chargedesign.simulation import setup_from_scene
from chargedesign.simulation.axes import resolve_axes
from chargedesign.sweeps.registry import COMMANDS, resolve
from chargedesign.tolerancing import ErrorModel, MaterialErrors
from chargedesign.validation import (
    check_error_spreads,
    check_material_analysis,
    check_periods,
    input_error,
)
from chargedesign.vocabulary import MATERIAL_ERROR_KEYS

__all__ = ["SweepSpec", "as_sweep", "load_sweep", "sweep_from_dict"]


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


def _region_candidates(scene: Scene) -> None:
    """A ``[body]`` region's candidates (their count within the cap), designed or not."""
    if scene.region is not None and "shape" in scene.region.table:
        candidates_from_region(scene.region.spec(), base_dir=scene.base_dir)


def check_options(command: Any, options: Mapping[str, Any], source: str) -> None:
    """``[options]``: names the command takes (its signature), numbers within the input range
    and, for a built-in command, within its command-line options' ranges; for ``tolerance``
    its errors parsed and within theirs. A bad option was found only when its point ran,
    after the others had written (``position = "1e31"``), or not at all (``samples = 1e9``)."""
    check_option_names(resolve(command), options, source)
    if not isinstance(command, str):
        return
    prefix = f"{source}: options."
    check_option_ranges(command, options, prefix)
    if command == "tolerance":
        errors = {k: options.get(k) for k in ("position", "charge", "dipole", "mass")}
        with named_as_option(prefix):
            model = ErrorModel.parse(**errors)
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
    """Every point's whole scene, before any point runs (:func:`.point_scene`: its tables by
    their owners), for a command that designs its ``[body]`` region's candidates (each
    distinct region once), and for ``simulate`` the work of its motion
    (:func:`chargedesign.validation.check_periods`, the cap the ``simulate`` command applies).
    A point that would fail on its input is refused here, with the point and its values
    named (:func:`.check_points`), not found after others ran."""

    designs = command in ("design", "check", "tolerance", "frontier")
    base = None if scene_source.startswith("<") else Path(scene_source).parent
    seen: set[str] = set()
    solvers: list[str] = []
    given = options or {}

    def check(point: dict[str, Any]) -> None:
        scene = point_scene(scene_data, point, scene_source)
        if "case" in scene.tables:
            # the point's [case] read by the case loader (the scene's own loader), and for
            # the commands that design it the refusals design makes before its work
            case = scene.case
            if designs:
                try:
                    case_target(case)
                except InfeasibleError as exc:
                    raise InputError(str(exc)) from None
        region = scene.region
        key = repr(sorted(region.table.items())) if region is not None else ""
        if designs and region is not None and "shape" in region.table and key not in seen:
            seen.add(key)
            found = candidates_from_region(region.spec(), base_dir=base)
            if scene.physical is not None:  # a physical design's cells need two points
                check_physical_candidates(len(found), region.table)
        if designs:
            _check_solver(scene.design.solver, solvers)
        if command == "simulate":
            _check_motion_work(scene, given.get(KEY.t_end))
            _check_axes(scene)
        elif command == "tolerance":
            _check_drift_work(scene, given)
            _check_material_work(scene, given)

    check_points(points, source, check)


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
    if given:
        check_material_analysis(
            f"options.{given[0]}", scene.physical is not None, scene.fields.get("magnetic", ())
        )


@dataclass
class _KeyChecks:
    """Swept keys checked alone against the base scene, each resolved once
    (:func:`.resolve_sweep_key`): its declaration, the whole scene it makes, a region's
    candidates."""

    scene_data: Mapping[str, Any]
    scene_source: str
    source: str
    keys: dict[str, SweptKey] = field(default_factory=dict)
    base_valid: bool | None = None

    def check(self, path: str, value: Any) -> None:
        if self.base_valid is None:
            self.base_valid = base_is_valid(self.scene_data, self.scene_source)
        key = self.keys.get(path) or resolve_sweep_key(path, self.source)
        self.keys[path] = key
        check_scene_key(
            key,
            value,
            self.scene_data,
            self.source,
            self.scene_source,
            _region_candidates if key.table == "body" else None,
            by_declaration=self.base_valid,
        )


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
    chosen = chosen_command(data, source, command, tuple(COMMANDS))
    scene_data, scene_source = base_scene(data, source, base_dir)
    chunk, options, grid, random = sweep_tables(data, source)
    keys, value_lists = grid_lists(grid, source)
    random_keys, n_random, seed = random_table(random, grid, source)
    # the work, counted before any point is built
    check_point_count(keys, value_lists, random_keys, n_random, max_points, source)
    swept = _KeyChecks(scene_data, scene_source, source)
    for key, values in zip(keys, value_lists, strict=True):
        for i, value in enumerate(values):  # every value of every grid key, alone
            check_point_value(value, f"{source}: grid key {key!r}[{i}]")
            swept.check(key, value)
    points = [dict(zip(keys, combo, strict=True)) for combo in itertools.product(*value_lists)]
    if random_keys:
        rng = np.random.default_rng(seed)
        points = random_points(points, random_keys, n_random, rng, source)
        for key in random_keys:  # every draw in range; the key (its first draw) alone
            for i, p in enumerate(points):
                check_point_value(p[key], f"{source}: random key {key!r} (draw {i})")
            swept.check(key, points[0][key])
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


def as_sweep(spec: Any, command: Callable[..., dict[str, Any]] | None = None) -> SweepSpec:
    """A parsed sweep: ``spec`` itself (``command`` must then be None: a parsed sweep holds
    its command), or the sweep file at that path read and validated (:func:`load_sweep`,
    ``command`` a function of your own run at every point)."""
    if isinstance(spec, SweepSpec):
        check_no_command_with_spec(command)
        return spec
    return load_sweep(spec, command=command)
