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
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    spec = table.plot or {}
    xi = table.columns.index(spec["x"])
    fig, ax = plt.subplots(figsize=(6, 4))
    for name in spec["y"]:
        yi = table.columns.index(name)
        pairs = [(row[xi], row[yi]) for row in table.rows if row[yi] is not None]
        ax.plot([p[0] for p in pairs], [p[1] for p in pairs], "o-", label=name)
    if spec.get("logx"):
        ax.set_xscale("log")
    if spec.get("logy"):
        ax.set_yscale("log")
    ax.set_xlabel(spec["x"])
    ax.set_title(table.title)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend()
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
