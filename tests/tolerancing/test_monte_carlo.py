"""The Monte Carlo of perturbed bodies against the linear-response prediction."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from chargedesign.body import read_design
from chargedesign.cli import main
from chargedesign.tolerancing import ErrorModel, error_distribution, monte_carlo, plot_drift

DESIGN = Path(__file__).parent / "data" / "default_design.json"


@pytest.fixture(scope="module")
def design():
    return read_design(DESIGN)


def test_small_errors_spread_matches_the_linear_prediction(design):
    model = ErrorModel.parse(position="0.1um", charge="1e-6%", dipole="1e-6%", mass="1e-6%")
    out = error_distribution(design, model, 200, seed=2, n_orientations=100)
    for q, v in out.items():
        mc, lin = v["monte_carlo"], v["linear"]
        assert np.allclose(mc, lin, rtol=1e-3, atol=1e-14), q
        # the predicted rms (no sampling) against the sampled spread of the worst orientation
        assert 0.3 < np.sqrt(np.mean(mc**2)) / v["linear_rms"] < 3.0, q


def test_large_errors_depart_from_the_linear_prediction(design):
    model = ErrorModel.parse(position="5%")
    out = error_distribution(design, model, 50, seed=2, n_orientations=50)
    mc, lin = out["V"]["monte_carlo"], out["V"]["linear"]
    assert np.max(np.abs(mc - lin) / lin) > 1e-2


def test_drift_grows_linearly_and_matches_the_linear_response(design):
    result = monte_carlo(
        design, ErrorModel.parse(position="2um"), samples=12, t_end=5.0, levels=(0.1, 1.0)
    )
    mc = np.median(result.drift_mc, axis=1)
    lin = np.median(result.drift_linear, axis=1)
    assert result.nominal_drift < 1e-3 * mc[0]
    assert 5.0 < mc[1] / mc[0] < 20.0  # first order: ten times the errors, ten times the drift
    for a, b in zip(mc, lin, strict=True):
        assert 0.8 < a / b < 1.25
    data = json.loads(json.dumps(result.to_dict(), allow_nan=False))
    assert [d["level"] for d in data["I4_drift"]] == [0.1, 1.0]
    assert set(data["rel_errors"]) == {"mu", "V", "inertia"}
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    assert plot_drift(result, ax=ax) is ax
    assert ax.get_xscale() == "log" and ax.get_yscale() == "log"
    plt.close(fig)


def test_cli_sensitivity_and_monte_carlo(tmp_path, capsys):
    assert main(["tolerance", str(DESIGN), "--json", "--target", "1e-5"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["target"] == 1e-5 and "dominates" in data["headline"]
    out = tmp_path / "tol"
    code = main(
        [
            "tolerance",
            str(DESIGN),
            "--position",
            "1um",
            "--charge",
            "0.01%",
            "--samples",
            "4",
            "--t-end",
            "2",
            "--levels",
            "0.5,1",
            "--out",
            str(out),
        ]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "Monte Carlo: 4 perturbed bodies" in text
    for name in ("tolerance.json", "errors.csv", "drift.csv", "drift_over_time.csv", "drift.png"):
        assert (out / name).is_file()
    assert len((out / "drift.csv").read_text().splitlines()) == 1 + 2 * 4  # 2 levels x 4 bodies
    stored = read_design(out / "design.json")
    assert stored.tolerance["format"] == "chargedesign.tolerance/1"
    assert stored.n_elements == read_design(DESIGN).n_elements


@pytest.mark.parametrize(
    ("args", "needle"),
    [
        (["--position", "3 parsecs"], "--position"),
        (["--position", "1um", "--samples", "100000"], "--samples"),
        (["--position", "1um", "--levels", "0,1"], "--levels"),
    ],
)
def test_cli_bad_options_one_line(args, needle, capsys):
    assert main(["tolerance", str(DESIGN), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err


def test_a_frame_body_is_toleranced_against_what_its_elements_realise(design):
    """A frame body (n read as the axes' rate) has the tolerances and drifts of the same
    elements as an n = 0 body: the references and I4 use the body's own parameters."""
    from dataclasses import replace

    from chargedesign.body import Design
    from chargedesign.larmor import LarmorReading

    as_n0 = Design.from_dict(
        {**design.to_dict(), "parameters": {**design.parameters.as_dict(), "n": 0.0}}
    )
    frame = Design.from_dict({**as_n0.to_dict(), "parameters": design.parameters.as_dict()})
    frame.larmor = LarmorReading("frame", design.parameters.n)
    assert frame.body_parameters == replace(design.parameters, n=0.0)
    model = ErrorModel.parse(position="2um")
    a = monte_carlo(as_n0, model, samples=6, t_end=2.0, levels=(1.0,), seed=3)
    b = monte_carlo(frame, model, samples=6, t_end=2.0, levels=(1.0,), seed=3)
    np.testing.assert_array_equal(a.drift_mc, b.drift_mc)
    np.testing.assert_array_equal(a.drift_linear, b.drift_linear)
    assert a.nominal_drift == b.nominal_drift
