"""Compile heyoka integrators in compact mode here: about 7x shorter cold compiles.

The equations are the same; compact mode changes only the generated code (slower to run,
faster to compile). Production runs keep heyoka's unrolled code (see taylor.COMPACT_MODE).
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

from chargedesign.simulation import taylor


@pytest.fixture(autouse=True, scope="module")
def _compact_heyoka() -> Iterator[None]:
    previous = taylor.COMPACT_MODE
    taylor.COMPACT_MODE = True
    yield
    taylor.COMPACT_MODE = previous
