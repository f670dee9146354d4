"""A usage mistake on the command line (a missing option, an unknown one, an unknown
command) gets one line naming the mistake and exit 2, like every other bad input."""

from __future__ import annotations

import pytest

from chargedesign.cli import build_parser


@pytest.mark.parametrize(
    ("argv", "named"),
    [
        (["export", "design.json"], "--out"),
        (["design", "--no-such-option", "1"], "--no-such-option"),
        (["frobnicate"], "frobnicate"),
        (["simulate", "--t-end", "many"], "many"),
    ],
)
def test_a_usage_mistake_is_one_line(argv, named, capsys):
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args(argv)
    assert stop.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1, err
    assert named in err and "error:" in err and "--help" in err


def test_help_still_prints_the_usage(capsys):
    with pytest.raises(SystemExit) as stop:
        build_parser().parse_args(["export", "--help"])
    assert stop.value.code == 0
    assert "usage:" in capsys.readouterr().out
