"""Files of derived data the package ships: derived once with sympy, read without it.

The harmonics, V and mu tables of the conditions engine
(:mod:`chargedesign.moment_conditions.table_data`), the realisability map's terms
(:mod:`chargedesign.physical.map_data`) and the model's compiled sources
(:mod:`chargedesign.model.evaluators`) are each one :class:`ShippedData`: a JSON file under
``chargedesign/`` holding ``format`` (a tag the reader checks), ``about`` (what it is and how
it is regenerated) and ``entries``. ``make tables`` writes them; the tests re-derive each and
compare the text exactly. What a reader does with a missing or stale file (derive, or refuse)
is its own: :meth:`ShippedData.entries` only says None.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import cache
from importlib import resources
from typing import Any

from chargedesign.files import write_text_atomic


@dataclass(frozen=True)
class ShippedData:
    """One shipped file: ``relative`` to the package, its ``format`` tag, its ``about`` text,
    and ``indent`` (None: one compact line; else ``json.dumps``' indent)."""

    relative: str
    format: str
    about: str
    indent: int | None = None

    def path(self) -> Any:
        """Where the file lives in the package (a Traversable)."""
        return resources.files("chargedesign").joinpath(self.relative)

    def text(self, entries: Any) -> str:
        """The file's text for these entries."""
        data = {"format": self.format, "about": self.about, "entries": entries}
        if self.indent is None:
            return json.dumps(data, indent=None, separators=(",", ":")) + "\n"
        return json.dumps(data, indent=self.indent) + "\n"

    def shipped_text(self) -> str:
        """The text the package ships ('' when it ships none)."""
        path = self.path()
        return path.read_text(encoding="utf-8") if path.is_file() else ""

    def write(self, entries: Any) -> str:
        """Write the text for these entries into the package's data folder; its path."""
        path = str(self.path())
        write_text_atomic(path, self.text(entries))
        return path

    def entries(self) -> Any:
        """The shipped entries (None: not shipped, or of another format)."""
        return _shipped_entries(self)


@cache
def _shipped_entries(data: ShippedData) -> Any:
    text = data.shipped_text()
    if not text:
        return None
    parsed = json.loads(text)
    return parsed["entries"] if parsed.get("format") == data.format else None
