"""The tests' shared check that a piece of work keeps a library out: ``code`` is run in a
fresh interpreter (this process has imported everything already) and says whether
``module`` was imported."""

from __future__ import annotations

import subprocess
import sys


def imports_module(code: str, module: str = "sympy") -> bool:
    """Whether running ``code`` in a fresh Python imports ``module``."""
    probe = f"import sys\n{code}\nprint({module!r} in sys.modules)\n"
    out = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True, check=True, timeout=120
    )
    answer = out.stdout.strip().splitlines()[-1]
    assert answer in ("True", "False"), out.stdout
    return answer == "True"
