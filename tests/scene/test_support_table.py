"""The [support] table: its keys, default and refusals (one line naming the key)."""

from __future__ import annotations

import pytest

from chargedesign.errors import InputError
from chargedesign.scene import scene_from_dict
from chargedesign.scene.load import validate_tables
from chargedesign.scene.support import SupportOptions


def test_without_a_table_the_support_is_today_s_air_bearing_not_given():
    support = scene_from_dict({}).support
    assert support == SupportOptions("air_bearing", None, False)
    assert not support.weightless


def test_free_fall_defaults_to_the_catapult():
    support = scene_from_dict({"support": {"style": "free_fall"}}).support
    assert support.facility == "drop_tower_catapult" and support.given and support.weightless
    drop = scene_from_dict({"support": {"style": "free_fall", "facility": "drop_tower_drop"}})
    assert drop.support.to_dict() == {"style": "free_fall", "facility": "drop_tower_drop"}


@pytest.mark.parametrize(
    ("table", "words"),
    [
        ({"style": "magnetic"}, "support.style"),
        ({"style": "free_fall", "facility": "bremen"}, "support.facility"),
        ({"style": "orbit", "facility": "drop_tower_drop"}, "only with style = 'free_fall'"),
        ({"stlye": "orbit"}, "stlye"),
        ({"style": 3}, "support.style"),
    ],
)
def test_a_bad_support_is_refused_in_one_line(table, words):
    scene = scene_from_dict({"support": table})
    with pytest.raises(InputError) as caught:
        validate_tables(scene)
    message = str(caught.value)
    assert words in message and "\n" not in message
