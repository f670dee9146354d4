"""The CLI's commands: their arguments in :mod:`.arguments` (light, for ``--help``), and one
module per command with ``run(args) -> int``, imported by :func:`chargedesign.cli.main` only
when that command runs (so each imports its stages at the top).
"""

from __future__ import annotations

import json
import os
from typing import Any

# A command's linear algebra is many small BLAS products (a few hundred columns): there
# OpenBLAS' second thread costs CPU and saves no wall time. One thread, set before numpy and
# scipy load their OpenBLAS (the package's top level loads neither; the command line imports
# this package first): `frontier --json` 1.92-1.93 s of user CPU with two threads, 1.62-1.68
# with one, the same output; the design of 9,939 candidates 3.7-4.2 s CPU and 3.0-4.0 s wall,
# against 2.9-3.1 and 2.9-3.05 (docs/benchmarks.md, "One BLAS thread for the command
# line"). A limit set at run time (threadpoolctl) saves about a third of that. The user's
# own OPENBLAS_NUM_THREADS wins; the library (`import chargedesign`) leaves it alone.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def print_result(result: Any, as_json: bool, end: str = "\n") -> None:
    """A stage's result on stdout by the one result protocol: ``result.to_dict()`` as JSON
    (``--json``), else ``str(result)`` (the text the stage renders; the command formats
    nothing itself)."""
    if as_json:
        print(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    else:
        print(str(result), end=end)
