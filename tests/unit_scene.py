"""Scenes the tests share: the unit-scale mathematical case (the embedded default is now a
buildable SI body, which the physical tests cover)."""

from pathlib import Path

UNIT_SCENE = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "unit_scale.toml"
