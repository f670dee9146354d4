"""chargedesign.formatting: one way to print a quantity."""

import math

import pytest

from chargedesign.formatting import (
    CELL,
    EXACT,
    FIGURE,
    FULL,
    KINDS,
    ORDER,
    ORDER_SCI,
    PLAIN,
    PRECISE,
    ROUGH,
    fmt,
    fmt_length,
)


@pytest.mark.parametrize(
    ("value", "kind", "expected"),
    [
        (0.012345, FIGURE, "0.0123"),
        (0.012345, PRECISE, "0.01235"),
        (2.54e-14, ROUGH, "2.5e-14"),
        (3.3e-16, ORDER, "3e-16"),
        (1.0e-5, ORDER_SCI, "1e-05"),
        (0.7, PLAIN, "0.7"),
        (1234567.0, PLAIN, "1.23457e+06"),
        (1 / 3, CELL, "0.333333"),
        (0.1, EXACT, "0.10000000000000001"),
        (0.1 + 0.2, FULL, "0.3"),
        (1 / 3, FULL, "0.333333333333"),
        (3, FIGURE, "3"),
    ],
)
def test_each_kind_prints_its_digits(value, kind, expected):
    assert fmt(value, kind) == expected


def test_the_kinds_keep_the_digits_the_text_always_had():
    # the before/after comparison of every command's text relies on these
    assert KINDS[FIGURE] == ".3g" and KINDS[PRECISE] == ".4g" and KINDS[PLAIN] == "g"
    for x in (0.0, -1.5e-7, 123456.789, 6.02214076e23):
        assert fmt(x) == f"{x:.3g}"
        assert fmt(x, PRECISE) == f"{x:.4g}"
        assert fmt(x, PLAIN) == f"{x:g}"


def test_units_follow_after_one_space():
    assert fmt(2.0e6, FIGURE, "V/m") == "2e+06 V/m"
    assert fmt(0.5, PRECISE, "kg") == "0.5 kg"


def test_unknown_kind_is_refused_by_name():
    with pytest.raises(ValueError, match="unknown kind 'sig5'"):
        fmt(1.0, "sig5")


def test_lengths_take_the_largest_unit_they_reach():
    assert fmt_length(3.125e-3) == "3.12 mm"
    assert fmt_length(1.2e-8) == "12 nm"
    assert fmt_length(2.0) == "2 m"
    assert fmt_length(4.0e-6, PRECISE) == "4 µm"
    assert fmt_length(1e-12) == "1e-12 m"
    assert fmt_length(math.inf) == "any"
