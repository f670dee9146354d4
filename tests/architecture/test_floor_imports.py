"""The boundary floor imports nothing above it (issue 33), read from the source with ``ast``.

The floor is where input is read and judged: the ``chargedesign.scene`` package and the
modules ``validation``, ``readers``, ``files``, ``limits``, ``errors`` and ``formatting``.
The rule: a floor module imports (at module level or in a function; ``if TYPE_CHECKING``
blocks aside) only

- other floor modules;
- the base records and words below every stage: ``vocabulary``, ``constants``, ``params``,
  ``results``; and
- ``chargedesign.physical`` modules of constants and formulas (materials, the state of the
  art, the air film's drag) whose own imports, followed to the end, reach only floor, base
  or such physical modules: no stage (``airbearing``, ``designer``, ``simulation``, ...).

Each exception is listed in :data:`EXCEPTIONS` with its reason. ``physical/window.py`` (a
kernel the floor does not import) must not import the air-bearing stage either.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "chargedesign"
FLOOR_MODULES = ("validation", "readers", "files", "limits", "errors", "formatting")
BASE = frozenset(f"chargedesign.{m}" for m in ("vocabulary", "constants", "params", "results"))
#: (floor module, imported module): kept on purpose, with the reason
EXCEPTIONS: dict[tuple[str, str], str] = {
    ("chargedesign.scene.load", "chargedesign.model.case_file"): "the [case] table's parser "
    "builds sympy expressions: imported in the function that reads a [case], so sympy loads "
    "only for a scene that carries one",
}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {module_name(p): p for p in sorted(PACKAGE.rglob("*.py"))}


def is_floor(name: str) -> bool:
    return (
        name == "chargedesign.scene"
        or name.startswith("chargedesign.scene.")
        or name in {f"chargedesign.{m}" for m in FLOOR_MODULES}
    )


def _statements(tree: ast.AST) -> Iterator[ast.Import | ast.ImportFrom]:
    for child in ast.iter_child_nodes(tree):
        if isinstance(child, ast.If) and "TYPE_CHECKING" in ast.unparse(child.test):
            continue
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            yield child
        yield from _statements(child)


def _resolve(name: str) -> str | None:
    while name and name not in MODULES:
        name = name.rpartition(".")[0]
    return name or None


def imported(module: str) -> set[str]:
    """The package's modules that ``module`` imports (relative imports resolved)."""
    path = MODULES[module]
    out = set()
    for node in _statements(ast.parse(path.read_text("utf-8"))):
        if isinstance(node, ast.Import):
            names = [alias.name for alias in node.names]
        else:
            base = node.module or ""
            if node.level:
                parts = module.split(".")[: None if path.name == "__init__.py" else -1]
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join([*parts, base] if base else parts)
            names = [f"{base}.{a.name}" for a in node.names] + [base]
        for name in names:
            if name.split(".")[0] == "chargedesign":
                target = _resolve(name)
                if target and target not in (module, "chargedesign"):
                    out.add(target)
    return out


def _below_every_stage(module: str, seen: set[str]) -> bool:
    """``module`` is floor or base, or a physical module whose imports stay there."""
    if is_floor(module) or module in seen:
        return True
    if module not in BASE and not module.startswith("chargedesign.physical."):
        return False
    seen.add(module)
    return all(_below_every_stage(t, seen) for t in imported(module))


def floor_violations() -> list[str]:
    out = []
    for module in sorted(m for m in MODULES if is_floor(m)):
        for target in sorted(imported(module)):
            if (module, target) in EXCEPTIONS:
                continue
            if not _below_every_stage(target, set()):
                out.append(f"{module} imports {target}")
    return out


def test_the_floor_imports_nothing_above_it():
    assert floor_violations() == []


def test_the_exceptions_are_still_needed():
    for module, target in EXCEPTIONS:
        assert target in imported(module), f"{module} no longer imports {target}: drop it"


def test_the_check_finds_a_stage_import():
    """The walk sees what is above the floor: the air-bearing stage, and a physical module
    that imports a kernel (the realised window imports chargedesign.fields)."""
    assert not _below_every_stage("chargedesign.airbearing.run", set())
    assert not _below_every_stage("chargedesign.physical.window", set())  # via fields
    assert _below_every_stage("chargedesign.physical.drag", set())


def test_the_realised_window_imports_no_air_bearing_module():
    assert not {t for t in imported("chargedesign.physical.window") if ".airbearing" in t}
