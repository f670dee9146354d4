"""The package's import structure, read from the source with ``ast`` (nothing is imported).

(a) No module imports another of the package's modules inside a function, except a module
    that itself loads a heavy third-party package (sympy, pyvista) at import time: deferring
    that import keeps the light modules light. Any other exception is listed, with its reason,
    in :data:`ALLOWED`.
(b) The module import graph has no circle, counting function-level imports, the imports
    under ``if TYPE_CHECKING`` and the implicit import of a module's parent packages.
"""

from __future__ import annotations

import ast
from collections.abc import Iterator
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[2] / "chargedesign"

#: modules that import a heavy third-party package at module level (sympy: the symbolic
#: model; pyvista and matplotlib: the 3-D views). A function-level import of one of them
#: from any other module is the lazy loading issue 21 keeps.
HEAVY_MODULES = frozenset(
    {
        "chargedesign.model.audit",
        "chargedesign.model.case",
        "chargedesign.model.case_file",
        "chargedesign.model.case_numeric",
        "chargedesign.designer.case_design",
        "chargedesign.model.catalogue",
        "chargedesign.model.certificate",
        "chargedesign.model.equations",
        "chargedesign.model.larmor",
        "chargedesign.model.printed",
        "chargedesign.scene.case_file",
        "chargedesign.scene.expressions",
        "chargedesign.topology.case_map",
        "chargedesign.topology.general",
        "chargedesign.viz",
    }
)

#: (importing module, imported module): function-level imports kept on purpose, each with
#: its reason.
ALLOWED: dict[tuple[str, str], str] = {
    ("chargedesign.simulation.setup", "chargedesign.designer.pipeline"): (
        "the designer loads scipy.sparse and scipy.linalg (about 0.4 s of CPU), which a run of "
        "a written design.json never calls (tests/test_startup.py): only a [case] scene designed "
        "at once and a [body] region a run needs (design_pending) call it"
    ),
}


def module_name(path: Path) -> str:
    parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def package_modules(package: Path = PACKAGE) -> dict[str, Path]:
    return {module_name(p): p for p in sorted(package.rglob("*.py"))}


def resolve(name: str, modules: dict[str, Path]) -> str | None:
    """The module a dotted name lives in (its longest prefix that is a module)."""
    while name and name not in modules:
        name = name.rpartition(".")[0]
    return name or None


def is_type_checking(node: ast.AST) -> bool:
    return isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test)


def imports(
    tree: ast.AST, in_function: bool = False, typing_only: bool = False
) -> Iterator[tuple[ast.Import | ast.ImportFrom, bool, bool]]:
    """Every import statement, with whether it is in a function and whether it is under
    ``if TYPE_CHECKING`` (for annotations only)."""
    for child in ast.iter_child_nodes(tree):
        if isinstance(child, (ast.Import, ast.ImportFrom)):
            yield child, in_function, typing_only
        nested = in_function or isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef))
        yield from imports(child, nested, typing_only or is_type_checking(child))


def targets(
    node: ast.Import | ast.ImportFrom, module: str, path: Path, modules: dict[str, Path]
) -> set[str]:
    """The package's modules an import statement loads (relative imports resolved)."""
    if isinstance(node, ast.Import):
        names = [alias.name for alias in node.names]
    else:
        base = node.module or ""
        if node.level:
            parts = module.split(".")
            if path.name != "__init__.py":
                parts = parts[:-1]
            parts = parts[: len(parts) - (node.level - 1)]
            base = ".".join([*parts, base] if base else parts)
        names = [f"{base}.{a.name}" if f"{base}.{a.name}" in modules else base for a in node.names]
    found = {resolve(n, modules) for n in names if n.split(".")[0] == "chargedesign"}
    return {t for t in found if t and t != module}


def parents(name: str) -> list[str]:
    parts = name.split(".")
    return [".".join(parts[:i]) for i in range(1, len(parts))]


def import_graph(
    modules: dict[str, Path],
) -> tuple[dict[str, set[str]], list[tuple[str, str, int]]]:
    """Edges module -> imported modules (with the parent packages Python imports first, for
    a module outside them), and every function-level own import as (module, target, line).

    The edges count every import: at module level, in a function (a lazy import is still a
    dependence) and under ``if TYPE_CHECKING`` (an annotation names the other module's type:
    a circle of types is a circle of the design)."""
    edges: dict[str, set[str]] = {m: set() for m in modules}
    function_level = []
    for module, path in modules.items():
        tree = ast.parse(path.read_text(encoding="utf-8"))
        for node, in_function, typing_only in imports(tree):
            for target in targets(node, module, path, modules):
                own = set(parents(module)) | {module}
                edges[module] |= {target, *(p for p in parents(target) if p not in own)}
                if in_function and not typing_only:
                    function_level.append((module, target, node.lineno))
    return edges, function_level


def circles(edges: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan, iterative)."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for root in sorted(edges):
        if root in index:
            continue
        work = [(root, iter(sorted(edges[root])))]
        index[root] = low[root] = len(index)
        stack.append(root)
        on_stack.add(root)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(edges.get(child, ())))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while True:
                    member = stack.pop()
                    on_stack.discard(member)
                    component.append(member)
                    if member == node:
                        break
                if len(component) > 1:
                    found.append(sorted(component))
    return found


def forbidden_function_imports(modules: dict[str, Path]) -> list[str]:
    _, function_level = import_graph(modules)
    return [
        f"{modules[m].relative_to(PACKAGE.parent)}:{line}: imports {t} in a function"
        for m, t, line in function_level
        if (t not in HEAVY_MODULES or m in HEAVY_MODULES) and (m, t) not in ALLOWED
    ]


# --------------------------------------------------------------- the checks themselves
def test_the_checks_see_a_function_level_import_and_a_circle(tmp_path: Path) -> None:
    package = tmp_path / "chargedesign"
    (package / "sub").mkdir(parents=True)
    (package / "__init__.py").write_text("", encoding="utf-8")
    (package / "sub" / "__init__.py").write_text("from . import b\n", encoding="utf-8")
    (package / "a.py").write_text(
        "def f():\n    from chargedesign.sub.b import g\n", encoding="utf-8"
    )
    (package / "sub" / "b.py").write_text("import numpy\n", encoding="utf-8")
    (package / "c.py").write_text("from chargedesign.sub import b\n", encoding="utf-8")
    modules = {module_name_in(p, tmp_path): p for p in sorted(package.rglob("*.py"))}
    edges, function_level = import_graph(modules)
    assert function_level == [("chargedesign.a", "chargedesign.sub.b", 2)]
    assert edges["chargedesign.c"] == {"chargedesign.sub", "chargedesign.sub.b"}
    assert circles(edges) == []
    # b importing c closes a circle through the parent package sub
    (package / "sub" / "b.py").write_text("import chargedesign.c\n", encoding="utf-8")
    edges, _ = import_graph(modules)
    assert circles(edges) == [["chargedesign.c", "chargedesign.sub", "chargedesign.sub.b"]]
    # an import for annotations only closes a circle too (and is no function-level import)
    (package / "sub" / "b.py").write_text(
        "from typing import TYPE_CHECKING\n"
        "if TYPE_CHECKING:\n    def f():\n        from chargedesign.c import x\n",
        encoding="utf-8",
    )
    edges, function_level = import_graph(modules)
    assert function_level == [("chargedesign.a", "chargedesign.sub.b", 2)]
    assert circles(edges) == [["chargedesign.c", "chargedesign.sub", "chargedesign.sub.b"]]


def module_name_in(path: Path, root: Path) -> str:
    parts = path.relative_to(root).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def test_no_function_level_import_of_the_package() -> None:
    remaining = forbidden_function_imports(package_modules())
    print(f"{len(remaining)} function-level imports of the package remain:")
    print("\n".join(remaining))
    assert remaining == []


def test_the_import_graph_has_no_circle() -> None:
    edges, _ = import_graph(package_modules())
    found = circles(edges)
    for component in found:
        print(f"circle of {len(component)}: {', '.join(component)}")
    assert found == []
