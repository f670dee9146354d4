"""Start-up structure (issue 42 item 4): importing the command line, and the modules a command
imports before it runs, loads no heavy library that the import itself does not use. The
libraries are loaded where they are called (``cKDTree`` in the cells above a thousand
candidates, ``solve_ivp`` and the DOP853 tableau in the integrator service,
``Rotation`` in the flight's observation), so they cannot come back to the start path through
a module-level import unnoticed; the check command, run on a physical design, loads neither
scipy.optimize nor scipy.spatial (its overlap pairs are numpy's). A structure test, not a
timing test (the CPU seconds: docs/benchmarks.md, "Start-up by command")."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.fresh_process import imported_of, imports_module

#: heavy libraries no command's start path imports (scipy.optimize brings scipy.spatial in
#: with it, scipy.integrate brings both; matplotlib, pyvista: the pictures; sympy: the symbolic
#: model; cvxpy: the mass program's old route; heyoka: the integrator)
HEAVY = (
    "scipy.optimize",
    "scipy.spatial",
    "scipy.integrate",
    "matplotlib",
    "pyvista",
    "sympy",
    "cvxpy",
    "heyoka",
)


@pytest.mark.parametrize(
    "code",
    [
        "import chargedesign.cli",
        "import chargedesign.cli, chargedesign.commands.frontier",
        "import chargedesign.cli, chargedesign.commands.design",
        "import chargedesign.cli, chargedesign.commands.simulate",
        "import chargedesign.cli, chargedesign.commands.check",
        "import chargedesign.designer",
        "import chargedesign.physical.limits, chargedesign.checker.verdict",
    ],
)
def test_start_path_keeps_heavy_libraries_out(code):
    assert imported_of(code, HEAVY) == set()


def test_the_probe_sees_an_import():
    # the same probe on code that does import them: the test above can fail
    assert imported_of("import scipy.optimize", HEAVY) == {"scipy.optimize", "scipy.spatial"}


def test_the_check_command_imports_no_scipy():
    # what the check command imports before it runs: numpy only (scipy loads, if at all, in
    # the stages that call it)
    assert not imports_module("import chargedesign.cli, chargedesign.commands.check", "scipy")


@pytest.fixture(scope="module")
def physical_design(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A small physical body (a medium, so the check runs the limits and the overlap pairs)."""
    from physical.test_buildable import SMALL

    from chargedesign.body import write_design
    from chargedesign.designer import design_from_scene
    from chargedesign.scene import load_scene

    path = tmp_path_factory.mktemp("startup") / "design.json"
    write_design(design_from_scene(load_scene(SMALL), frontier=False).design, path)
    return path


def test_the_check_command_runs_without_scipy_optimize_or_spatial(physical_design):
    # the whole command in a fresh process: the limits check's overlap pairs (numpy) and the
    # forward check load neither (scipy.special still loads: the coils' Gegenbauer terms)
    run = (
        "from chargedesign.cli import main\n"
        f"assert main(['check', {str(physical_design)!r}, '--orientations', '20']) in (0, 1)"
    )
    assert imported_of(run, HEAVY) == set()


def test_the_parser_runs_no_scene_reader():
    # the command line's parser needs the scene's key declarations only (scene.keys), not the
    # scene's loader and its readers (the package's names load on first use)
    light = ("chargedesign.scene.load", "chargedesign.readers")
    assert imported_of("import chargedesign.cli", light) == set()
    assert imported_of("from chargedesign.scene import load_scene", light) == set(light)


@pytest.mark.skipif(
    importlib.util.find_spec("heyoka") is None, reason="without heyoka simulate falls back to scipy"
)
def test_simulating_a_written_design_loads_no_scipy(physical_design):
    # a design.json has its elements: no design, so none of the designer's scipy (sparse,
    # linalg), and heyoka's Taylor integrator in place of solve_ivp
    run = (
        "import contextlib, io\n"
        "from chargedesign.cli import main\n"
        "with contextlib.redirect_stdout(io.StringIO()):\n"
        f"    assert main(['simulate', {str(physical_design)!r}, '--json', '--t-end', '1']) == 0"
    )
    assert not imports_module(run, "scipy")


@pytest.mark.parametrize(
    "args",
    [
        ["frontier", "--json"],
        ["design", "examples/scenes/unit_scale.toml", "--out", "{out}"],
    ],
)
def test_a_theorem_scenes_design_and_frontier_run_without_sympy(args, tmp_path):
    """The theorem's scene's exact certificate is made when ``result.certificate`` is read
    (designer/pipeline._record_case): no output of these commands prints it, so the run,
    not only its start path, keeps sympy out."""
    from pathlib import Path

    root = Path(__file__).resolve().parents[1]
    argv = [a.format(out=tmp_path) for a in args]
    code = (
        f"import contextlib, os; os.chdir({str(root)!r})\n"
        "from chargedesign.cli import main\n"
        f"with contextlib.redirect_stdout(open(os.devnull, 'w')): assert main({argv!r}) == 0"
    )
    assert imported_of(code, ("sympy",)) == set()


def test_the_frontier_command_runs_without_scipy_optimize_or_spatial():
    """The default scene's frontier point, run whole: its LPs go to HiGHS through highspy
    (designer/linear_program.py) and its cells' nearest neighbours are numpy's below
    NEAREST_BY_BLOCKS_MAX candidates, so neither library is loaded at all."""
    root = Path(__file__).resolve().parents[1]
    code = (
        f"import contextlib, os; os.chdir({str(root)!r})\n"
        "from chargedesign.cli import main\n"
        "with contextlib.redirect_stdout(open(os.devnull, 'w')):\n"
        "    assert main(['frontier', '--json']) == 0"
    )
    assert imported_of(code, ("scipy.optimize", "scipy.spatial")) == set()


#: the environment variables OpenBLAS reads for its thread count
BLAS_THREAD_VARIABLES = ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")


def _blas_threads_seen(code: str, environment: dict[str, str]) -> str:
    """The thread counts of a fresh process's BLAS libraries (threadpoolctl's, scipy's OpenBLAS
    loaded after ``code``), with ``environment`` in place of OPENBLAS_NUM_THREADS."""
    probe = (
        f"{code}\nimport scipy.linalg\nfrom threadpoolctl import threadpool_info\n"
        "print(sorted({i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas'}))"
    )
    # every variable OpenBLAS reads for its count goes (an in-process dask test leaves
    # OMP_NUM_THREADS=1 in this process's environment), then the test's own
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREAD_VARIABLES} | environment
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, env=env
    )
    return out.stdout.strip().splitlines()[-1]


def test_the_command_line_runs_blas_on_one_thread_unless_the_user_says():
    # the command line's package sets the default before numpy loads: every BLAS library
    # of the process runs one thread; a user's own setting wins; the library alone leaves
    # the count to the machine (two or more threads where it has the cores)
    assert imported_of("import chargedesign", ("numpy",)) == set()
    assert _blas_threads_seen("import chargedesign.cli", {}) == "[1]"
    assert _blas_threads_seen("import chargedesign.cli", {"OPENBLAS_NUM_THREADS": "2"}) == "[2]"
    if (os.cpu_count() or 1) > 1:
        assert _blas_threads_seen("import chargedesign", {}) != "[1]"
