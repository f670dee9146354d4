"""The curated top level: `import chargedesign as cd` reaches the main entry points, lazily."""

import json
import subprocess
import sys

import pytest

import chargedesign as cd

HEAVY = ("sympy", "cvxpy", "pyvista", "scipy.optimize", "vtkmodules", "matplotlib")


def imported_modules(code: str) -> set[str]:
    """Modules a fresh interpreter imports to run ``code`` (from ``-X importtime``)."""
    run = subprocess.run(
        [sys.executable, "-X", "importtime", "-c", code],
        capture_output=True,
        text=True,
        timeout=120,
        check=True,
    )
    names = set()
    for line in run.stderr.splitlines():
        if line.startswith("import time:") and "|" in line:
            names.add(line.rsplit("|", 1)[1].strip())
    return names


def test_import_is_light():
    names = imported_modules("import chargedesign as cd; cd.Parameters(C=1.0)")
    assert "chargedesign" in names
    heavy = sorted(n for n in names if any(n == h or n.startswith(h + ".") for h in HEAVY))
    assert heavy == []


def test_the_command_line_parser_is_light_too():
    names = imported_modules("from chargedesign.cli import build_parser; build_parser()")
    assert not [n for n in names if any(n == h or n.startswith(h + ".") for h in HEAVY)]


def test_every_public_name_resolves():
    for name in cd.__all__:
        assert getattr(cd, name) is not None, name
    assert sorted(cd.__all__) == sorted(set(cd.__all__))
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        cd.nope  # noqa: B018
    # solver tuning constants stay internal
    assert not {"CLARABEL_SETTINGS", "HIGHS_OPTIONS", "POLISH_THRESHOLDS"} & set(cd.__all__)


def test_stage_names_are_plain_functions_of_the_api():
    import inspect

    import chargedesign.api as api
    import chargedesign.checker
    import chargedesign.designer.pipeline
    import chargedesign.simulation
    import chargedesign.sweeps
    import chargedesign.tolerancing  # noqa: F401

    for name in ("design", "check", "simulate", "frontier", "tolerance", "sweep"):
        entry = getattr(cd, name)
        assert inspect.isfunction(entry), name
        assert entry is getattr(api, name), name


def test_design_check_simulate_from_the_top_level(default_result):
    result = default_result
    assert isinstance(result, cd.DesignResult)
    assert isinstance(result.design, cd.Design) and isinstance(result.design, cd.ElementSet)
    report = cd.check(result, n_orientations=40)
    assert isinstance(report, cd.CheckReport) and report.passed
    motion = cd.simulate(result, t_end=0.5, effects=["theorem"])
    assert isinstance(motion, cd.SimulationResult)
    json.dumps(motion.summary(), allow_nan=False)


def test_design_from_parameters_uses_the_default_region():
    from chargedesign.api import as_scene

    body = {"shape": "ball", "radius": 1.0, "spacing": 0.5}
    scene = as_scene(cd.Parameters(C=1.0, n=0.7), body=body)
    assert scene.parameters.n == 0.7 and scene.table("body")["spacing"] == 0.5
    assert "magnetic" in scene.fields


def test_read_design_and_load_scene(tmp_path, default_result):
    path = tmp_path / "design.json"
    cd.write_design(default_result.design, path)
    again = cd.read_design(path)
    assert len(again.charge_values) == len(default_result.design.charge_values)
    assert cd.load_scene(None).source == "<default>"
    with pytest.raises(cd.InputError):
        cd.check(42)


def test_no_public_name_is_hidden_by_a_submodule():
    """Importing every module of the package rebinds no public name: a subpackage never
    shares the name of an entry point, and no package re-exports a name of one of its
    submodules (the submodule import would silently replace it)."""
    import importlib
    import inspect
    import pkgutil

    modules = [
        importlib.import_module(info.name)
        for info in pkgutil.walk_packages(cd.__path__, "chargedesign.")
        if not info.name.startswith("chargedesign.bench") and not info.name.endswith("__main__")
    ]
    for name in cd.__all__:
        assert not inspect.ismodule(getattr(cd, name)), name
    for module in modules:
        if not hasattr(module, "__path__"):
            continue
        for info in pkgutil.iter_modules(module.__path__):
            value = getattr(module, info.name, None)
            if value is not None:
                assert inspect.ismodule(value), f"{module.__name__}.{info.name}"
