"""The before/after comparison (tools/compare_outputs.py) sees a change and forgives round-off."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
_spec = importlib.util.spec_from_file_location("compare_outputs", ROOT / "tools/compare_outputs.py")
assert _spec is not None and _spec.loader is not None
compare_outputs = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(compare_outputs)

DESIGN = {"charges": {"values": [1.0e-9, -2.0e-9, 3.0e-21]}, "seconds": 1.0, "solver": "HIGHS"}
REPORT = "Verdict: buildable\nlargest field 0.4996 of breakdown\nTimings: setup 0.75 s\n"


def _snapshot(folder: Path, design: dict, report: str, exit_code: int = 0) -> Path:
    case = folder / "design_case"
    case.mkdir(parents=True)
    (case / "design.json").write_text(json.dumps(design))
    (case / "report.md").write_text(report)
    record = {"steps": [{"argv": ["design"], "exit": exit_code, "stdout": report, "stderr": ""}]}
    (case / "_record.json").write_text(json.dumps(record))
    return folder


def test_round_off_and_timings_are_the_same_behaviour(tmp_path: Path) -> None:
    before = _snapshot(tmp_path / "a", DESIGN, REPORT)
    noisy = json.loads(json.dumps(DESIGN))
    noisy["charges"]["values"][0] *= 1 + 1e-12
    noisy["charges"]["values"][2] += 1e-30  # tiny against the array's largest magnitude
    noisy["seconds"] = 7.0
    after = _snapshot(tmp_path / "b", noisy, REPORT.replace("0.75 s", "0.91 s"))
    assert compare_outputs.compare(before, after) == []


def test_a_changed_number_word_exit_code_or_file_is_found(tmp_path: Path) -> None:
    before = _snapshot(tmp_path / "a", DESIGN, REPORT)
    changed = json.loads(json.dumps(DESIGN))
    changed["charges"]["values"][1] *= 1 + 1e-6
    changed["solver"] = "CLARABEL"
    after = _snapshot(tmp_path / "b", changed, REPORT.replace("buildable", "refused"), 1)
    (after / "design_case" / "extra.csv").write_text("x\n")
    diffs = "\n".join(compare_outputs.compare(before, after))
    assert "charges.values[1]" in diffs
    assert "'HIGHS' != 'CLARABEL'" in diffs
    assert "buildable" in diffs and "exit 0 != 1" in diffs
    assert "extra.csv: only in after" in diffs
