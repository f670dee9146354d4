"""Values past float range are refused before any work (issue 43 item 3): a V of 384 digits
verified exactly and then failed in design, testbed and simulate with OverflowError; a
product of 1500 numbers ended in Python's 4300-digit limit; and refusing
``(gamma1+gamma2+gamma3+1)**24`` took 50 s of expansion. The parser bounds, before it builds
them, the digits and the size of every coefficient the expansion makes (the parameters at
their values) and the expansion's cost."""

from __future__ import annotations

from pathlib import Path

import pytest
from case_scene import case_scene
from reliability_support import refused

from chargedesign.errors import InputError
from chargedesign.scene.case_file import case_from_table
from chargedesign.scene.expressions import parse_bounded

INTERNALS = ("int_max_str_digits", "4300", "Overflow", "zoo", "Traceback")


@pytest.mark.parametrize(
    ("changes", "key", "reason"),
    [
        ({"V": '"(9**24)**16*gamma1"'}, "case.V", "coefficients outside 1e-100..1e100"),
        ({"V": '"' + "9**24*" * 1500 + 'gamma1"'}, "case.V", "coefficients outside"),
        ({"V": '"1e30*1e30*1e30*1e30*gamma1"'}, "case.V", "coefficients outside"),
        ({"a": "1e30", "integral": '"a**4*p"'}, "case.integral", "coefficients outside"),
        ({"l": '["0", "0", "(9**24)**16*gamma3"]'}, "case.l[2]", "coefficients outside"),
        ({"V": '"(1 + 1/3333333)**400*gamma1"'}, "case.V", "exponent"),
        ({"V": '"(333333333/333333331)**24*gamma1"'}, "case.V", "more than 400 digits"),
        ({"V": '"(gamma1+gamma2+gamma3+1)**24"'}, "case:", "certificate's work"),
    ],
)
@pytest.mark.parametrize("command", ["verify", "design", "simulate", "testbed"])
def test_a_number_past_float_range_is_refused_before_any_work(
    changes: dict[str, str],
    key: str,
    reason: str,
    command: str,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    scene = case_scene(tmp_path, **changes)
    argv = [command, str(scene)] + (["--out", str(tmp_path / "o")] if command != "verify" else [])
    line = refused(argv, command, capsys, tmp_path)
    assert key in line and reason in line, line
    assert not any(word in line for word in INTERNALS), line


def test_a_sum_of_many_fractions_is_measured_as_built() -> None:
    primes = [p for p in range(3, 20000, 2) if all(p % d for d in range(3, int(p**0.5) + 1, 2))]
    text = "+".join(f"1/{p}" for p in primes[:600]) + "+gamma1"
    with pytest.raises(InputError, match="more than 400 digits"):
        parse_bounded(text, "case.V")


def test_long_sums_of_decimals_and_large_parameters_stay_accepted() -> None:
    text = " + ".join(f"0.{i:04d}*gamma1**{i % 3}*gamma2" for i in range(1, 700))
    assert parse_bounded(text, "case.V").scale < 10
    table = {
        "name": "k",
        "inertia": ["2*C", "2*C", "C"],
        "V": "C*a*gamma1",
        "integral": "(p**2 - q**2 - a*gamma1)**2 + (2*p*q - a*gamma2)**2",
        "parameters": {"C": 1e8, "a": 1e16},
    }
    assert case_from_table(table).V.free_symbols
