"""The bands of docs/architecture.md hold: a module imports only modules of its band or lower.

The band table is the one in docs/architecture.md (its rows name the rooms of each band: a file
``name.py``, or a folder ``name/`` that holds every module under it except those that another
row names more closely, such as ``physical/realism.py``). Every module of the package is in one
band. The imports are read with ``ast`` as :mod:`test_imports` reads them: at module level, in
a function (the lazy sympy and PyVista imports) and under ``if TYPE_CHECKING``, with the parent
packages Python imports first.
"""

from __future__ import annotations

import re
from itertools import pairwise
from pathlib import Path

from test_imports import PACKAGE, import_graph, package_modules

DOC = PACKAGE.parent / "docs" / "architecture.md"
#: (importing module, imported module): a band crossed upward on purpose, with the reason
EXCEPTIONS: dict[tuple[str, str], str] = {}

ROW = re.compile(r"^\| (?P<band>[a-z ]+) \| (?P<low>\d+)-(?P<high>\d+) \| (?P<rooms>.*?) \|")


def band_table(text: str) -> list[tuple[str, int, int, list[str]]]:
    """The table's rows, top band first: (band, lowest floor, highest floor, rooms)."""
    rows = []
    for line in text.splitlines():
        found = ROW.match(line)
        if found:
            rooms = re.findall(r"`([\w/]+(?:\.py|/))`", found["rooms"])
            rows.append((found["band"], int(found["low"]), int(found["high"]), rooms))
    return rows


def module_path(module: str) -> str:
    """``chargedesign.physical.realism`` -> ``physical/realism.py``; a package -> ``dir/``,
    the top level -> ``__init__.py``."""
    path = PACKAGE.parent.joinpath(*module.split("."))
    if path.is_dir():
        rest = module.split(".")[1:]
        return "/".join(rest) + "/" if rest else "__init__.py"
    return "/".join(module.split(".")[1:]) + ".py"


def band_of(module: str, rows: list[tuple[str, int, int, list[str]]]) -> int | None:
    """The index of the band (0 = top) whose row names ``module`` most closely."""
    path = module_path(module)
    best: tuple[int, int] | None = None  # (length of the room's name, band)
    for index, (_, _, _, rooms) in enumerate(rows):
        for room in rooms:
            if path == room or (room.endswith("/") and path.startswith(room)):
                if best is None or len(room) > best[0]:
                    best = (len(room), index)
    return None if best is None else best[1]


def band_violations(
    edges: dict[str, set[str]], rows: list[tuple[str, int, int, list[str]]]
) -> list[str]:
    """Every import from a band to one above it, and every module in no band."""
    out = []
    for module in sorted(edges):
        mine = band_of(module, rows)
        if mine is None:
            out.append(f"{module_path(module)} is in no band")
            continue
        for target in sorted(edges[module]):
            theirs = band_of(target, rows)
            if theirs is not None and theirs < mine and (module, target) not in EXCEPTIONS:
                out.append(
                    f"{module_path(module)} ({rows[mine][0]}) imports "
                    f"{module_path(target)} ({rows[theirs][0]})"
                )
    return out


def test_the_table_has_its_bands_top_down_on_floors_that_follow() -> None:
    rows = band_table(DOC.read_text(encoding="utf-8"))
    assert [r[0] for r in rows] == ["entry points", "stages", "kernels", "boundary", "ground"]
    assert rows[-1][1] == 1
    for upper, lower in pairwise(rows):
        assert upper[1] == lower[2] + 1, (upper, lower)


def test_every_module_imports_only_its_band_or_lower() -> None:
    edges, _ = import_graph(package_modules())
    found = band_violations(edges, band_table(DOC.read_text(encoding="utf-8")))
    print("\n".join(found))
    assert found == []


def test_the_exceptions_are_still_needed() -> None:
    edges, _ = import_graph(package_modules())
    for module, target in EXCEPTIONS:
        assert target in edges[module], f"{module} no longer imports {target}: drop it"


def test_the_check_sees_an_upward_import_and_a_module_in_no_band() -> None:
    rows = band_table(
        "| top | 2-2 | `cli.py`, `sub/` | |\n| base | 1-1 | `errors.py`, `sub/low.py` | |\n"
    )
    edges = {
        "chargedesign.cli": {"chargedesign.errors"},
        "chargedesign.sub.low": {"chargedesign.errors"},
        "chargedesign.errors": set(),
    }
    assert band_violations(edges, rows) == []
    edges["chargedesign.sub.low"].add("chargedesign.cli")  # the base reaches up
    edges["chargedesign.stray"] = set()
    assert band_violations(edges, rows) == [
        "stray.py is in no band",
        "sub/low.py (base) imports cli.py (top)",
    ]


def test_module_paths() -> None:
    assert module_path("chargedesign") == "__init__.py"
    assert module_path("chargedesign.physical") == "physical/"
    assert module_path("chargedesign.physical.realism") == "physical/realism.py"
    assert isinstance(DOC, Path) and DOC.is_file()


def test_the_table_places_the_physical_folder_on_two_bands() -> None:
    """The scene reads the physical tables (boundary); the realised window and the realism
    budget read the scene's records (kernels), below every stage (issue 33's floor rule)."""
    rows = band_table(DOC.read_text(encoding="utf-8"))
    names = [r[0] for r in rows]
    assert names[band_of("chargedesign.physical.drag", rows) or 0] == "boundary"
    assert names[band_of("chargedesign.physical.materials", rows) or 0] == "boundary"
    assert names[band_of("chargedesign.scene.keys", rows) or 0] == "boundary"
    assert names[band_of("chargedesign.physical.window", rows) or 0] == "kernels"
    assert names[band_of("chargedesign.airbearing.run", rows) or 0] == "stages"
