"""The induced magnetisation, one figure (issue 38, item 2): computed in one place
(:func:`chargedesign.physical.budget.induced_magnetisation`), printed under one name, with
its reference and rate beside it, and the same number in every output of one design:
report.md (summary, verdict row, budget table), design.json, ``design``'s terminal,
``frontier`` (text and ``--json``) and ``check`` (text and ``--json``, recomputed). The K law
is printed as the law, never under the figure's name."""

from __future__ import annotations

import contextlib
import io
import json
import re
from pathlib import Path

import pytest

from chargedesign.cli import main
from chargedesign.formatting import ROUGH, fmt
from chargedesign.scene.design_realism import INDUCED_NAME, INDUCED_REFERENCE, parasitic_text

#: a small K != 0 body in air (the carriers' breakdown binds): designed in seconds
SCENE = Path(__file__).resolve().parent / "physical" / "small.toml"

#: the one figure as every output prints it: name, value, reference, term, rate
FIGURE = re.compile(
    rf"{INDUCED_NAME}(?: \(of the \w+ term\))?[:|\s]+(\S+) {INDUCED_REFERENCE} \((\w+)\) at s = 1\b"
)
#: how the effect was printed before under the same name with other meanings
STALE = (
    "induced magnetisation at the K frontier",
    "induced magnetisation fraction",
    "Induced magnetisation:",
)


def _printed(text: str) -> set[tuple[str, str]]:
    """Every (value, term) of the one figure at s = 1 in ``text`` (whitespace joined, so a
    figure wrapped over two lines of a table or terminal is found too)."""
    joined = " ".join(text.replace("|", " | ").split())
    return set(FIGURE.findall(joined))


@pytest.fixture(scope="module")
def outputs(tmp_path_factory: pytest.TempPathFactory) -> dict[str, str]:
    """Every output of one design (the commands run in this process, their stdout kept)."""
    out = tmp_path_factory.mktemp("induced") / "out"
    texts: dict[str, str] = {}

    def run(name: str, args: list[str]) -> None:
        buffer = io.StringIO()
        with contextlib.redirect_stdout(buffer), contextlib.redirect_stderr(io.StringIO()):
            assert main(args) == 0
        texts[name] = buffer.getvalue()

    run("design stdout", ["design", str(SCENE), "--out", str(out), "--no-picture", "--quiet"])
    texts["report.md"] = (out / "report.md").read_text()
    texts["design.json"] = (out / "design.json").read_text()
    run("frontier --json", ["frontier", str(SCENE), "--json", "--quiet"])
    run("frontier", ["frontier", str(SCENE), "--quiet"])
    check = ["check", str(out / "design.json"), "--orientations", "200"]
    run("check --json", [*check, "--json"])
    run("check", check)
    return texts


def test_one_figure_one_name_one_value_everywhere(outputs: dict[str, str]) -> None:
    record = json.loads(outputs["design.json"])["realism"]["induced_magnetisation"]
    assert record["name"] == INDUCED_NAME and record["unit"] == INDUCED_REFERENCE
    assert record["s"] == 1.0 and record["value"] > 0
    shown = fmt(record["value"], ROUGH)
    one = {(shown, record["term"])}
    # the verdict's item is the same figure (design.json's verdict record)
    verdict = json.loads(outputs["design.json"])["verdict"]
    (item,) = [i for i in verdict["items"] if i["name"].startswith(INDUCED_NAME)]
    assert fmt(item["value"], ROUGH) == shown and item["unit"] == INDUCED_REFERENCE
    # the JSON outputs carry the record (check recomputes it from the written parts)
    frontier = json.loads(outputs["frontier --json"])
    assert frontier["induced_magnetisation"]["name"] == INDUCED_NAME
    assert fmt(frontier["induced_magnetisation"]["value"], ROUGH) == shown
    check = json.loads(outputs["check --json"])
    assert check["induced_magnetisation"]["value"] == pytest.approx(record["value"], rel=1e-9)
    # the text outputs print it, and only it, under its name at s = 1
    for name in ("report.md", "design stdout", "frontier", "check"):
        assert _printed(outputs[name]) == one, name
        for stale in STALE:
            assert stale not in outputs[name], (name, stale)
    # the report's summary, its verdict row and its budget table
    report = outputs["report.md"]
    summary = report.split("## Detail")[0]
    figure = parasitic_text(record["value"], record["term"], 1.0)
    assert f"- {INDUCED_NAME}: {figure}" in summary
    assert f"| induced_magnetisation | {figure} |" in report


def test_the_k_law_is_named_as_the_law(outputs: dict[str, str]) -> None:
    realism = json.loads(outputs["design.json"])["realism"]
    law = realism["k_law_induced_ratio"]
    frontier = json.loads(outputs["frontier --json"])["k_law_induced_ratio"]
    assert frontier["name"] == "the K law" and frontier["value"] == law["value"]
    for name in ("report.md", "frontier", "check"):
        text = " ".join(outputs[name].split())
        assert f"{fmt(law['value'])} x the designed K torques C K_max^2" in text, name
        assert "K law" in text, name


def test_design_keeps_the_terminal_rules(outputs: dict[str, str]) -> None:
    lines = outputs["design stdout"].splitlines()
    assert len(lines) <= 40 and max(len(x) for x in lines) <= 160
