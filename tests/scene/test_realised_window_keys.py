"""[design] realised_fraction and realised_gravity: declared once, read by the design and the
frontier, refused in one line out of range; the frontier's options override them."""

from __future__ import annotations

from pathlib import Path

import pytest

from chargedesign.errors import InputError
from chargedesign.scene import load_scene
from chargedesign.scene.keys import declared

DEFAULT_SCENE = Path(__file__).resolve().parents[2] / "chargedesign" / "data" / "default_scene.toml"


def _scene(tmp_path: Path, extra: str) -> Path:
    text = DEFAULT_SCENE.read_text()
    assert "\n[design]\n" in text
    path = tmp_path / "s.toml"
    path.write_text(text.replace("\n[design]\n", "\n[design]\n" + extra + "\n", 1))
    return path


def test_defaults_come_from_the_declarations(tmp_path):
    scene = load_scene(_scene(tmp_path, ""))
    assert scene.design.realised_fraction == declared("design", "realised_fraction").default
    assert scene.design.realised_gravity == declared("design", "realised_gravity").default


def test_a_scene_sets_them(tmp_path):
    scene = load_scene(_scene(tmp_path, "realised_fraction = 0.01\nrealised_gravity = 0.0"))
    assert scene.design.realised_fraction == 0.01
    assert scene.design.realised_gravity == 0.0


@pytest.mark.parametrize(
    "line", ["realised_fraction = 0", "realised_fraction = 1", "realised_gravity = -1"]
)
def test_out_of_range_is_one_line(tmp_path, line):
    with pytest.raises(InputError) as err:
        load_scene(_scene(tmp_path, line))
    message = str(err.value)
    assert line.split(" ")[0] in message and "\n" not in message


def test_the_frontier_reads_the_scene_and_its_option_overrides(tmp_path, monkeypatch, capsys):
    import chargedesign.designer.pipeline as pipeline
    from chargedesign.cli import main

    seen = []

    def fake_frontier(*_, progress=None, window=None, **__):
        seen.append((window.fraction, window.gravity))
        raise InputError("stop here")

    # the command locates the frontier on the setup of the body at the scene's rate, or alone
    # on that setup when the rate is refused: both routes read the window
    monkeypatch.setattr(pipeline, "find_frontier", fake_frontier)
    path = _scene(tmp_path, "realised_fraction = 0.02")
    assert main(["frontier", str(path), "--quiet"]) == 2
    assert main(["frontier", str(path), "--quiet", "--realised-fraction", "0.3"]) == 2
    capsys.readouterr()
    assert seen == [(0.02, 9.80665), (0.3, 9.80665)]
