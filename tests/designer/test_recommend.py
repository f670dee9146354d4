"""The frontier's realised window on the command line, the recommended scene, and a probe whose
design fails refusing only its rate."""

from __future__ import annotations

import json
import tomllib
from pathlib import Path

import pytest

from chargedesign.cli import main
from chargedesign.designer import frontier as frontier_mod
from chargedesign.designer import recommend as recommend_mod
from chargedesign.designer.frontier import WindowOptions
from chargedesign.designer.pipeline import frontier_from_scene
from chargedesign.designer.recommend import Choice, recommend, scene_at_rate, toml_text
from chargedesign.errors import SolverError
from chargedesign.readers import loads_toml
from chargedesign.scene import load_scene, scene_from_dict

ROOT = Path(__file__).resolve().parents[2]
CHAPLYGIN = ROOT / "examples" / "scenes" / "chaplygin_magnetic.toml"


def ferrite_brass() -> dict:
    """The issue's hand-edited K = 0 body: ferrite magnets, brass ballast, a2 = 1 T/m."""
    data = tomllib.loads(CHAPLYGIN.read_text())
    data["fields"]["magnetic"]["a2"] = 1.0
    data["magnets"]["material"] = "ferrite"
    data["ballast"]["material"] = "brass"
    data["body"].update(radius=0.05, spacing=0.0125)
    data["parameters"].update(C=2e-5, kappa=1.1025e-7, n=2.45e-6)
    return data


def test_the_scene_writer_round_trips_through_the_toml_reader():
    data = {
        "parameters": {"C": 0.02, "n": 0.02, "K": 0.0, "kappa": 9.0},
        "fields": {"magnetic": {"legendre": [0.0, 0.06], "max": 1.0}},
        "design": {"realise": ["mu", "V", "inertia"], "larmor": "frame"},
        "body": {"shape": "ball", "radius": 0.2},
    }
    text = toml_text(data, ["a comment", "", "two"])
    assert text.startswith("# a comment\n#\n# two\n")
    assert loads_toml(text, "written") == data


def test_the_rate_scales_n_and_k_once_kappa_twice_and_the_time_inversely():
    data = scene_at_rate(
        {"parameters": {"n": 2.0, "K": 3.0, "kappa": 5.0}, "simulation": {"t_end": 10.0}}, 4.0
    )
    assert data == {
        "parameters": {"n": 8.0, "K": 12.0, "kappa": 80.0},
        "simulation": {"t_end": 2.5},
    }


def test_recommend_finds_a_realised_choice_and_writes_it_with_every_change(tmp_path, monkeypatch):
    """The search over a few choices (its dimensions cut down to keep the test short): the
    ferrite and brass body's window is empty (its ferrite's own chi); NdFeB and a weaker
    gradient open it. The written scene loads, names every change, and its rate lies inside
    its own window."""
    monkeypatch.setattr(
        recommend_mod,
        "_dimensions",
        lambda base: {"a2_factor": (0.03, 1.0), "magnets": ("ndfeb", "ferrite")},
    )
    scene = scene_from_dict(ferrite_brass(), "ferrite-brass")
    found = recommend(scene, WindowOptions())
    assert found.base.window is not None and found.base.window.empty
    assert found.best.choice == Choice(a2_factor=0.03, magnets="ndfeb")
    assert found.best.window is not None and not found.best.window.empty
    path = tmp_path / "recommended.toml"
    found.write(path)
    text = path.read_text()
    assert "[magnets] material: ferrite -> ndfeb" in text
    assert "[fields.magnetic] a2: 1 -> 0.03 T/m" in text
    assert "Window margins at this rate" in text and "Searched: a2_factor" in text
    again = frontier_from_scene(load_scene(path), window=WindowOptions())
    assert again.realised is not None and not again.realised.empty
    assert again.realised.s_low < 1.0 < again.realised.s_high


def test_a_probe_whose_design_fails_refuses_only_its_rate(monkeypatch):
    """A design that fails above s = 2 (as a polish leaving a magnet lighter than its volume
    did) ends the frontier there, named, instead of ending the search."""
    original = frontier_mod.design_at_rate

    def failing(setup, s):
        if s > 2.0:
            raise SolverError("magnets: polishing left a magnet lighter than its volume")
        return original(setup, s)

    monkeypatch.setattr(frontier_mod, "design_at_rate", failing)
    front = frontier_from_scene(load_scene(CHAPLYGIN))
    assert 1.0 < front.s_max <= 2.0
    assert front.binding.stage == "design"
    assert "lighter than its volume" in front.binding.text("vacuum")


def test_frontier_json_carries_the_realised_window(capsys):
    assert main(["frontier", str(CHAPLYGIN), "--json", "--quiet"]) == 0
    data = json.loads(capsys.readouterr().out)
    realised = data["realised"]
    assert {"s_low", "s_high", "binding_low", "binding_high", "empty"} <= set(realised)
    assert realised["empty"] is False and realised["s_low"] < 1.0 < realised["s_high"]
    assert realised["s_high"] <= data["s_max"]


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["--realised-fraction", "2"], "--realised-fraction"),
        (["--realised-gravity", "-1"], "--realised-gravity"),
        (["--recommend", "x.toml", "--scan"], "--recommend"),
    ],
)
def test_bad_window_options_are_one_line_refusals(capsys, tmp_path, args, fragment):
    args = [a if a != "x.toml" else str(tmp_path / "x.toml") for a in args]
    assert main(["frontier", str(CHAPLYGIN), "--quiet", *args]) == 2
    captured = capsys.readouterr()
    lines = captured.err.strip().splitlines()
    assert captured.out == "" and len(lines) == 1 and fragment in lines[0]
    assert not (tmp_path / "x.toml").exists()


def test_frontier_out_draws_the_window(tmp_path, capsys):
    out = tmp_path / "window"
    assert main(["frontier", str(CHAPLYGIN), "--out", str(out), "--quiet"]) == 0
    assert "realised window: s = " in capsys.readouterr().out
    picture = out / "realised_window.png"
    assert picture.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert sorted(p.name for p in out.iterdir()) == ["realised_window.png"]
