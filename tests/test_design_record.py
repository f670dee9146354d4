"""design.json's record keys are named Design attributes; the file keeps its keys exactly."""

import json
from pathlib import Path

import pytest

from chargedesign.body import RECORD_KEYS, Design, read_design, write_design
from chargedesign.errors import InputError

OLD = Path(__file__).resolve().parent / "tolerancing" / "data" / "default_design.json"


def test_an_old_design_json_reads_into_named_fields_and_writes_back_its_keys(tmp_path):
    data = json.loads(OLD.read_text())
    design = read_design(OLD)
    assert design.residuals == data["residuals"]
    assert design.provenance == data["provenance"]
    assert design.notes == data["notes"] and design.region == data["region"]
    assert design.frontier is None and design.time_rate is None and design.further_keys == {}
    write_design(design, tmp_path / "again.json")
    again = json.loads((tmp_path / "again.json").read_text())
    assert list(again) == list(data)
    assert again == data


def test_unknown_keys_are_kept_verbatim_and_never_shadow_the_contract():
    data = {
        "parameters": {"C": 1.0},
        "realises": [],
        "made_by": {"tool": "elsewhere"},
        "time_rate": 0.25,
        "frontier": {"s_max": 2.0},
    }
    design = Design.from_dict(data)
    assert design.further_keys == {"made_by": {"tool": "elsewhere"}}
    assert design.time_rate == 0.25 and design.frontier == {"s_max": 2.0}
    out = design.to_dict()
    assert out["made_by"] == {"tool": "elsewhere"} and out["time_rate"] == 0.25
    design.further_keys["parameters"] = "shadow"
    assert design.to_dict()["parameters"] == {
        "C": 1.0,
        **{k: 0.0 for k in out["parameters"] if k != "C"},
    }


def test_every_record_key_is_an_attribute_and_absent_ones_are_not_written():
    design = Design.from_dict({"parameters": {"C": 1.0}})
    for key in RECORD_KEYS:
        assert getattr(design, key) is None
    assert not set(RECORD_KEYS) & set(design.to_dict())
    assert design.record() == {}


def test_a_bad_time_rate_is_refused_by_name():
    with pytest.raises(InputError, match="time_rate"):
        Design.from_dict({"parameters": {"C": 1.0}, "time_rate": "fast"})
