"""`chargedesign verify`: exact certificate of the theorem and audit of the printed formulas.

Exit 0 when the certificate holds in all four cases of the paper's table (printed misprints
are findings, reported but not failures), 1 when any case fails.
"""

from __future__ import annotations

import argparse
import json
import time

CERTIFICATE_CASES = ("general", "yehia2003", "goriachev", "chaplygin")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print JSON")


def collect() -> dict[str, object]:
    """Everything ``verify`` reports, contract keys first."""
    from chargedesign.model.audit import audit_printed
    from chargedesign.model.certificate import certify, counterexample

    results = [certify(case) for case in CERTIFICATE_CASES]
    start = time.perf_counter()
    entries = audit_printed()
    audit_seconds = time.perf_counter() - start
    return {
        "certificate": {res.case: res.holds for res in results},
        "printed": [entry.to_dict() for entry in entries],
        "certificate_checks": {res.case: res.checks for res in results},
        "counterexample": counterexample(),
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
        f"  dI4/dt = {ce['dI4_dt']} (~{ce['dI4_dt_float']:.6g}), not 0",
        "",
        f"audit: {seconds['audit']:.3f} s",
    ]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    report = collect()
    if args.json:
        print(json.dumps(report, indent=2))
    else:
        print(format_report(report))
    certificate = report["certificate"]
    assert isinstance(certificate, dict)
    return 0 if all(certificate.values()) else 1
