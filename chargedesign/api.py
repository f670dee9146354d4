"""The main entry points behind ``import chargedesign as cd``: thin functions over the stages.

``cd.design`` designs a body from a scene (or from bare parameters with the default scene's
region and fields), ``cd.check`` checks a design forward, ``cd.simulate`` simulates a scene or
a design. Each returns a result of the one result protocol (:mod:`chargedesign.results`).
"""

from __future__ import annotations

import os
import tomllib
from collections.abc import Mapping
from typing import TYPE_CHECKING, Any

from chargedesign.airbearing.result import TestbedResult
from chargedesign.airbearing.run import default_testbed_scene, testbed_from_scene
from chargedesign.body import Design, read_design
from chargedesign.checker import CheckReport, check_design
from chargedesign.designer import DesignResult, design_from_scene
from chargedesign.designer.frontier import FrontierResult
from chargedesign.designer.pipeline import frontier_from_scene
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.scene import Scene, default_scene_text, load_scene, scene_from_dict
from chargedesign.simulation import SimulationResult
from chargedesign.simulation import simulate as simulate_scene_or_design
from chargedesign.sweeps import SweepResult, as_sweep, run_sweep
from chargedesign.tolerancing import DEFAULT_TARGET, ToleranceReport, tolerance_report
from chargedesign.topology.diagram import BifurcationDiagram, CaseDiagram, bifurcation_diagram

if TYPE_CHECKING:
    from chargedesign.model.case_file import CaseCertificate
    from chargedesign.model.catalogue import CatalogueReport


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

    tables = {name: table for name, table in tables.items() if table is not None}
    if isinstance(source, Scene) and not tables:
        return source
    if source is None or isinstance(source, Parameters):
        data = tomllib.loads(default_scene_text())
        where = "<default>"
        if isinstance(source, Parameters):
            data["parameters"] = source.as_dict()
            where = "<parameters>"
    elif isinstance(source, Scene):
        model = {} if "case" in source.tables else {"parameters": source.parameters.as_dict()}
        data = {**model, **source.tables}
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
        raise wrong_kind("design", "a scene, a path, a mapping, Parameters or None", source)
    data.update(tables)
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
        ``result.design`` is the body (:class:`~chargedesign.body.Design`); a scene with
        ``[case]`` takes the same route (:func:`~chargedesign.designer.design_from_scene`).
        Every result carries the exact certificate of its model (``result.certificate``,
        made when first read); ``result.recorded_design()`` is the body with a ``[case]``
        scene's certificate verdict in its ``case`` record, as design.json is written.

    Raises
    ------
    InputError, InfeasibleError, SolverError
    """

    scene = as_scene(source, fields=fields, body=body)
    return design_from_scene(scene, progress=progress, **options)


def verify_case(source: Any) -> CaseCertificate:
    """The exact certificate of a case of (ep) and its claimed integral (docs/workbench.md).

    Parameters
    ----------
    source : str, PathLike, Mapping or Case
        A case file (TOML with ``[case]``, a scene with one too), the ``[case]`` table as a
        mapping (or a mapping holding it under ``case``), or a validated
        :class:`~chargedesign.scene.case_file.Case`.

    Returns
    -------
    CaseCertificate
        ``holds``, ``independent``, ``counterexample``, ... (``to_dict`` is ``verify --json``).

    Raises
    ------
    InputError
        One line naming the key and the reason (a refused expression names its token).
    """
    from chargedesign.model.case_file import (  # sympy: loaded by the case stages only
        certify_case,
        verify_case_file,
    )
    from chargedesign.scene.case_file import Case, case_from_table

    if isinstance(source, (str, os.PathLike)):
        return verify_case_file(source)
    if isinstance(source, Mapping):
        table = source["case"] if "case" in source else source
        return certify_case(case_from_table(table, "case"))
    if isinstance(source, Case):
        return certify_case(source)
    raise wrong_kind("verify_case", "a case file path, a [case] mapping or a Case", source)


def catalogue() -> CatalogueReport:
    """The paper's integrable cases of (ep), each certified exactly (``chargedesign
    catalogue``): a :class:`~chargedesign.model.catalogue.CatalogueReport`."""
    from chargedesign.model.catalogue import certify_catalogue  # sympy: the case stages only

    return certify_catalogue()


def _held_body(source: Any) -> Any:
    """The body a result holds (a DesignResult's with its whole record, a case's certificate
    too; another result's ``design``), else ``source`` itself."""
    if isinstance(source, DesignResult):
        return source.recorded_design()
    inner = getattr(source, "design", None)
    return inner if isinstance(inner, Design) else source


def _design_of(design: Any, where: str) -> Design:
    """The body of a Design, a DesignResult (or a case's), a design.json path or mapping;
    another kind is refused in one line naming the entry point ``where``."""
    body = _held_body(design)
    if isinstance(body, Design):
        return body
    if isinstance(design, (str, os.PathLike)):
        return read_design(design)
    if isinstance(design, Mapping):
        return Design.from_dict(dict(design))

    raise wrong_kind(where, "a Design, a DesignResult, a design.json path or mapping", design)


def check(design: Any, **options: Any) -> CheckReport:
    """Check a design forward: rotate it through the fields and compare with the theorem.

    Parameters
    ----------
    design : Design, DesignResult, str, PathLike or Mapping
        The body (a design.json path or mapping is read first).
    **options
        ``n_orientations``, ``tol``, ``seed``, ``quadrature_order``, ``precision``
        (see :func:`chargedesign.checker.check_design`).

    Returns
    -------
    CheckReport
    """

    return check_design(_design_of(design, "check"), **options)


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

    return simulate_scene_or_design(_held_body(source), **options)


def tolerance(design: Any, target: float | None = None, **options: Any) -> ToleranceReport:
    """Per-element tolerances of a design (:func:`chargedesign.tolerancing.tolerance_report`).

    ``design``: a Design, a DesignResult, a design.json path or mapping; ``target`` the relative
    accuracy of mu, V and the inertia to keep.
    """

    target = DEFAULT_TARGET if target is None else target
    return tolerance_report(_design_of(design, "tolerance"), target, **options)


def sweep(spec: Any, out: Any, command: Any = None, **options: Any) -> SweepResult:
    """Run a sweep file or spec into ``out`` (:func:`chargedesign.sweeps.run_sweep`).

    ``command``: a function of your own, ``(scene, point_dir, **options) -> dict``, run at
    every point of a sweep file that names no command. A file itself names only built-in
    commands: the tool never imports or calls code a file names.
    """

    return run_sweep(as_sweep(spec, command), out, **options)


def frontier(source: Any = None, *, progress: Any = None, **overrides: Any) -> FrontierResult:
    """How far the scene's parameters can grow before a physical limit binds.

    ``source``: see :func:`as_scene` (the scene needs a ``[medium]`` table);
    ``overrides``: frontier options (see :func:`chargedesign.designer.frontier.find_frontier`).
    """
    return frontier_from_scene(as_scene(source), progress=progress, **overrides)


def testbed(source: Any = None, *, progress: Any = None, **options: Any) -> TestbedResult:
    """An air-bearing testbed that moves as the theorem says (docs/testbed.md).

    ``source``: see :func:`as_scene` (its parameters and ``[testbed]`` table); None: the
    embedded testbed scene (examples/scenes/testbed.toml);
    ``options``: ``[testbed]`` keys that replace the scene's (``rate_Hz``, ``seeds``, ...).
    ``result`` is written with :func:`chargedesign.airbearing.report.write_testbed`.
    """
    scene = as_scene(default_testbed_scene() if source is None else source)
    return testbed_from_scene(scene, progress=progress, **options)


def bifurcation(
    source: Any = None, *, h_range: tuple[float, float] | None = None
) -> BifurcationDiagram | CaseDiagram:
    """The bifurcation diagram of the scene's case, as ``chargedesign bifurcation`` draws it.

    ``source``: see :func:`as_scene`. A ``[case]`` scene's diagram is of its case, on the
    case's own level (a :class:`CaseDiagram`, or the theorem's :class:`BifurcationDiagram`
    when the case is the theorem's entry); any other scene's is the theorem's at its
    parameters, on ``I3 = 0``. ``h_range``: energies (default: see
    :func:`chargedesign.topology.diagram.bifurcation_diagram`).
    """
    scene = as_scene(source)
    if scene.case is not None:
        return bifurcation_diagram(scene.case, h_range)
    return bifurcation_diagram(scene.parameters, h_range)


def wrong_kind(where: str, expected: str, value: Any) -> InputError:
    """The one line for an argument of a kind an entry point does not take (the notebook
    API's sources): ``where: expected ..., got <type name>``."""
    return InputError(f"{where}: expected {expected}, got {type(value).__name__}")


__all__ = [
    "as_scene",
    "bifurcation",
    "check",
    "design",
    "frontier",
    "simulate",
    "sweep",
    "testbed",
    "tolerance",
]
