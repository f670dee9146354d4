"""The CLI's commands: their arguments in :mod:`.arguments` (light, for ``--help``), and one
module per command with ``run(args) -> int``, imported by :func:`chargedesign.cli.main` only
when that command runs (so each imports its stages at the top).
"""

from __future__ import annotations

import json
from typing import Any


def print_result(result: Any, as_json: bool, end: str = "\n") -> None:
    """A stage's result on stdout by the one result protocol: ``result.to_dict()`` as JSON
    (``--json``), else ``str(result)`` (the text the stage renders; the command formats
    nothing itself)."""
    if as_json:
        print(json.dumps(result.to_dict(), indent=2, allow_nan=False))
    else:
        print(str(result), end=end)
