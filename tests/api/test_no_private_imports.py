"""No module of the package imports another module's private (``_name``) names.

A name that another module needs is public (no leading underscore), even when it is internal
(not in any ``__all__``); names that only their own module uses stay private.
"""

import ast
from pathlib import Path

import chargedesign

PACKAGE = Path(chargedesign.__file__).parent


def _imported_module(node: ast.ImportFrom, path: Path, root: Path) -> str:
    """The absolute module name of a ``from ... import`` (relative imports resolved)."""
    if node.level == 0:
        return node.module or ""
    # ``a/b/c.py`` and ``a/b/__init__.py`` both resolve ``from . import x`` against ``a.b``
    parts = [root.name, *path.relative_to(root).with_suffix("").parts]
    base = parts[: len(parts) - node.level]
    return ".".join([*base, node.module] if node.module else base)


def private_imports(root: Path = PACKAGE) -> list[str]:
    """Every ``from chargedesign... import _name`` in the package, as ``file:line: text``."""
    found = []
    for path in sorted(root.rglob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom):
                continue
            module = _imported_module(node, path, root)
            if module != "chargedesign" and not module.startswith("chargedesign."):
                continue
            for alias in node.names:
                if alias.name.startswith("_") and not alias.name.startswith("__"):
                    where = path.relative_to(root.parent).as_posix()
                    found.append(f"{where}:{node.lineno}: from {module} import {alias.name}")
    return found


def test_no_module_imports_another_modules_private_names() -> None:
    offending = private_imports()
    assert not offending, "private names imported across modules:\n" + "\n".join(offending)


def test_the_check_finds_a_private_import(tmp_path: Path) -> None:
    package = tmp_path / "chargedesign"
    package.mkdir()
    (package / "a.py").write_text("from chargedesign.b import _hidden, shown\n", encoding="utf-8")
    (package / "b.py").write_text("from chargedesign.a import __version__\n", encoding="utf-8")
    relative = "from .b import _relative\nfrom os import _exit\n"
    (package / "c.py").write_text(relative, encoding="utf-8")
    assert private_imports(package) == [
        "chargedesign/a.py:1: from chargedesign.b import _hidden",
        "chargedesign/c.py:1: from chargedesign.b import _relative",
    ]
