"""Run the benchmark areas and write their tables and plots."""

from __future__ import annotations

import importlib
import os
import platform
from collections.abc import Callable, Iterable
from pathlib import Path
from typing import Any

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


def _group_column(table: BenchTable, spec: dict) -> int | None:
    """The column whose values split the rows into separate lines.

    ``spec["group"]`` when given; else the first text column (not the x or y columns) with
    at least two values, each shared by several rows (e.g. ``method``: DOP853 rows and
    Gauss-Legendre rows are two lines, never one line joining them).
    """
    if spec.get("group"):
        return table.columns.index(spec["group"])
    used = {spec.get("x"), *spec.get("y", []), *spec.get("y2", [])}
    for i, name in enumerate(table.columns):
        if name in used:
            continue
        values = [row[i] for row in table.rows]
        if values and all(isinstance(v, str) for v in values):
            distinct = set(values)
            if 2 <= len(distinct) < len(values):
                return i
    return None


def plot_table(table: BenchTable, axes: Any = None) -> Any:
    """Draw a table per ``table.plot`` into matplotlib axes; returns the figure.

    x column, ``y`` columns (left panel), optional ``y2`` columns (right panel), one line per
    group (:func:`_group_column`); y labels from ``ylabel``/``ylabel2`` or the columns' names.

    Parameters
    ----------
    table : BenchTable
    axes : matplotlib Axes or sequence of Axes, optional
        One axes per panel (1, or 2 with ``y2``); default: a new figure.
    """
    spec = table.plot or {}
    panels = [("y", "logy", "ylabel")] + ([("y2", "logy2", "ylabel2")] if spec.get("y2") else [])
    if axes is None:
        import matplotlib.pyplot as plt

        fig, grid = plt.subplots(1, len(panels), figsize=(6 * len(panels), 4), squeeze=False)
        axes_list = list(grid[0])
        fig.suptitle(table.title, fontsize=10)
    else:
        axes_list = list(axes) if isinstance(axes, (list, tuple)) else [axes]
        if len(axes_list) != len(panels):
            raise ValueError(f"plot_table: {len(panels)} axes needed, got {len(axes_list)}")
        fig = axes_list[0].figure
    xi = table.columns.index(spec["x"])
    gi = _group_column(table, spec)
    groups = sorted({row[gi] for row in table.rows}, key=str) if gi is not None else [None]
    for ax, (key, logkey, labelkey) in zip(axes_list, panels, strict=True):
        for name in spec[key]:
            yi = table.columns.index(name)
            for group in groups:
                pairs = [
                    (row[xi], row[yi])
                    for row in table.rows
                    if isinstance(row[yi], (int, float)) and (gi is None or row[gi] == group)
                ]
                if all(isinstance(p[0], (int, float)) for p in pairs):
                    pairs.sort(key=lambda p: p[0])  # a line runs left to right
                label = name if group is None else f"{group}: {name}"
                ax.plot([p[0] for p in pairs], [p[1] for p in pairs], "o-", label=label)
        if spec.get("logx"):
            ax.set_xscale("log")
        if spec.get(logkey):
            ax.set_yscale("log")
        ax.set_xlabel(spec["x"])
        ax.set_ylabel(spec.get(labelkey) or ", ".join(spec[key]))
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    return fig


def _plot(table: BenchTable, path: Path) -> None:
    """Plot a table (:func:`plot_table`) into a PNG, written atomically."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plot_table(table)
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
