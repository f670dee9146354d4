"""The ``[support]`` table: how the body is held (docs/flight.md).

``style`` is one of ``free_fall``, ``orbit``, ``air_bearing``, ``electrostatic``; ``facility``
names the free-fall facility (ZARM's Bremen Drop Tower: ``drop_tower_drop`` or
``drop_tower_catapult``) and is read only with ``free_fall``. The support's figures and items
are :mod:`chargedesign.physical.support`'s.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

from chargedesign.errors import InputError
from chargedesign.scene.keys import KEY, check_table, check_value, default_of


@dataclass(frozen=True)
class SupportOptions:
    """A scene's support: ``style`` and (free fall) ``facility``; ``given`` is False when the
    scene has no ``[support]`` table (today's reading: the air bearing, stated, not counted)."""

    style: str = default_of("support", KEY.style)
    facility: str | None = None
    given: bool = False

    @classmethod
    def from_table(cls, table: Mapping[str, Any] | None) -> SupportOptions:
        if table is None:
            return cls()
        check_table(table, "support")
        style = check_value(
            "support",
            KEY.style,
            table.get(KEY.style, default_of("support", KEY.style)),
            "support.style",
        )
        facility = None
        if style == "free_fall":
            facility = check_value(
                "support",
                KEY.facility,
                table.get(KEY.facility, default_of("support", KEY.facility)),
                "support.facility",
            )
        elif KEY.facility in table:
            raise InputError(
                f"support.facility: a facility is read only with style = 'free_fall', got "
                f"style = {style!r}"
            )
        return cls(style, facility, True)

    @property
    def weightless(self) -> bool:
        """True in free fall and in orbit: the balance in 1 g is no longer a requirement."""
        return self.style in ("free_fall", "orbit")

    def to_dict(self) -> dict[str, Any]:
        return {"style": self.style, "facility": self.facility}
