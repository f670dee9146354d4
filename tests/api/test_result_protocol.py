"""One result protocol: to_dict (JSON-ready), str (the CLI's text), a short repr, HTML."""

import json

import pytest

import chargedesign as cd
from chargedesign.results import REPR_LIMIT, Result, compact_repr, json_ready

VERIFY_DATA = {
    "certificate": {"general": True, "yehia2003": True, "goriachev": True, "chaplygin": True},
    "printed": [
        {"name": "I4", "agrees": True, "difference": "0"},
        {"name": "p6", "agrees": False, "difference": "x", "note": "a misprint"},
    ],
    "certificate_checks": {
        case: {"I1": True} for case in ("general", "yehia2003", "goriachev", "chaplygin")
    },
    "counterexample": {
        "I3_printed": "0",
        "I3": "1/2",
        "state": {"gamma1": "0", "gamma2": "0", "gamma3": "1", "p": "1", "q": "0", "r": "0"},
        "dI4_dt": "3/4",
        "dI4_dt_float": 0.75,
    },
    "seconds": {
        "certificate": dict.fromkeys(("general", "yehia2003", "goriachev", "chaplygin"), 0.1),
        "audit": 0.2,
    },
}


@pytest.fixture(scope="module")
def results(default_result):
    from chargedesign.moment_conditions import conditions_for_scene
    from chargedesign.verification import VerificationReport

    report = cd.check(default_result.design, n_orientations=40)
    return {
        "DesignResult": default_result,
        "Design": default_result.design,
        "CheckReport": report,
        "Parameters": default_result.design.parameters,
        "LinearConditions": conditions_for_scene(cd.load_scene(None)),
        "VerificationReport": VerificationReport(VERIFY_DATA),
        "SimulationResult": cd.simulate(default_result, t_end=0.5, effects=["theorem"]),
        **_later_results(default_result.design),
    }


def _later_results(design):
    """The results of the physical, tolerance, ensemble and sweep stages, small and fast."""
    import tempfile
    from pathlib import Path

    import numpy as np

    from chargedesign.physical.limits import check_limits
    from chargedesign.simulation.ensemble import simulate_ensemble
    from chargedesign.sweeps import run_sweep, sweep_from_dict
    from chargedesign.tolerancing import ErrorModel, monte_carlo, tolerance_report

    mc = monte_carlo(design, ErrorModel.parse(position="1um"), samples=8, t_end=1.0, levels=(1.0,))
    states = np.array([[1e-6 * k, 0.0, 0.0, 0.0, 0.6, 0.8] for k in (1, 2, 3)])
    with tempfile.TemporaryDirectory() as tmp:
        from chargedesign.bench.sweep import idle

        grid = {"grid": {"parameters.n": [1e-6, 2e-6]}}
        sweep = run_sweep(sweep_from_dict(grid, command=idle), Path(tmp) / "s")
    from chargedesign.designer.pipeline import frontier_from_scene

    small = Path(__file__).resolve().parents[1] / "physical" / "small.toml"
    return {
        "FrontierResult": frontier_from_scene(cd.load_scene(small)),
        "LimitsReport": check_limits(design),
        "ToleranceReport": tolerance_report(design),
        "MonteCarloResult": mc,
        "EnsembleResult": simulate_ensemble(design, states, t_end=1.0),
        "SweepResult": sweep,
    }


NAMES = [
    "DesignResult",
    "Design",
    "CheckReport",
    "Parameters",
    "LinearConditions",
    "VerificationReport",
    "SimulationResult",
    "FrontierResult",
    "LimitsReport",
    "ToleranceReport",
    "MonteCarloResult",
    "EnsembleResult",
    "SweepResult",
]


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_short_and_names_the_type(results, name):
    text = repr(results[name])
    assert text.startswith(name + "(") and len(text) <= REPR_LIMIT
    assert "\n" not in text


@pytest.mark.parametrize("name", NAMES)
def test_to_dict_round_trips_through_json(results, name):
    data = results[name].to_dict()
    text = json.dumps(data, allow_nan=False)
    assert json.loads(text) == data


@pytest.mark.parametrize("name", NAMES)
def test_str_is_the_text_and_html_is_a_table(results, name, monkeypatch):
    import chargedesign.viz

    # no rendering in this test: the picture beside the table is tested in tests/viz
    monkeypatch.setattr(chargedesign.viz, "design_picture", lambda design: "")
    obj = results[name]
    assert str(obj).strip() and str(obj) != repr(obj)
    html = obj._repr_html_()
    assert html.startswith("<table") and "</table>" in html


def test_the_cli_prints_the_library_text(results, capsys, tmp_path):
    from chargedesign.cli import main

    design_path = tmp_path / "design.json"
    cd.write_design(results["Design"], design_path)
    assert main(["check", str(design_path), "--orientations", "40"]) == 0
    assert capsys.readouterr().out.strip() == str(results["CheckReport"]).strip()


def test_design_result_repr_was_40_kb_and_is_now_one_line(results):
    assert len(repr(results["DesignResult"])) < REPR_LIMIT
    assert "charges=" in repr(results["DesignResult"])


def test_helpers():
    assert len(compact_repr("X", {"a": "y" * 1000, **{f"k{i}": i for i in range(200)}})) <= 300
    assert json_ready({"a": float("nan"), "b": (1, 2)}) == {"a": None, "b": [1, 2]}

    class Tiny(Result):
        def to_dict(self):
            return {"x": 1.0, "y": [1, 2]}

    assert repr(Tiny()) == "Tiny(x=1)" and str(Tiny()) == "x: 1.0"
    assert json.loads(Tiny().to_json()) == {"x": 1.0, "y": [1, 2]}
