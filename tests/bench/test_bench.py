"""Smoke test of `chargedesign bench`: every area runs (quick sizes) and writes its report.

Benchmarks measure; this test only checks that the tables are complete and finite, never a time.
"""

import json
import math

from chargedesign.bench.runner import run_benchmarks
from chargedesign.cli import main
from chargedesign.commands.bench import AREAS


def _numbers(rows):
    for row in rows:
        for value in row:
            if isinstance(value, float):
                yield value


def test_every_area_reports_tables_with_ratios_to_a_baseline():
    tables = run_benchmarks(AREAS, quick=True)
    titles = [t.title for t in tables]
    assert len(tables) >= len(AREAS)
    assert len(set(titles)) == len(titles)
    for table in tables:
        assert table.rows, table.title
        assert all(len(row) == len(table.columns) for row in table.rows), table.title
        assert all(not math.isnan(v) for v in _numbers(table.rows)), table.title
    # each area states its ratios against a baseline of the same run
    assert sum(any("ratio" in c or "/" in c or "x" in c for c in t.columns) for t in tables) >= len(
        AREAS
    )


def test_cli_writes_markdown_and_plots(tmp_path, capsys):
    args = ["bench", "--quick", "--only", "fields", "--only", "simulate", "--json"]
    code = main([*args, "--out", str(tmp_path)])
    assert code == 0
    out = json.loads(capsys.readouterr().out)
    assert {t["title"] for t in out}
    text = (tmp_path / "benchmarks.md").read_text()
    for table in out:
        assert table["title"] in text
    plots = sorted((tmp_path / "images").glob("bench_*.png"))
    assert len(plots) == sum(1 for t in out if t.get("plot"))
