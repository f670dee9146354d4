"""The catalogue: every case certified, at its file's parameters and at others; the command
line of ``verify CASE`` and ``catalogue`` (contract keys, exit codes, one-line refusals)."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
import sympy as sp

from chargedesign.cli import main
from chargedesign.commands import catalogue as catalogue_command
from chargedesign.designer.pipeline import design_from_scene
from chargedesign.model.case import g1, g2, g3, p, q, r
from chargedesign.model.case_file import certify_case, conserved_combinations
from chargedesign.model.catalogue import (
    CatalogueReport,
    catalogue_case,
    catalogue_entries,
    certify_catalogue,
    entry_table,
)
from chargedesign.results import REPR_LIMIT
from chargedesign.scene import scene_from_dict
from chargedesign.scene.case_file import case_from_table

#: the paper's cases the catalogue must hold (names of the entries)
PAPER_CASES = {
    "euler",
    "lagrange",
    "kowalevski",
    "goriachev-chaplygin",
    "goriachev",
    "joukovsky",
    "lagrange-gyrostat",
    "yehia-gyrostat",
    "sretensky",
    "clebsch",
    "steklov-lyapunov",
    "chaplygin",
    "chaplygin-goriachev",
    "yehia2003",
    "yehia-elmandouh",
}


@pytest.fixture(scope="module")
def catalogue_report() -> CatalogueReport:
    return certify_catalogue()


def test_every_catalogue_case_is_certified(catalogue_report: CatalogueReport) -> None:
    report = catalogue_report
    names = {c.name for c in report.certificates}
    assert names == PAPER_CASES
    for certificate in report.certificates:
        assert certificate.holds, certificate.name
        assert certificate.independent, certificate.name
        assert all(certificate.checks.values()), certificate.name
        assert certificate.holds_for_all_parameters, certificate.name
        assert certificate.source, certificate.name
    assert report.holds
    assert "15/15 certified" in str(report)


def _shifted(value: Any) -> str:
    """Another admissible value: the exact value plus 2/7 (moments stay positive)."""
    return str(sp.Rational(str(value)) + sp.Rational(2, 7))


#: the entries other than the theorem's (its file is certified at two other parameter sets
#: against the model in test_case_certificate.py)
CLASSICAL = [e for e in catalogue_entries() if e["file"] != "yehia_elmandouh.toml"]


@pytest.mark.parametrize("entry", CLASSICAL, ids=lambda e: e.get("name", e["file"]))
def test_each_integral_holds_at_other_parameter_values(entry: dict[str, Any]) -> None:
    """Numeric route beside the all-parameters one: every parameter the entry leaves free is
    moved, and the certificate holds again at the new numbers."""
    table = entry_table(entry)
    fixed = set(entry.get("parameters", {}))
    table["parameters"] = {
        k: (v if k in fixed else _shifted(v)) for k, v in table["parameters"].items()
    }
    result = certify_case(case_from_table(table))
    assert result.holds and result.independent


def test_derived_integrals_match_the_catalogue() -> None:
    """Independent route: the integral found by an exact linear ansatz among candidate
    monomials is the catalogue's (Yehia's gyrostat, Goriachev's singular case)."""
    yehia = case_from_table(entry_table({"file": "yehia_gyrostat.toml"}))
    a, k = (yehia.parameters[n] for n in ("a", "k"))
    kowalevski = (p**2 - q**2 - a * g1) ** 2 + (2 * p * q - a * g2) ** 2
    found = conserved_combinations(
        yehia, [kowalevski, r * (p**2 + q**2), p**2 + q**2, g3 * p, g3 * q, g1 * r, g2 * r]
    )
    assert len(found) == 1
    assert sp.expand(found[0] - yehia.integral) == 0
    assert (
        sp.expand(found[0] - kowalevski - 2 * k * (r - k) * (p**2 + q**2) + 4 * a * k * p * g3) == 0
    )

    goriachev = case_from_table(entry_table({"file": "goriachev.toml"}))
    laurent = [g1**i * g2**j * g3**m for i in (0, 1) for j in (0, 1) for m in range(-3, 2)]
    found = conserved_combinations(
        goriachev, [r * (p**2 + q**2)] + [w * g for w in (p, q) for g in laurent]
    )
    assert len(found) == 1
    assert sp.expand(sp.together(found[0] - goriachev.integral)) == 0


def test_a_changed_integral_of_a_catalogue_case_fails() -> None:
    """The certificate can fail: Sretensky's integral without the gyrostat's shift."""
    table = entry_table({"file": "sretensky.toml"})
    table["integral"] = "r*(p**2 + q**2) - a*p*gamma3"
    result = certify_case(case_from_table(table))
    assert not result.holds and result.counterexample is not None


def test_catalogue_case_by_name() -> None:
    assert catalogue_case("yehia2003").parameters["K"] == 0
    with pytest.raises(Exception, match="no case named"):
        catalogue_case("nobody")


# --------------------------------------------------------------------- the command line


def test_catalogue_command_json(
    catalogue_report: CatalogueReport,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The command's wiring and JSON (the certificates themselves: the fixture's, computed
    once for this module by the same function)."""
    monkeypatch.setattr(catalogue_command, "certify_catalogue", lambda: catalogue_report)
    assert main(["catalogue", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert data["holds"] is True
    assert {c["name"] for c in data["cases"]} == PAPER_CASES
    for case in data["cases"]:
        assert {"name", "holds", "level", "independent", "counterexample"} <= set(case)


def test_verify_a_case_file_json_has_the_contract_keys(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    path = tmp_path / "kow.toml"
    path.write_text(
        "[case]\n"
        'name = "kowalevski"\n'
        "inertia = [2.0, 2.0, 1.0]\n"
        'V = "g*gamma1"\n'
        'l = ["0", "0", "0"]\n'
        'integral = "(p**2 - q**2 - g*gamma1)**2 + (2*p*q - g*gamma2)**2"\n'
        'level = "general"\n'
        "[case.parameters]\n"
        "g = 1.0\n"
    )
    assert main(["verify", str(path), "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    case = data["case"]
    assert list(case)[:5] == ["name", "holds", "level", "independent", "counterexample"]
    assert case == case | {"name": "kowalevski", "holds": True, "level": "general"}
    assert case["independent"] is True and case["counterexample"] is None

    path.write_text(path.read_text().replace("- g*gamma1)**2", "+ g*gamma1)**2"))
    assert main(["verify", str(path), "--json"]) == 1
    case = json.loads(capsys.readouterr().out)["case"]
    assert case["holds"] is False and case["counterexample"]["dF_dt"] != "0"

    path.write_text(path.read_text().replace('level = "general"', "level = 0.5"))
    assert main(["verify", str(path)]) == 1
    out = capsys.readouterr().out
    assert "I3 = 1/2" in out and "Counterexample" in out


def test_verify_a_hostile_case_file_is_one_line_and_runs_nothing(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    marker = tmp_path / "ran"
    path = tmp_path / "hostile.toml"
    path.write_text(
        "[case]\n"
        'name = "hostile"\n'
        "inertia = [2.0, 2.0, 1.0]\n"
        f"V = \"__import__('os').system('touch {marker}')\"\n"
        'integral = "p"\n'
    )
    assert main(["verify", str(path), "--json"]) == 2
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err.count("\n") == 1 and "case.V: a call" in captured.err
    assert not marker.exists()


def test_verify_the_catalogue_files_from_the_command_line(
    capsys: pytest.CaptureFixture[str],
) -> None:
    folder = Path(__file__).resolve().parents[2] / "chargedesign" / "data" / "cases"
    assert main(["verify", str(folder / "goriachev.toml")]) == 0
    out = capsys.readouterr().out
    assert "goriachev" in out and "singular where: gamma3 = 0" in out


def test_the_workbench_results_follow_the_result_protocol(
    catalogue_report: CatalogueReport,
) -> None:
    kowalevski = catalogue_case("kowalevski")
    wrong = entry_table({"file": "kowalevski.toml"}) | {"integral": "p*q"}
    results = [
        certify_case(kowalevski),
        certify_case(case_from_table(wrong)),
        catalogue_report,
        design_from_scene(
            scene_from_dict(
                {
                    "case": entry_table({"file": "kowalevski.toml"}),
                    "body": {"shape": "ball", "radius": 1.0, "spacing": 0.5},
                },
                "<kowalevski>",
            )
        ),
    ]
    for result in results:
        data = result.to_dict()
        json.dumps(data, allow_nan=False)
        assert json.loads(result.to_json()) == json.loads(json.dumps(data))
        assert str(result).strip()
        assert len(repr(result)) <= REPR_LIMIT and "\n" not in repr(result)
        assert "<table>" in result._repr_html_()
