"""`chargedesign verify`: contract keys, exit codes, readable table."""

from __future__ import annotations

import json

import pytest

from chargedesign import verification
from chargedesign.cli import main
from chargedesign.errors import ChargeDesignError

CONTRACT_NAMES = {"mu_from_l", "eom_p", "eom_q", "eom_r", "eom_gamma", "I3", "I4", "p6"}


def test_verify_json_has_the_contract_keys(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify", "--json"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert list(report)[:2] == ["certificate", "printed"]
    assert report["certificate"] == {
        "general": True,
        "yehia2003": True,
        "goriachev": True,
        "chaplygin": True,
    }
    names = [e["name"] for e in report["printed"]]
    assert CONTRACT_NAMES <= set(names)
    for entry in report["printed"]:
        assert isinstance(entry["agrees"], bool)
        assert isinstance(entry["difference"], str) and entry["difference"]
    by_name = {e["name"]: e for e in report["printed"]}
    assert by_name["eom_p"]["agrees"] is False and by_name["eom_r"]["agrees"] is True
    assert report["counterexample"]["nonzero"] is True


def test_verify_prints_a_table(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["verify"]) == 0
    out = capsys.readouterr().out
    assert "Certificate" in out and "general" in out and "chaplygin" in out
    assert "eom_q" in out and "dI4/dt" in out


def test_verify_when_the_p6_engine_fails_says_so_in_one_line(
    capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    def broken() -> None:
        raise ChargeDesignError("p6: the conditions engine failed")

    monkeypatch.setattr(verification, "audit_p6", broken)
    assert main(["verify", "--json"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "p6" in err


def test_report_formatting_from_collected_parts() -> None:
    from chargedesign.verification import format_report

    report = {
        "certificate": {"general": True, "chaplygin": False},
        "certificate_checks": {"general": {"a": True}, "chaplygin": {"a": False, "b": True}},
        "printed": [{"name": "eom_p", "agrees": False, "difference": "x", "note": ""}],
        "counterexample": {
            "I3_printed": "0",
            "I3": "9/4",
            "state": {k: "1" for k in ("p", "q", "r", "gamma1", "gamma2", "gamma3")},
            "dI4_dt": "1/2",
            "dI4_dt_float": 0.5,
        },
        "seconds": {"certificate": {"general": 0.1, "chaplygin": 0.2}, "audit": 0.3},
    }
    text = format_report(report)
    assert "failed: a" in text and "NO" in text and "eom_p" in text
