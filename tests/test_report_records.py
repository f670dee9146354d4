"""design.json's records read once into the typed records the report renders
(chargedesign.report_records), with the defaults an older design.json gets."""

from __future__ import annotations

import math

from chargedesign.body import Design
from chargedesign.physical.window import BearingSupport, support_of
from chargedesign.report import Plausibility, plausibility
from chargedesign.report_records import (
    Budget,
    Candidates,
    CaseRecord,
    KLaw,
    Placement,
    Problems,
    ReportRecords,
)
from chargedesign.scene.design_realism import FIELD_RESPONSE_KEYS, INDUCED_KEY


def _design(**record) -> Design:
    return Design.from_dict({"parameters": {"C": 1.0}, **record})


def test_the_candidates_spacing_is_the_written_one_else_the_geometry_s():
    geometry = Candidates.from_dict({"n": 5, "geometry": {"spacing_m": 0.5}, "kind": "grid"})
    assert (geometry.count, geometry.spacing, geometry.figures) == (5, 0.5, {"kind": "grid"})
    written = Candidates.from_dict({"spacing": 0.25, "geometry": {"spacing_m": 0.5}})
    assert (written.count, written.spacing) == ("?", 0.25)
    # a spacing that is no positive number is not a spacing
    assert Candidates.from_dict({"spacing": 0, "geometry": {"spacing_m": "x"}}).spacing is None


def test_problems_are_read_only_when_written_and_keep_the_report_s_defaults():
    assert Problems.read(_design()) is None
    problems = Problems.read(
        _design(
            objective={"charges": {"kind": "l1", "value": 2.0}},
            solver={"charges": {"solver": "HIGHS"}},
            residuals={"after_polish": {"charges": 1e-12, "dipoles": 3e-11, "masses": "n/a"}},
        )
    )
    assert problems is not None
    objective, solver = problems.objective["charges"], problems.solver["charges"]
    assert (objective.kind, objective.value, objective.units) == ("l1", 2.0, "")
    assert (solver.name, solver.method) == ("HIGHS", "")
    assert problems.definition is None and problems.tolerance == "?"
    assert problems.largest_residual == 3e-11  # the words are not a residual


def test_the_budget_table_says_the_induced_magnetisation_once():
    response = {"value": 2.0, "unit": "", "verdict": "ok", "note": "input"}
    induced = {"value": 5.0, "verdict": "ok", "note": "", "term": "K2", "s": 1.0}
    both = Budget.from_dict(
        {"typical_rate_1_per_s": 3.0, FIELD_RESPONSE_KEYS[0]: response, INDUCED_KEY: induced}
    )
    assert list(both.table) == [INDUCED_KEY] and both.items[INDUCED_KEY].term == "K2"
    assert (both.typical_rate_1_per_s, both.period_s, both.balance_1g) == (3.0, 0, None)
    older = Budget.from_dict({FIELD_RESPONSE_KEYS[0]: response})  # no one figure recorded
    assert list(older.table) == [FIELD_RESPONSE_KEYS[0]]


def test_absent_records_read_as_none():
    records = ReportRecords.read(_design())
    assert (records.candidates, records.problems, records.case, records.frontier) == (None,) * 4
    assert records.placement is None and records.physical is None
    assert (records.limits.surface_field_fraction, records.limits.violations) == (0, ())
    assert (records.materials.carrier, records.materials.magnet) == ("?", "?")
    assert KLaw.read({}) is None
    # tolerancing where nothing binds names no element
    assert Placement.read({"elements": [{"element": "q1", "binding": ""}]}) is None


def test_a_case_record_reads_its_certificate_checks_and_window():
    case = CaseRecord.read(
        _design(
            case={
                "name": "kowalevski",
                "level": "general",
                "inertia": [2.0, 2.0, 1.0],
                "certificate": {"holds": True},
                "checks": {"inertia_rel_err": 1e-16, "torque_rel_err": 2e-15, "level_offset": 0},
                "realism": {"term_key": None},
                "realised": {"s_low": 0.2, "s_high": 3.0, "fraction": 1e-3},
            }
        )
    )
    assert case is not None and case.holds and not case.independent
    assert case.inertia == (2.0, 2.0, 1.0) and case.checks is not None
    assert case.realism is not None and case.realism.term_key is None
    assert case.window is not None and case.window.s_high == 3.0
    assert case.window.missing == math.inf


def test_the_support_reads_back_as_the_window_writes_it():
    written = support_of(0.05, 2.0, 1e-6)
    support = BearingSupport.from_dict(written)
    assert (support.ball_radius_m, support.drag_torque_N_m) == (0.05, written["drag_torque_N_m"])
    assert support.drag_over_term == written["drag_torque_N_m"] / 1e-6
    assert support.source and support.drag_source


def test_plausibility_lists_only_the_kinds_the_design_has():
    design = _design(
        charges={"positions": [[0.0, 0.0, 0.0], [0.1, 0.0, 0.0]], "values": [1e-9, -2e-9]}
    )
    figures = plausibility(design)
    assert figures == Plausibility.of(design, Candidates.read(design)).to_dict()
    assert list(figures) == [
        "largest_charge_C",
        "spacing_m",
        "field_V_per_m",
        "field_over_air_breakdown",
    ]
    assert figures["largest_charge_C"] == 2e-9 and math.isclose(figures["spacing_m"], 0.1)
    assert plausibility(_design()) == {}
