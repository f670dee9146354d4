"""Scenes the tests share: the unit-scale mathematical case (the embedded default is now a
buildable SI body, which the physical tests cover)."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

UNIT_SCENE = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "unit_scale.toml"


def unit_design(n: float) -> Any:
    """The unit-scale body designed with the theorem's n replaced by ``n`` (a Design)."""
    from chargedesign.designer import design_from_scene
    from chargedesign.scene import scene_from_dict

    data = tomllib.loads(UNIT_SCENE.read_text())
    data["parameters"]["n"] = n
    return design_from_scene(scene_from_dict(data)).design
