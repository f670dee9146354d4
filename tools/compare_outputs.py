"""Before/after comparison of every command's output: a refactor must change none of it.

    python tools/compare_outputs.py snapshot DIR [--quick]   # run every case into DIR
    python tools/compare_outputs.py compare BEFORE AFTER      # exit 1 on any difference

A case is one command line run with the installed ``chargedesign`` in a fresh folder: its exit
code, its standard output and error, and every file it writes are kept. ``compare`` then
holds the two snapshots against each other:

- exit codes and file lists must be equal;
- JSON files are compared value by value: strings, booleans and keys exactly, numbers to
  round-off (``RTOL`` relative to the largest magnitude of the array they sit in), and
  timing keys (``seconds``, ``time``, ``elapsed``...) are skipped;
- text (stdout, stderr, report.md, CSV) is split into numbers and words: the words must be
  equal, the numbers equal to ``TEXT_RTOL``, except on lines that report timings;
- pictures (PNG) and binary files are compared by size only within 10 % (renderers differ
  in their last bytes from run to run).

The cases cover the embedded default scene, the example scenes and a set of bad inputs
(their one-line errors and exit codes). A snapshot also holds
``scene_verdicts/verdicts.json``: every key of the scene schema set to a fixed set of probe
values in three base scenes, and whether the scene was accepted or the one-line error that
refused it (``tools/scene_verdicts.py``), so that the scene's validators must accept and
refuse exactly what they did.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import subprocess
import sys
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
RTOL = 1e-8
TEXT_RTOL = 1e-6
TIMING_KEYS = re.compile(r"(second|time|elapsed|wall|duration|timing|_s_per_|compile)", re.I)
TIMING_LINE = re.compile(
    r"(\bin [0-9.e+-]+ ?m?s\b|\btook\b|seconds|\bwall\b|\bs/point\b|eta |timings?\b|compile)", re.I
)
NUMBER = re.compile(r"[-+]?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?")
TEXT_SUFFIXES = {".txt", ".md", ".csv", ".toml", ".json", ".log"}
TIMEOUT_S = 900


def cases(quick: bool) -> list[tuple[str, list[str]]]:
    """(name, argv after ``chargedesign``); ``{out}`` is the case's own folder."""
    unit = str(ROOT / "examples" / "scenes" / "unit_scale.toml")
    small = str(ROOT / "tests" / "physical" / "small.toml")
    listed: list[tuple[str, list[str]]] = [
        ("verify", ["verify", "--json"]),
        ("conditions_default", ["conditions"]),
        ("conditions_unit", ["conditions", unit, "--json"]),
        ("design_unit", ["design", unit, "--out", "{out}/d"]),
        ("design_small", ["design", small, "--out", "{out}/d"]),
        ("check_unit", ["design", unit, "--out", "{out}/d", "&&", "check", "{out}/d/design.json"]),
        ("frontier_small", ["frontier", small, "--json"]),
        (
            "simulate_kowalevski",
            ["simulate", str(ROOT / "examples/simulate_kowalevski.toml"), "--out", "{out}/s"],
        ),
        (
            "simulate_pendulum",
            ["simulate", str(ROOT / "examples/simulate_pendulum.toml"), "--out", "{out}/s"],
        ),
        ("schema_design", ["schema", "design"]),
        ("schema_scene", ["schema", "scene"]),
        ("bad_no_scene", ["design", "{out}/missing.toml", "--out", "{out}/d"]),
        ("bad_check_missing", ["check", "{out}/missing.json"]),
        ("bad_export_format", ["export", "{out}/missing.json", "--format", "xyz", "--out", "x"]),
    ]
    if not quick:
        listed += [
            ("design_default", ["design", "--out", "{out}/d"]),
            (
                "design_yehia2003",
                ["design", str(ROOT / "examples/scenes/yehia2003.toml"), "--out", "{out}/d"],
            ),
            (
                "design_thin_slab",
                ["design", str(ROOT / "examples/scenes/thin_slab.toml"), "--out", "{out}/d"],
            ),
            (
                "tolerance_unit",
                [
                    "design",
                    unit,
                    "--out",
                    "{out}/d",
                    "&&",
                    "tolerance",
                    "{out}/d/design.json",
                    "--no-simulate",
                ],
            ),
            (
                "export_unit",
                [
                    "design",
                    unit,
                    "--out",
                    "{out}/d",
                    "&&",
                    "export",
                    "{out}/d/design.json",
                    "--format",
                    "csv",
                    "--out",
                    "{out}/e.csv",
                ],
            ),
        ]
    return listed


def _run(argv: list[str], folder: Path) -> dict[str, Any]:
    exe = Path(sys.executable).with_name("chargedesign")
    steps, current = [], []
    for token in argv:
        if token == "&&":
            steps.append(current)
            current = []
        else:
            current.append(token.replace("{out}", str(folder)))
    steps.append(current)
    record: dict[str, Any] = {"steps": []}
    env = {**os.environ, "MPLBACKEND": "Agg", "PYVISTA_OFF_SCREEN": "true"}
    for step in steps:
        proc = subprocess.run(
            [str(exe), *step],
            cwd=folder,
            capture_output=True,
            text=True,
            timeout=TIMEOUT_S,
            env=env,
        )
        # the case's own folder differs between snapshots: name it {out} in what was printed
        record["steps"].append(
            {
                "argv": [a.replace(str(folder), "{out}") for a in step],
                "exit": proc.returncode,
                "stdout": proc.stdout.replace(str(folder), "{out}"),
                "stderr": proc.stderr.replace(str(folder), "{out}"),
            }
        )
        if proc.returncode != 0:
            break
    return record


def snapshot(out: Path, quick: bool) -> None:
    if out.exists():
        raise SystemExit(f"{out}: exists; choose a new folder")
    out.mkdir(parents=True)
    for name, argv in cases(quick):
        folder = out / name
        folder.mkdir()
        print(f"{name}: chargedesign {' '.join(argv)}", file=sys.stderr, flush=True)
        record = _run(argv, folder)
        (folder / "_record.json").write_text(json.dumps(record, indent=1))
    folder = out / "scene_verdicts"
    folder.mkdir()
    print("scene_verdicts: tools/scene_verdicts.py", file=sys.stderr, flush=True)
    subprocess.run(
        [sys.executable, str(ROOT / "tools" / "scene_verdicts.py"), str(folder / "verdicts.json")],
        check=True,
        timeout=TIMEOUT_S,
    )


# ------------------------------------------------------------------------------ compare
def _numbers_close(a: float, b: float, scale: float, rtol: float) -> bool:
    if math.isnan(a) or math.isnan(b):
        return math.isnan(a) and math.isnan(b)
    if math.isinf(a) or math.isinf(b):
        return a == b
    return abs(a - b) <= rtol * max(abs(a), abs(b), scale) or a == b


def _scale(values: list[Any]) -> float:
    nums = [abs(v) for v in values if isinstance(v, (int, float)) and not isinstance(v, bool)]
    nums = [v for v in nums if math.isfinite(v)]
    return max(nums, default=0.0)


def compare_json(a: Any, b: Any, where: str, diffs: list[str], scale: float = 0.0) -> None:
    """Append to ``diffs`` every difference between two JSON values beyond round-off."""
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            diffs.append(f"{where}: keys differ: {sorted(set(a) ^ set(b))}")
        for key in sorted(set(a) & set(b)):
            if TIMING_KEYS.search(str(key)):
                continue
            compare_json(a[key], b[key], f"{where}.{key}", diffs)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            diffs.append(f"{where}: lengths {len(a)} != {len(b)}")
            return
        inner = max(scale, _scale(a), _scale(b))
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            compare_json(x, y, f"{where}[{i}]", diffs, inner)
    elif isinstance(a, str) and isinstance(b, str):
        if _ROOTS and a.replace(_ROOTS[0], "{snapshot}") != b.replace(_ROOTS[1], "{snapshot}"):
            diffs.append(f"{where}: {a!r} != {b!r}")
    elif isinstance(a, bool) or isinstance(b, bool) or isinstance(a, str) or isinstance(b, str):
        if a != b:
            diffs.append(f"{where}: {a!r} != {b!r}")
    elif isinstance(a, (int, float)) and isinstance(b, (int, float)):
        if not _numbers_close(float(a), float(b), scale, RTOL):
            diffs.append(f"{where}: {a!r} != {b!r}")
    elif a != b:
        diffs.append(f"{where}: {a!r} != {b!r}")


def compare_text(a: str, b: str, where: str, diffs: list[str]) -> None:
    """Words equal, numbers to TEXT_RTOL; lines that report timings are skipped."""
    if _ROOTS:
        a, b = a.replace(_ROOTS[0], "{snapshot}"), b.replace(_ROOTS[1], "{snapshot}")
    lines_a, lines_b = a.splitlines(), b.splitlines()
    if len(lines_a) != len(lines_b):
        diffs.append(f"{where}: {len(lines_a)} lines != {len(lines_b)}")
        return
    for i, (x, y) in enumerate(zip(lines_a, lines_b, strict=True)):
        if TIMING_LINE.search(x) and TIMING_LINE.search(y):
            continue
        if NUMBER.sub("#", x) != NUMBER.sub("#", y):
            diffs.append(f"{where}:{i + 1}: {x.strip()!r} != {y.strip()!r}")
            continue
        for u, v in zip(NUMBER.findall(x), NUMBER.findall(y), strict=True):
            if not _numbers_close(float(u), float(v), 0.0, TEXT_RTOL):
                diffs.append(f"{where}:{i + 1}: {u} != {v} in {x.strip()!r}")
                break


def compare_file(a: Path, b: Path, where: str, diffs: list[str]) -> None:
    if a.suffix == ".json":
        try:
            ja, jb = json.loads(a.read_text()), json.loads(b.read_text())
        except (json.JSONDecodeError, UnicodeDecodeError):
            compare_text(a.read_text(errors="replace"), b.read_text(errors="replace"), where, diffs)
            return
        if a.name == "_record.json":
            compare_records(ja, jb, where, diffs)
        else:
            compare_json(ja, jb, where, diffs)
    elif a.suffix in TEXT_SUFFIXES:
        compare_text(a.read_text(errors="replace"), b.read_text(errors="replace"), where, diffs)
    else:
        sa, sb = a.stat().st_size, b.stat().st_size
        if abs(sa - sb) > 0.1 * max(sa, sb, 1):
            diffs.append(f"{where}: size {sa} != {sb}")


def compare_records(a: dict[str, Any], b: dict[str, Any], where: str, diffs: list[str]) -> None:
    if len(a["steps"]) != len(b["steps"]):
        diffs.append(f"{where}: {len(a['steps'])} steps ran != {len(b['steps'])}")
        return
    for i, (x, y) in enumerate(zip(a["steps"], b["steps"], strict=True)):
        if x["exit"] != y["exit"]:
            diffs.append(f"{where} step {i}: exit {x['exit']} != {y['exit']}")
        for stream in ("stdout", "stderr"):
            tx, ty = x[stream], y[stream]
            try:
                compare_json(json.loads(tx), json.loads(ty), f"{where} {stream}", diffs)
            except json.JSONDecodeError:
                compare_text(tx, ty, f"{where} step {i} {stream}", diffs)


def _files(folder: Path) -> set[str]:
    return {str(p.relative_to(folder)) for p in folder.rglob("*") if p.is_file()}


#: the two snapshot folders being compared (paths inside outputs differ by them only)
_ROOTS: list[str] = []


def compare(before: Path, after: Path) -> list[str]:
    """Every difference between two snapshots (empty: the same behaviour)."""
    _ROOTS[:] = [str(before.resolve()), str(after.resolve())]
    diffs: list[str] = []
    fa, fb = _files(before), _files(after)
    for name in sorted(fa ^ fb):
        diffs.append(f"{name}: only in {'before' if name in fa else 'after'}")
    for name in sorted(fa & fb):
        compare_file(before / name, after / name, name, diffs)
    return diffs


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = parser.add_subparsers(dest="verb", required=True)
    snap = sub.add_parser("snapshot", help="run every case into DIR")
    snap.add_argument("dir", type=Path)
    snap.add_argument("--quick", action="store_true", help="leave out the slower cases")
    comp = sub.add_parser("compare", help="compare two snapshots")
    comp.add_argument("before", type=Path)
    comp.add_argument("after", type=Path)
    args = parser.parse_args(argv)
    if args.verb == "snapshot":
        snapshot(args.dir, args.quick)
        return 0
    diffs = compare(args.before, args.after)
    for line in diffs:
        print(line)
    print(f"{len(diffs)} difference(s)" if diffs else "the same behaviour", file=sys.stderr)
    return 1 if diffs else 0


if __name__ == "__main__":
    sys.exit(main())
