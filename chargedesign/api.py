"""The main entry points behind ``import chargedesign as cd``: thin functions over the stages.

``cd.design`` designs a body from a scene (or from bare parameters with the default scene's
region and fields), ``cd.check`` checks a design forward, ``cd.simulate`` simulates a scene or
a design. Each returns a result of the one result protocol (:mod:`chargedesign.results`).
"""

from __future__ import annotations

import os
import sys
import types
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

if TYPE_CHECKING:  # pragma: no cover
    from chargedesign.body import Design
    from chargedesign.check import CheckReport
    from chargedesign.design.result import DesignResult
    from chargedesign.scene import Scene
    from chargedesign.simulation.result import SimulationResult


def as_scene(source: Any = None, **tables: Any) -> Scene:
    """A :class:`~chargedesign.scene.Scene` from a scene, a path, a mapping, parameters or None.

    Parameters
    ----------
    source : Scene, str, PathLike, Mapping, Parameters or None
        A scene; a TOML file; the scene's tables as a mapping (as read from TOML); bare
        :class:`~chargedesign.params.Parameters` (the default scene's fields and region with
        these parameters); None for the embedded default scene.
    **tables
        Scene tables that replace the source's (``fields=...``, ``body=...``, ``design=...``);
        ``fields`` given as ``{"magnetic": {"a1": 1.0, "a2": 0.5}}`` or with ``legendre``.
    """
    import tomllib

    from chargedesign.errors import InputError
    from chargedesign.params import Parameters
    from chargedesign.scene import Scene, default_scene_text, load_scene, scene_from_dict

    if isinstance(source, Scene) and not tables:
        return source
    if source is None or isinstance(source, Parameters):
        data = tomllib.loads(default_scene_text())
        where = "<default>"
        if isinstance(source, Parameters):
            data["parameters"] = source.as_dict()
            where = "<parameters>"
    elif isinstance(source, Scene):
        data = {"parameters": source.parameters.as_dict(), **source.tables}
        data["fields"] = {k: {"legendre": list(v)} for k, v in source.fields.items()}
        where = source.source
    elif isinstance(source, (str, os.PathLike)):
        scene = load_scene(source)
        if not tables:
            return scene
        return as_scene(scene, **tables)
    elif isinstance(source, Mapping):
        data = {k: v for k, v in source.items()}
        where = "<dict>"
    else:
        raise InputError(
            f"design: expected a scene, a path, a mapping, Parameters or None, got "
            f"{type(source).__name__}"
        )
    for name, table in tables.items():
        if table is not None:
            data[name] = table
    return scene_from_dict(data, where)


def design(
    source: Any = None,
    *,
    progress: Any = None,
    fields: Mapping[str, Any] | None = None,
    body: Mapping[str, Any] | None = None,
    **options: Any,
) -> DesignResult:
    """Design the body a scene describes (charges, dipoles, masses that realise the case).

    Parameters
    ----------
    source : Scene, str, PathLike, Mapping, Parameters or None
        See :func:`as_scene`; None designs the embedded default scene.
    progress : callable, optional
        ``progress(message)`` at each stage.
    fields, body : mapping, optional
        Replace the scene's ``[fields]`` or ``[body]`` table.
    **options
        ``[design]`` options that replace the scene's (``objective``, ``solver``,
        ``n_charges``, ``max_charge``, ``total_charge``, ``total_mass``, ``polish``, ...).

    Returns
    -------
    DesignResult
        ``result.design`` is the body (:class:`~chargedesign.body.Design`).

    Raises
    ------
    InputError, InfeasibleError, SolverError
    """
    from chargedesign.design import design_from_scene

    scene = as_scene(source, fields=fields, body=body)
    return design_from_scene(scene, progress=progress, **options)


def _design_of(design: Any) -> Design:
    from chargedesign.body import Design, read_design

    if isinstance(design, Design):
        return design
    inner = getattr(design, "design", None)
    if isinstance(inner, Design):  # a DesignResult
        return inner
    if isinstance(design, (str, os.PathLike)):
        return read_design(design)
    if isinstance(design, Mapping):
        return Design.from_dict(dict(design))
    from chargedesign.errors import InputError

    raise InputError(
        f"check: expected a Design, a DesignResult, a design.json path or mapping, got "
        f"{type(design).__name__}"
    )


def check(design: Any, **options: Any) -> CheckReport:
    """Check a design forward: rotate it through the fields and compare with the theorem.

    Parameters
    ----------
    design : Design, DesignResult, str, PathLike or Mapping
        The body (a design.json path or mapping is read first).
    **options
        ``n_orientations``, ``tol``, ``seed``, ``quadrature_order``, ``precision``
        (see :func:`chargedesign.check.check_design`).

    Returns
    -------
    CheckReport
    """
    from chargedesign.check import check_design

    return check_design(_design_of(design), **options)


def simulate(source: Any = None, **options: Any) -> SimulationResult:
    """Simulate a scene or a design (see :func:`chargedesign.simulation.api.simulate`).

    Parameters
    ----------
    source : Scene, Design, DesignResult, Parameters, str, PathLike or None
        None simulates the embedded default scene (its body designed on the fly).
    **options
        ``t_end``, ``effects``, ``initial``, ``rtol``, ``method``, ``samples``, ...

    Returns
    -------
    SimulationResult
    """
    from chargedesign.design.result import DesignResult
    from chargedesign.simulation.api import simulate as _simulate

    if isinstance(source, DesignResult):
        source = source.design
    return _simulate(source, **options)


def tolerance(design: Any, target: float | None = None, **options: Any) -> Any:
    """Per-element tolerances of a design (:func:`chargedesign.tolerance.tolerance_report`).

    ``design``: a Design, a DesignResult or a design.json path; ``target`` the relative
    accuracy of mu, V and the inertia to keep.
    """
    from chargedesign.body import Design, read_design
    from chargedesign.design.result import DesignResult
    from chargedesign.tolerance import DEFAULT_TARGET, tolerance_report

    if isinstance(design, DesignResult):
        design = design.design
    if not isinstance(design, Design):
        design = read_design(design)
    return tolerance_report(design, DEFAULT_TARGET if target is None else target, **options)


def sweep(spec: Any, out: Any, command: Any = None, **options: Any) -> Any:
    """Run a sweep file or spec into ``out`` (:func:`chargedesign.sweep.run_sweep`).

    ``command``: a function of your own, ``(scene, point_dir, **options) -> dict``, run at
    every point of a sweep file that names no command. A file itself names only built-in
    commands: the tool never imports or calls code a file names.
    """
    from chargedesign.errors import InputError
    from chargedesign.sweep import SweepSpec, load_sweep, run_sweep

    if not isinstance(spec, SweepSpec):
        spec = load_sweep(spec, command=command)
    elif command is not None:
        raise InputError("command=: give it with a sweep file, not with a parsed SweepSpec")
    return run_sweep(spec, out, **options)


__all__ = [
    "CallableModule",
    "as_scene",
    "check",
    "design",
    "make_callable",
    "simulate",
    "sweep",
    "tolerance",
]


class CallableModule(types.ModuleType):
    """A module that can be called: ``chargedesign.check(design)`` runs :func:`check`.

    ``chargedesign.design``, ``chargedesign.check`` and ``chargedesign.simulate`` are both
    modules (their internals stay importable and patchable as before) and the main entry
    points of the package: calling one calls the function of the same name in this module.
    """

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        entry = globals()[self.__name__.rsplit(".", 1)[-1]]
        return entry(*args, **kwargs)


def make_callable(module_name: str) -> None:
    """Turn the module ``chargedesign.<name>`` into a :class:`CallableModule` (idempotent)."""
    module = sys.modules[module_name]
    if not isinstance(module, CallableModule):
        module.__class__ = CallableModule
