"""Run the benchmark areas and write their tables and plots."""

from __future__ import annotations

import importlib
import os
import platform
from collections.abc import Callable, Iterable
from pathlib import Path

from chargedesign.bench.common import BenchTable
from chargedesign.files import atomic_path, write_text_atomic


def run_benchmarks(
    areas: Iterable[str], *, quick: bool = False, progress: Callable[[str], None] | None = None
) -> list[BenchTable]:
    """Run ``chargedesign.bench.<area>.run(quick)`` for each area, in order."""
    tables: list[BenchTable] = []
    for area in areas:
        if progress is not None:
            progress(area)
        module = importlib.import_module(f"chargedesign.bench.{area}")
        tables.extend(module.run(quick=quick))
    return tables


def _plot(table: BenchTable, path: Path) -> None:
    """Plot per ``table.plot``: x column, ``y`` columns (left panel), optional ``y2`` columns
    (right panel), optional ``group`` column (one line per distinct value)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spec = table.plot or {}
    panels = [("y", "logy")] + ([("y2", "logy2")] if spec.get("y2") else [])
    fig, axes = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4), squeeze=False)
    xi = table.columns.index(spec["x"])
    gi = table.columns.index(spec["group"]) if spec.get("group") else None
    groups = sorted({row[gi] for row in table.rows}, key=str) if gi is not None else [None]
    for ax, (key, logkey) in zip(axes[0], panels, strict=True):
        for name in spec[key]:
            yi = table.columns.index(name)
            for group in groups:
                pairs = [
                    (row[xi], row[yi])
                    for row in table.rows
                    if isinstance(row[yi], (int, float)) and (gi is None or row[gi] == group)
                ]
                label = name if group is None else f"{group}: {name}"
                ax.plot([p[0] for p in pairs], [p[1] for p in pairs], "o-", label=label)
        if spec.get("logx"):
            ax.set_xscale("log")
        if spec.get(logkey):
            ax.set_yscale("log")
        ax.set_xlabel(spec["x"])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(table.title, fontsize=10)
    fig.tight_layout()
    with atomic_path(path) as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


def write_report(tables: list[BenchTable], out_dir: str | os.PathLike[str]) -> Path:
    """Write ``benchmarks.md`` (tables) and ``images/bench_*.png`` (plots) into ``out_dir``."""
    out = Path(out_dir)
    (out / "images").mkdir(parents=True, exist_ok=True)
    lines = [
        "# Benchmarks",
        "",
        "Measured by `chargedesign bench --out docs` on "
        f"{platform.machine()} with {os.cpu_count()} cores, Python {platform.python_version()}. "
        "Every table states its baseline, measured in the same run; ratios are relative to it.",
        "",
    ]
    for i, table in enumerate(tables):
        lines.append(table.to_markdown())
        if table.plot:
            name = f"bench_{i:02d}.png"
            _plot(table, out / "images" / name)
            lines.append(f"![{table.title}](images/{name})\n")
    path = out / "benchmarks.md"
    write_text_atomic(path, "\n".join(lines))
    return path
