"""The verification of the theorem as one result: the exact certificate in the paper's four
cases and the audit of the printed formulas (what ``chargedesign verify`` prints): the model's
own (:func:`chargedesign.model.audit.audit_printed`), then the moment conditions (p6) by the
conditions engine (:func:`chargedesign.moment_conditions.audit.audit_p6`). It stands above both.

``verify().holds`` is True when the certificate holds in every case and the Larmor
certificate holds (:mod:`chargedesign.model.larmor`: the n-system is the n = 0 system in axes
turning at n about Z); ``to_dict()`` gives the keys of ``chargedesign verify --json``, the
Larmor certificate under ``larmor``.
"""

from __future__ import annotations

import time
from dataclasses import dataclass
from typing import Any

from chargedesign.formatting import CELL, fmt
from chargedesign.moment_conditions.audit import audit_p6
from chargedesign.results import Result

CERTIFICATE_CASES = ("general", "yehia2003", "goriachev", "chaplygin")


def collect() -> dict[str, object]:
    """Everything ``verify`` reports as a JSON-ready mapping, contract keys first."""
    from chargedesign.model.audit import audit_printed
    from chargedesign.model.certificate import certify, counterexample
    from chargedesign.model.larmor import certify_larmor

    results = [certify(case) for case in CERTIFICATE_CASES]
    larmor = certify_larmor()
    start = time.perf_counter()
    entries = [*audit_printed(), audit_p6()]  # the model's formulas, then (p6) by the conditions
    audit_seconds = time.perf_counter() - start
    return {
        "certificate": {res.case: res.holds for res in results},
        "printed": [entry.to_dict() for entry in entries],
        "certificate_checks": {res.case: res.checks for res in results},
        "counterexample": counterexample(),
        "larmor": larmor.to_dict(),
        "seconds": {
            "certificate": {res.case: res.seconds for res in results},
            "audit": audit_seconds,
        },
    }


def _yes(flag: object) -> str:
    return "yes" if flag else "NO"


def format_report(report: dict[str, object]) -> str:
    """The human-readable tables."""
    certificate = report["certificate"]
    checks = report["certificate_checks"]
    seconds = report["seconds"]
    assert isinstance(certificate, dict) and isinstance(checks, dict)
    assert isinstance(seconds, dict)
    lines = ["Certificate (exact rational arithmetic, all parameters symbolic)", ""]
    lines.append(f"  {'case':<11} {'holds':<6} {'checks':<7} seconds")
    for case, holds in certificate.items():
        passed = sum(bool(v) for v in checks[case].values())
        total = len(checks[case])
        lines.append(
            f"  {case:<11} {_yes(holds):<6} {passed}/{total:<5} {seconds['certificate'][case]:.3f}"
        )
        failed = [name for name, ok in checks[case].items() if not ok]
        if failed:
            lines.append("    failed: " + ", ".join(failed))
    larmor = report.get("larmor")
    if isinstance(larmor, dict):
        from chargedesign.model.larmor import format_larmor

        lines += ["", *format_larmor(larmor)]
    lines += ["", "Printed formulas: printed - derived on |gamma| = 1", ""]
    printed = report["printed"]
    assert isinstance(printed, list)
    width = max(len(str(e["name"])) for e in printed)
    lines.append(f"  {'name':<{width}} {'agrees':<6} difference")
    for entry in printed:
        lines.append(f"  {entry['name']:<{width}} {_yes(entry['agrees']):<6} {entry['difference']}")
    notes = [f"  {e['name']}: {e['note']}" for e in printed if not e["agrees"] and e.get("note")]
    if notes:
        lines += ["", "Notes on the entries that do not agree:", *notes]
    ce = report["counterexample"]
    assert isinstance(ce, dict)
    state = ce["state"]
    lines += [
        "",
        "Counterexample (exact): on the printed zero level I3_printed = "
        f"{ce['I3_printed']} (derived I3 = {ce['I3']}), gamma = ({state['gamma1']}, "
        f"{state['gamma2']}, {state['gamma3']}), p, q, r = {state['p']}, {state['q']}, "
        f"{state['r']}:",
        f"  dI4/dt = {ce['dI4_dt']} (~{fmt(ce['dI4_dt_float'], CELL)}), not 0",
        "",
        f"audit: {seconds['audit']:.3f} s",
    ]
    return "\n".join(lines)


@dataclass(repr=False)
class VerificationReport(Result):
    """The certificate and the audit (keys as ``chargedesign verify --json``).

    Attributes
    ----------
    data : dict
        ``certificate`` (case -> holds), ``printed`` (one entry per printed formula),
        ``certificate_checks``, ``counterexample``, ``larmor`` (the Larmor certificate,
        :meth:`chargedesign.model.larmor.LarmorCertificate.to_dict`), ``seconds``.
    """

    data: dict[str, Any]

    @property
    def larmor(self) -> dict[str, Any] | None:
        """The Larmor certificate (``holds``, ``checks``, ``identities``, ...), if run."""
        return self.data.get("larmor")

    @property
    def holds(self) -> bool:
        """True when the certificate holds in every case and the Larmor certificate holds."""
        larmor = self.larmor
        return all(self.data["certificate"].values()) and (larmor is None or larmor["holds"])

    def to_dict(self) -> dict[str, Any]:
        return dict(self.data)

    def _summary(self) -> dict[str, Any]:
        printed = self.data["printed"]
        return {
            "holds": self.holds,
            **{f"certificate_{k}": v for k, v in self.data["certificate"].items()},
            "larmor": None if self.larmor is None else self.larmor["holds"],
            "printed_agree": sum(bool(e["agrees"]) for e in printed),
            "printed_total": len(printed),
        }

    def _text(self) -> str:
        return format_report(self.data)

    def _html_rows(self) -> dict[str, Any]:
        rows = self._summary()
        for entry in self.data["printed"]:
            rows[entry["name"]] = "agrees" if entry["agrees"] else f"differs: {entry['difference']}"
        return rows


def verify() -> VerificationReport:
    """Certify the theorem (exact, symbolic) and audit the paper's printed formulas."""
    return VerificationReport(collect())


__all__ = ["CERTIFICATE_CASES", "VerificationReport", "collect", "format_report", "verify"]
