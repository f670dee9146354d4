"""Start-up structure (issue 42 item 4): importing the command line, and the modules a command
imports before it runs, loads no heavy library that the import itself does not use. The
libraries are loaded where they are called (``linprog`` in the charge and ballast LPs,
``cKDTree`` in the cells and the limits check), so they cannot come back to the start path
through a module-level import unnoticed. A structure test, not a timing test."""

from __future__ import annotations

import pytest

from tests.fresh_process import imported_of

#: heavy libraries no command's start path imports (scipy.optimize brings scipy.spatial in
#: with it; matplotlib, pyvista: the pictures; sympy: the symbolic model; cvxpy: the
#: mass program's old route; heyoka: the integrator)
HEAVY = (
    "scipy.optimize",
    "scipy.spatial",
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
        "import chargedesign.designer",
        "import chargedesign.physical.limits, chargedesign.checker.verdict",
    ],
)
def test_start_path_keeps_heavy_libraries_out(code):
    assert imported_of(code, HEAVY) == set()


def test_the_probe_sees_an_import():
    # the same probe on code that does import them: the test above can fail
    assert imported_of("import scipy.optimize", HEAVY) == {"scipy.optimize", "scipy.spatial"}


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
