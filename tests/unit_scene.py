"""Scenes the tests share: the unit-scale mathematical case (the embedded default is now a
buildable SI body, which the physical tests cover)."""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Any

import numpy as np

from chargedesign.scene import load_scene

UNIT_SCENE = Path(__file__).resolve().parents[1] / "examples" / "scenes" / "unit_scale.toml"
#: the unit scene's theorem parameters (its [parameters], read from the file, not copied)
UNIT_PARAMETERS = load_scene(UNIT_SCENE).parameters
#: the Kowalevski inertia A = B = 2C about O of the unit case (C = 1)
UNIT_INERTIA = np.diag([2.0, 2.0, 1.0]) * UNIT_PARAMETERS.C


def unit_design(n: float) -> Any:
    """The unit-scale body designed with the theorem's n replaced by ``n`` (a Design)."""
    from chargedesign.designer import design_from_scene
    from chargedesign.scene import scene_from_dict

    data = tomllib.loads(UNIT_SCENE.read_text())
    data["parameters"]["n"] = n
    return design_from_scene(scene_from_dict(data)).design
