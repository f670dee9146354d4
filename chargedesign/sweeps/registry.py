"""What a sweep can run at each point: command name -> function(scene, point_dir, **options).

Each function takes the point's :class:`~chargedesign.scene.Scene` and its own output folder
(which it may fill with files), and returns a flat dict of main figures (numbers, strings,
booleans) for ``summary.csv``.

A sweep *file* names only these built-in commands: a file never makes the tool import or call
code it names (a colleague's sweep file is data, not a program). A function of your own with
the same signature runs only through the Python API, passed as an object:
``cd.sweep("grid.toml", "out", command=my_function)``.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

from chargedesign.body import write_design
from chargedesign.checker import check_design
from chargedesign.designer import design_from_scene
from chargedesign.designer.pipeline import frontier_from_scene
from chargedesign.files import write_json_atomic
from chargedesign.scene.keys import KEY
from chargedesign.scene.sweep_file import builtin_command
from chargedesign.simulation import setup_from_scene, simulate
from chargedesign.tolerancing import (
    ErrorModel,
    material_errors_with,
    monte_carlo,
    tolerance_report,
)
from chargedesign.verdict import recorded_verdict

CommandFunction = Callable[..., dict[str, Any]]


def _flat(data: Any, prefix: str = "") -> dict[str, Any]:
    """Scalars of a (nested) mapping, keys joined by dots; lists and None dropped."""
    out: dict[str, Any] = {}
    if not isinstance(data, dict):
        return out
    for key, value in data.items():
        name = f"{prefix}{key}"
        if isinstance(value, dict):
            out.update(_flat(value, name + "."))
        elif isinstance(value, (bool, int, float, str)):
            out[name] = value
    return out


def _scene_design(scene: Any, point_dir: Path) -> Any:
    """The design a scene names (``body.design`` or inline elements), else designed now."""

    setup = setup_from_scene(scene)
    if setup.design is not None:
        return setup.design

    design = design_from_scene(scene).recorded_design()  # its whole record, certificate too
    write_design(design, point_dir / "design.json")
    return design


def run_design(scene: Any, point_dir: Path) -> dict[str, Any]:
    """Design the body; writes design.json. Figures: the recorded verdict's state, element
    counts, residual, seconds."""

    result = design_from_scene(scene)
    d = result.recorded_design()  # its whole record, a [case] scene's certificate too
    write_design(d, point_dir / "design.json")
    residual = getattr(result, "residual_after", None)  # a case's result has its residuals
    return {
        "verdict": recorded_verdict(d)["state"],
        "charges": len(d.charge_values),
        "dipoles": len(d.dipole_moments),
        "masses": len(d.mass_values),
        **({} if residual is None else {"residual_after": float(residual)}),
        "max_abs_charge": float(abs(d.charge_values).max()) if len(d.charge_values) else 0.0,
        KEY.total_mass: float(d.mass_values.sum()),
    }


def run_check(scene: Any, point_dir: Path) -> dict[str, Any]:
    """Design (unless the scene names a design) and check; writes check.json."""

    report = check_design(_scene_design(scene, point_dir))
    data = report.to_dict()
    write_json_atomic(point_dir / "check.json", data)
    return {
        "mu_rel_err": data.get("mu_rel_err"),
        "V_rel_err": data.get("V_rel_err"),
        "inertia_rel_err": data.get("inertia_rel_err"),
        "passed": bool(report.passed),
        # the check's own verdict, recomputed from the parts, and whether the record agrees
        **(
            {"verdict": data["verdict"]["state"], "verdict_agrees": data["verdict_agrees"]}
            if "verdict" in data
            else {}
        ),
    }


def run_simulate(scene: Any, point_dir: Path, t_end: float | None = None) -> dict[str, Any]:
    """Simulate the scene (its [simulation] table, whose ``axes`` key is ``simulate
    --axes``); writes summary.json."""

    result = simulate(scene, t_end=t_end)
    summary = result.summary()
    write_json_atomic(point_dir / "summary.json", summary)
    return {
        k: summary[k]
        for k in ("I4_rel_drift", "I3_max", "I1_rel_drift", "I2_max_dev")
        if k in summary
    }


def run_frontier(scene: Any, point_dir: Path) -> dict[str, Any]:
    """The largest time-rate within every limit (:mod:`chargedesign.designer.frontier`);
    writes frontier.json. A scene without ``[medium]`` fails with the frontier's reason."""

    data = frontier_from_scene(scene).to_dict()
    write_json_atomic(point_dir / "frontier.json", data)
    return _flat(data)


def run_tolerance(
    scene: Any,
    point_dir: Path,
    position: Any = None,
    charge: Any = None,
    dipole: Any = None,
    mass: Any = None,
    target: float = 1e-4,
    samples: int = 100,
    t_end: float = 100.0,
    simulate: bool = True,
    chi_relative: float | None = None,
    density_relative: float | None = None,
    magnetisation_relative: float | None = None,
) -> dict[str, Any]:
    """Design (unless named) and analyse tolerances; writes tolerance.json. The materials'
    relative errors (as ``tolerance --chi-relative`` ...) replace those of the scene's
    ``[tolerance]`` table."""

    design = _scene_design(scene, point_dir)
    model = ErrorModel.parse(position, charge, dipole, mass)
    materials = material_errors_with(
        design,
        "options",
        chi_relative=chi_relative,
        density_relative=density_relative,
        magnetisation_relative=magnetisation_relative,
    )
    report = tolerance_report(design, target, material_errors=materials, material_samples=samples)
    figures: dict[str, Any] = {
        "dominant": report.dominant["element"] if report.dominant else "",
        "position_tol_m": report.dominant["position_tol_m_min"] if report.dominant else None,
        "binding": (report.dominant or {}).get("binding") or "",
        "uniform_tol_m_rms": report.uniform["position_tol_m_rms_min"],
    }
    data: dict[str, Any] = report.to_dict()
    if not model.is_zero:
        mc = monte_carlo(
            design,
            model,
            samples=samples,
            drift_samples=samples if simulate else 0,
            t_end=t_end,
            levels=(1.0,),
            target=target,
            material_errors=materials,
        )
        data = mc.to_dict()
        for q, v in data["rel_errors"].items():
            figures[f"{q}_rel_err_p90"] = v["monte_carlo"]["p90"]
        if simulate:
            figures["I4_drift_median"] = data["I4_drift"][0]["monte_carlo"]["median"]
            figures["I4_drift_linear_median"] = data["I4_drift"][0]["linear"]["median"]
    if report.materials is not None:
        induced = report.materials.to_dict()["induced_over_term"]["monte_carlo"]
        figures["induced_over_term_p90"] = induced.get("p90")
        # deprecated alias: the same value (over the smallest realised term at s = 1)
        figures["induced_fraction_p90"] = figures["induced_over_term_p90"]
    write_json_atomic(point_dir / "tolerance.json", data)
    return figures


#: the built-in commands
COMMANDS: dict[str, CommandFunction] = {
    "design": run_design,
    "check": run_check,
    "simulate": run_simulate,
    "frontier": run_frontier,
    "tolerance": run_tolerance,
}


def command_label(command: str | CommandFunction) -> str:
    """How a command is named in sweep.json: its registry name, or ``module.qualname`` of a
    function passed from Python (a label only: nothing ever imports it back)."""
    if isinstance(command, str):
        return command
    module = getattr(command, "__module__", None) or "?"
    name = getattr(command, "__qualname__", None) or type(command).__name__
    return f"python:{module}.{name}"


def resolve(command: str | CommandFunction) -> CommandFunction:
    """The function of a command: a built-in's by name, or the callable itself.

    Raises
    ------
    InputError
        A string that is not a built-in command (it is never imported).
    """
    if callable(command):
        return command
    return COMMANDS[builtin_command(command, tuple(COMMANDS))]
