"""The scene-verdict corpus (tools/scene_verdicts.py) writes the scenes it means and records
each verdict: accepted, or the refusal's one line."""

from __future__ import annotations

import importlib.util
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("scene_verdicts", ROOT / "tools/scene_verdicts.py")
assert _spec is not None and _spec.loader is not None
scene_verdicts = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(scene_verdicts)


def test_every_base_scene_and_probe_round_trips_through_the_toml_it_writes() -> None:
    for base in scene_verdicts._bases().values():
        assert tomllib.loads(scene_verdicts._toml(base)) == base
        for value in scene_verdicts.PROBES:
            probed = scene_verdicts._set(base, ("design", "tol"), value)
            assert tomllib.loads(scene_verdicts._toml(probed))["design"]["tol"] == value


def test_the_corpus_walks_every_table_and_records_refusals_by_their_line() -> None:
    keys = scene_verdicts._keys()
    assert {path[0] for path in keys} >= {"parameters", "fields", "design", "body", "testbed"}
    assert ("fields", "magnetic", "a1") in keys
    assert scene_verdicts._enums(("design", "objective")) == ["l1", "l2", "linf", "robust"]
