"""The [case] scene's refusals at the boundary (issue 33): each takes plain values and raises
the one line the user reads; the case designer calls them where the figure is known."""

from __future__ import annotations

import pytest

from chargedesign.constants import STANDARD_GRAVITY
from chargedesign.errors import InputError
from chargedesign.scene import case_refusals


def test_case_gravity_is_the_uniform_part_or_standard_gravity() -> None:
    assert case_refusals.case_gravity({}) == STANDARD_GRAVITY
    assert case_refusals.case_gravity({"gravity": ()}) == STANDARD_GRAVITY
    assert case_refusals.case_gravity({"gravity": (0.0,)}) == STANDARD_GRAVITY
    assert case_refusals.case_gravity({"gravity": (1.62, 0.0)}) == 1.62


@pytest.mark.parametrize(
    ("fields", "message"),
    [
        (
            {"magnetic": (1.0,), "gravity": (9.8,)},
            "fields.magnetic: a [case] scene is designed as masses in gravity; only "
            "[fields.gravity] (its uniform part) may be given",
        ),
        (
            {"gravity": (9.8, 1.0)},
            "fields.gravity.legendre: give the uniform part only ([g]); the gradient is "
            "derived from the case's quadratic V",
        ),
        ({"gravity": (-9.8,)}, "fields.gravity.legendre[0]: expected g > 0, got -9.8"),
    ],
)
def test_case_gravity_refuses_in_one_line(fields, message) -> None:
    with pytest.raises(InputError) as refused:
        case_refusals.case_gravity(fields)
    assert str(refused.value) == message


def test_the_degree_is_refused_only_when_wrong() -> None:
    case_refusals.refuse_mass_degree("k", 2)
    with pytest.raises(InputError, match="V has degree 3 in gamma"):
        case_refusals.refuse_mass_degree("k", 3)
