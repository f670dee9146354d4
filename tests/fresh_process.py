"""The tests' shared check that a piece of work keeps a library out: ``code`` is run in a
fresh interpreter (this process has imported everything already) and says whether
``module`` was imported."""

from __future__ import annotations

import subprocess
import sys


def imports_module(code: str, module: str = "sympy") -> bool:
    """Whether running ``code`` in a fresh Python imports ``module``."""
    return module in imported_of(code, (module,))


def imported_of(code: str, modules: tuple[str, ...]) -> set[str]:
    """Which of ``modules`` running ``code`` in a fresh Python imports (one interpreter)."""
    probe = f"import sys\n{code}\nprint(sorted(m for m in {modules!r} if m in sys.modules))\n"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120
    )
    answer = out.stdout.strip().splitlines()[-1]
    assert answer.startswith("[") and answer.endswith("]"), out.stdout
    found = {name.strip().strip("'") for name in answer[1:-1].split(",") if name.strip()}
    assert found <= set(modules), out.stdout
    return found
