"""A negative number in exponent form is a number wherever a number is, not an option."""

from __future__ import annotations

import pytest

from chargedesign.cli import NEGATIVE_NUMBER, build_parser


@pytest.mark.parametrize("text", ["-3", "-0.3", "-.3", "-3.", "-3e-1", "-3E+2", "-2.5e-07"])
def test_negative_spellings_are_numbers(text):
    assert NEGATIVE_NUMBER.match(text)
    assert float(text) < 0


@pytest.mark.parametrize("text", ["-e3", "--3", "-3e", "-h", "-3-1", "-inf", "-nan"])
def test_options_and_words_are_not_numbers(text):
    assert not NEGATIVE_NUMBER.match(text)


def test_bifurcation_takes_exponent_form_ranges():
    args = build_parser().parse_args(["bifurcation", "--h-range", "-3e-1", "5e-1", "--at", "-2e-1"])
    assert args.h_range == [-0.3, 0.5]
    assert args.at == -0.2
