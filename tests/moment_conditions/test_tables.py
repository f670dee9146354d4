"""The shipped tables of the conditions engine are what sympy derives, exactly."""

from __future__ import annotations

import json

import pytest
from fresh_process import imports_module

from chargedesign.moment_conditions.constants import MAX_FIELD_DEGREE
from chargedesign.moment_conditions.harmonics import (
    derive_real_solid_harmonics,
    real_solid_harmonics,
)
from chargedesign.moment_conditions.mu import derive_mu_system, mu_system
from chargedesign.moment_conditions.potential import derive_v_projection, v_projection
from chargedesign.moment_conditions.table_data import TABLE_FORMAT, TABLE_NAMES, shipped_table
from chargedesign.moment_conditions.tables import derived_entries, shipped_table_text, table_text


@pytest.mark.parametrize("name", TABLE_NAMES)
def test_the_shipped_table_is_the_derived_one(name):
    assert shipped_table_text(name) == table_text(name)  # regenerate: make tables
    assert json.loads(shipped_table_text(name))["format"] == TABLE_FORMAT
    assert shipped_table(name) == derived_entries(name)


@pytest.mark.parametrize("k", range(MAX_FIELD_DEGREE + 1))
def test_the_read_harmonics_equal_sympy_s(k):
    assert real_solid_harmonics(k) == derive_real_solid_harmonics(k)


@pytest.mark.parametrize("degree", range(1, MAX_FIELD_DEGREE + 1))
def test_the_read_mu_equations_equal_sympy_s(degree):
    assert mu_system(degree) == derive_mu_system(degree)


def test_the_read_v_projection_equals_sympy_s():
    assert v_projection() == derive_v_projection()


def test_without_a_shipped_table_the_pieces_are_derived(monkeypatch):
    import chargedesign.moment_conditions.harmonics as harmonics_module

    monkeypatch.setattr(harmonics_module, "shipped_table", lambda name: None)
    assert real_solid_harmonics.__wrapped__(2) == real_solid_harmonics(2)


def test_a_float_derivation_does_not_import_sympy():
    code = (
        "from chargedesign.moment_conditions import conditions_for_scene\n"
        "from chargedesign.scene import load_scene\n"
        "conditions_for_scene(load_scene(None))"
    )
    assert not imports_module(code, "sympy")
