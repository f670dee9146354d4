"""The sources table: every row sourced, the checked ones located, each module's figures the
table's own, and the command's JSON the contract's shape."""

from __future__ import annotations

import json
import math

import pytest

from chargedesign.cli import main
from chargedesign.physical import (
    coils,
    drag,
    materials,
    realism,
    sources,
    state_of_the_art,
    support,
)
from chargedesign.physical.sources import FIELDS, cite, rows, source, table, value


def test_every_row_has_a_source_a_locator_and_a_finite_value() -> None:
    assert len(rows()) >= 100
    for r in rows():
        assert r.source.strip() and r.locator.strip() and r.what.strip() and r.unit.strip(), r.key
        assert math.isfinite(r.value), r.key
        assert isinstance(r.checked, bool)
    assert len({r.key for r in rows()}) == len(rows())


def test_checked_rows_say_where_they_were_read() -> None:
    for r in rows():
        if r.checked:
            assert len(r.locator) > 8 and "not read" not in r.locator, r.key


def test_at_least_half_the_table_is_checked() -> None:
    assert table().checked_count >= len(rows()) / 2


def test_the_corrected_figures() -> None:
    """The figures an outside check corrected, read in their sources."""
    assert value("limits.field_evaporation.tungsten") == pytest.approx(6e10, rel=0.06)
    assert source("limits.field_evaporation.tungsten").checked
    assert value("media.viscosity.air") == pytest.approx(1.81e-5, rel=0.01)
    assert value("media.breakdown.vacuum") == 1e7
    assert "top of the practical range" in source("media.breakdown.vacuum").what
    assert value("sensors.motion_capture.along_m") / value(
        "sensors.motion_capture.across_m"
    ) == pytest.approx(0.74 / 0.12)
    assert "ESTIMATED" in source("state_of_the_art.balance.automatic_horizontal_m").what
    assert (value("bearings.air_film.thin_m"), value("bearings.air_film.thick_m")) == (
        5e-6,
        12.7e-6,
    )
    for momentum, mass in ((50, 9.0), (75, 10.4), (100, 12.0)):
        assert value(f"actuators.honeywell_hr16_{momentum}.momentum") == momentum
        assert value(f"actuators.honeywell_hr16_{momentum}.mass") == mass


def test_each_module_reads_its_figures_from_the_table() -> None:
    for group, names in materials.KEYS.items():
        for name, key in names.items():
            table_value = value(key)
            if group == "breakdown":
                assert materials.BREAKDOWN_V_PER_M[name] == table_value
            elif group == "susceptibility":
                assert materials.SUSCEPTIBILITY[name] == table_value
            elif group == "conductivity":
                assert materials.CONDUCTIVITY[name] == table_value
            elif group == "coercivity":
                assert materials.MAGNET_COERCIVITY[name] == table_value
            elif group == "remanence":
                assert materials.MAGNET_DATA[name][0] == table_value
            else:
                found = {
                    **materials.CARRIER_DENSITY,
                    **materials.BALLAST_DENSITY,
                    **{m: d for m, (_, d) in materials.MAGNET_DATA.items()},
                }
                assert found[name] == table_value
    assert materials.GAS_PROPERTIES["air"] == (
        value("media.density.air"),
        value("media.viscosity.air"),
    )
    assert materials.MAGNET_CONTINUUM_SIZE == value("limits.magnet_continuum_size")
    assert drag.AIR_VISCOSITY == value("media.viscosity.air")
    assert realism.FIELD_EVAPORATION == value("limits.field_evaporation.tungsten")
    assert coils.COPPER_RESISTIVITY == value("coils.copper_resistivity")
    sota = state_of_the_art
    assert sota.BALANCE["automatic_horizontal_m"].value == value(
        "state_of_the_art.balance.automatic_horizontal_m"
    )
    assert sota.LOOP_RATE.value == value("state_of_the_art.loop_rate")
    assert sota.BEARINGS["tabletop"].tilt_limit_deg == value("bearings.tabletop.tilt_limit_deg")
    assert sota.MOUNT_MATERIALS["steel"][0].value == value("mounts.steel.youngs_modulus")
    arw = sota.GYROS["tactical"][0]
    assert arw.value == pytest.approx(value("sensors.gyro.tactical.arw") * math.pi / 180 / 60)
    noise = sota.ATTITUDE_SENSORS["motion_capture"][0].value
    assert noise == value("sensors.motion_capture.along_m") / value(
        "sensors.motion_capture.baseline_m"
    )


def test_a_citation_marks_the_unchecked() -> None:
    assert cite("media.viscosity.air") == "[media.viscosity.air]"
    assert cite("room_air.asymmetry") == "[room_air.asymmetry, unverified]"
    with pytest.raises(KeyError, match="no figure"):
        source("no.such.figure")


def test_the_drop_tower_keys_the_support_stage_reads() -> None:
    for key, expected in (
        ("drop_tower.drop_time_s", 4.74),
        ("drop_tower.catapult_time_s", 9.3),
        ("drop_tower.residual_g", 1e-6),
        ("drop_tower.catapult_launch_g", 35.0),
        ("drop_tower.catapult_launch_s", 0.25),
        ("drop_tower.landing_g", 50.0),
        ("drop_tower.tube_pressure_fraction", 1e-4),
        ("drop_tower.capsule_diameter_m", 0.8),
        ("drop_tower.capsule_length_m", 2.5),
        ("drop_tower.capsule_pressure_Pa", 101325.0),
    ):
        assert value(key) == expected and source(key).checked


def test_the_table_as_a_result() -> None:
    t = table()
    assert [sorted(d) for d in t.to_dict()] == [sorted(FIELDS)] * len(rows())
    text = str(t)
    assert all(len(line) <= sources.LINE_WIDTH for line in text.splitlines())
    assert "media.viscosity.air" in text and repr(t).startswith("SourcesTable(")
    assert "<table>" in t._repr_html_()


def test_the_command_prints_the_contracts_json(capsys) -> None:
    assert main(["sources", "--json"]) == 0
    data = json.loads(capsys.readouterr().out)
    assert isinstance(data, list) and len(data) == len(rows())
    for row in data:
        assert list(row) == list(FIELDS)
        assert isinstance(row["key"], str) and isinstance(row["value"], float)
        assert isinstance(row["checked"], bool)
    assert main(["sources"]) == 0
    text = capsys.readouterr().out
    assert max(len(line) for line in text.splitlines()) <= 160


def test_the_support_stages_figures_are_the_tables() -> None:
    """physical/support.py reads every figure from the table (one source of truth), and the
    drop tower's figures are the ones read at ZARM (4.74 s, 9.3 s, 1e-6 g, 0.8 m x 2.5 m)."""
    assert set(support.FIGURES) == set(support.SUPPORT_KEYS)
    for key, figure in support.FIGURES.items():
        row = source(key)
        assert (figure.value, figure.unit, figure.checked) == (row.value, row.unit, row.checked)
    read_at_zarm = {
        "drop_tower.drop_time_s": 4.74,
        "drop_tower.catapult_time_s": 9.3,
        "drop_tower.residual_g": 1e-6,
        "drop_tower.capsule_diameter_m": 0.8,
        "drop_tower.capsule_length_m": 2.5,
    }
    for key, expected in read_at_zarm.items():
        assert support.figure(key) == expected and source(key).checked, key


def test_citations_of_keys_with_hyphens_and_capitals_are_found_and_other_brackets_kept() -> None:
    """Every key of the table is a citation (``fused-silica``, ``PTFE``: the design report's
    pattern used to miss them, inline and in its sources section); a bracketed dotted name
    that is no key and carries no mark (``[design.json]``) is left as written."""
    from chargedesign.physical.sources import cited_keys

    text = (
        "a [materials.density.fused-silica, unverified], b [materials.insulator_conductivity.PTFE]"
        ", c [design.json]"
    )
    out, keys = cited_keys(text)
    assert keys == ["materials.density.fused-silica", "materials.insulator_conductivity.PTFE"]
    assert "[materials.density.fused-silica]," in out and "[design.json]" in out
    assert "unverified" not in out
