"""Issue 39's measure (tools/shared_functions.py): the twin it writes is the theorem's case, and
its "same body" sees a moved or missing element but forgives the last bits."""

from __future__ import annotations

import importlib.util
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location(
    "shared_functions", ROOT / "tools/shared_functions.py"
)
assert _spec is not None and _spec.loader is not None
shared_functions = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(shared_functions)

BODY = {
    "charge_positions": [[0.1, 0.0, 0.0], [-0.1, 0.0, 0.0]],
    "charge_values": [1.0e-9, -2.0e-9],
    "dipole_positions": [],
    "dipole_moments": [],
    "mass_positions": [[0.0, 0.0, 0.2]],
    "mass_values": [0.5],
}


def test_the_same_body_to_the_last_bits_and_a_different_one() -> None:
    noisy = {**BODY, "charge_values": [1.0e-9 * (1 + 1e-13), -2.0e-9]}
    assert shared_functions.body_difference(BODY, noisy) <= shared_functions.SAME_BODY
    moved = {**BODY, "mass_positions": [[0.0, 0.0, 0.21]]}
    assert shared_functions.body_difference(BODY, moved) > shared_functions.SAME_BODY
    fewer = {**BODY, "charge_values": [1.0e-9], "charge_positions": [[0.1, 0.0, 0.0]]}
    assert shared_functions.body_difference(BODY, fewer) == float("inf")


def test_the_twin_is_the_scene_with_the_theorems_case(tmp_path: Path) -> None:
    scene = ROOT / "examples" / "scenes" / "unit_scale.toml"
    twin = tomllib.loads(shared_functions.write_twin(scene, tmp_path / "twin.toml").read_text())
    given = tomllib.loads(scene.read_text("utf-8"))
    assert "parameters" not in twin and "simulation" not in twin
    assert twin["case"]["level"] == 0 and twin["case"]["inertia"] == ["2", "2", "1"]
    assert {k: v for k, v in twin.items() if k != "case"} == {
        k: v for k, v in given.items() if k not in ("parameters", "simulation")
    }
