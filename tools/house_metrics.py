"""The house's figures (issue 33), counted from the source alone, so a refactor's before and
after can be compared:

    python tools/house_metrics.py [--json]

- lines per subpackage (``chargedesign/<sub>/``; top-level modules as ``(top)``) and the share
  of those lines that sit inside docstrings (module, class and function docstrings, by ``ast``);
- files per multi-word scene key: every key of the scene schema (``chargedesign schema
  scene``, walked through every table) whose name holds an underscore, and the number of
  package files in which it occurs as a string literal exactly (an output of the same name
  counts too);
- ``InputError`` raise sites outside the boundary modules: ``raise InputError(...)`` and
  ``raise input_error(...)`` statements, by module;
- package imports per module (issue 39): for each package module, the distinct other package
  modules it imports at any level (``from chargedesign.a import b`` counts ``chargedesign.a.b``
  when that is a module, else ``chargedesign.a``; relative imports resolved), and their mean.
"""

from __future__ import annotations

import argparse
import ast
import json
import statistics
import sys
from collections import Counter
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "chargedesign"
#: the boundary: modules (by dotted name part) whose InputErrors are where they belong
BOUNDARY = (
    "scene",
    "validation",
    "readers",
    "files",
    "limits",
    "errors",
    "formatting",
    "options",
    "schemas",
    "commands",
    "cli",
)
RAISERS = ("InputError", "input_error")


def _modules() -> list[Path]:
    return sorted(PACKAGE.rglob("*.py"))


def _docstring_lines(tree: ast.Module) -> int:
    lines = 0
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if (
                body
                and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant)
                and isinstance(body[0].value.value, str)
            ):
                first = body[0]
                lines += (first.end_lineno or first.lineno) - first.lineno + 1
    return lines


def lines_per_subpackage() -> dict[str, dict[str, int]]:
    """``{subpackage: {"lines": n, "docstring_lines": m}}`` and a ``(total)`` row."""
    out: dict[str, Counter[str]] = {}
    for path in _modules():
        rel = path.relative_to(PACKAGE)
        group = rel.parts[0] if len(rel.parts) > 1 else "(top)"
        text = path.read_text("utf-8")
        counts = out.setdefault(group, Counter())
        counts["lines"] += len(text.splitlines())
        counts["docstring_lines"] += _docstring_lines(ast.parse(text))
    total: Counter[str] = Counter()
    for counts in out.values():
        total.update(counts)
    rows = {k: dict(v) for k, v in sorted(out.items())}
    rows["(total)"] = dict(total)
    return rows


def _schema_keys(node: Any, found: set[str]) -> None:
    if isinstance(node, dict):
        for key, value in node.get("properties", {}).items():
            found.add(key)
            _schema_keys(value, found)
        for key, value in node.items():
            if key != "properties":
                _schema_keys(value, found)
    elif isinstance(node, list):
        for item in node:
            _schema_keys(item, found)


def _string_literals(path: Path) -> set[str]:
    tree = ast.parse(path.read_text("utf-8"))
    return {
        node.value
        for node in ast.walk(tree)
        if isinstance(node, ast.Constant) and isinstance(node.value, str)
    }


def files_per_key() -> dict[str, int]:
    """Every multi-word scene key -> the package files holding it as a string literal."""
    sys.path.insert(0, str(ROOT))
    from chargedesign.schemas import schema

    keys: set[str] = set()
    _schema_keys(schema("scene"), keys)
    multi = sorted(k for k in keys if "_" in k)
    literals = {path: _string_literals(path) for path in _modules()}
    return {key: sum(key in found for found in literals.values()) for key in multi}


def _in_boundary(path: Path) -> bool:
    parts = path.relative_to(PACKAGE).with_suffix("").parts
    return any(part in BOUNDARY for part in parts)


def _raise_sites(path: Path) -> int:
    tree = ast.parse(path.read_text("utf-8"))
    count = 0
    for node in ast.walk(tree):
        if isinstance(node, ast.Raise) and isinstance(node.exc, ast.Call):
            func = node.exc.func
            name = func.id if isinstance(func, ast.Name) else getattr(func, "attr", "")
            count += name in RAISERS
    return count


def input_error_sites() -> dict[str, int]:
    """Modules outside the boundary -> their InputError raise sites (those with any)."""
    out = {}
    for path in _modules():
        if _in_boundary(path):
            continue
        n = _raise_sites(path)
        if n:
            out[str(path.relative_to(ROOT))] = n
    return dict(sorted(out.items(), key=lambda kv: (-kv[1], kv[0])))


def _module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_imports() -> dict[str, int]:
    """Every package module -> how many distinct other package modules it imports."""
    names = {_module_name(path): path for path in _modules()}
    out = {}
    for name, path in names.items():
        package = name.split(".") if path.name == "__init__.py" else name.split(".")[:-1]
        found: set[str] = set()
        for node in ast.walk(ast.parse(path.read_text("utf-8"))):
            if isinstance(node, ast.Import):
                found.update(a.name for a in node.names if a.name.startswith("chargedesign"))
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package[: len(package) - node.level + 1]
                    module = ".".join(base + ([node.module] if node.module else []))
                else:
                    module = node.module or ""
                if not module.startswith("chargedesign"):
                    continue
                for alias in node.names:
                    sub = f"{module}.{alias.name}"
                    found.add(sub if sub in names else module)
        found.discard(name)
        out[name] = len(found)
    return out


def metrics() -> dict[str, Any]:
    keys = files_per_key()
    sites = input_error_sites()
    return {
        "lines": lines_per_subpackage(),
        "files_per_key": keys,
        "files_per_key_mean": statistics.fmean(keys.values()) if keys else 0.0,
        "files_per_key_max": max(keys.values(), default=0),
        "input_error_sites": sites,
        "input_error_sites_total": sum(sites.values()),
        "input_error_modules": len(sites),
        "package_imports": (imports := package_imports()),
        "package_imports_mean": statistics.fmean(imports.values()),
    }


def report(m: dict[str, Any]) -> str:
    out = ["lines per subpackage (docstring share):"]
    for name, row in m["lines"].items():
        share = row["docstring_lines"] / row["lines"] if row["lines"] else 0.0
        out.append(f"  {name:<20} {row['lines']:>6}  {share:5.1%}")
    keys = m["files_per_key"]
    out.append(
        f"multi-word scene keys: {len(keys)}; files per key: mean "
        f"{m['files_per_key_mean']:.2f}, max {m['files_per_key_max']}; over 3 files: "
        + ", ".join(f"{k} ({n})" for k, n in sorted(keys.items(), key=lambda kv: -kv[1]) if n > 3)
    )
    out.append(
        f"InputError raise sites outside the boundary: {m['input_error_sites_total']} in "
        f"{m['input_error_modules']} modules"
    )
    for name, n in m["input_error_sites"].items():
        out.append(f"  {name:<50} {n:>4}")
    imports = m["package_imports"]
    out.append(
        f"package imports per module: mean {m['package_imports_mean']:.3f} over {len(imports)} "
        "modules; the most: "
        + ", ".join(f"{k} ({n})" for k, n in sorted(imports.items(), key=lambda kv: -kv[1])[:8])
    )
    return "\n".join(out)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--json", action="store_true", help="print the figures as JSON")
    args = parser.parse_args(argv)
    m = metrics()
    print(json.dumps(m, indent=1) if args.json else report(m))
    return 0


if __name__ == "__main__":
    sys.exit(main())
