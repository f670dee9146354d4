"""Magnets keep their magnetisation: the field at every magnet stays below what it withstands.

A magnetised sphere's own field inside is -M/3; an applied field reversed against it adds to
it, and beyond the intrinsic coercivity Hcj the magnet is demagnetised for good. The body
turns every way, so the limit is ``mu0 (Hcj - M/3)`` on |B| in any direction.
"""

from __future__ import annotations

import tomllib

import numpy as np
import pytest
from physical.test_buildable import SMALL, scene_with

from chargedesign.body import Design
from chargedesign.constants import MU_0
from chargedesign.designer import design_from_scene
from chargedesign.designer.pipeline import physical_setup_from_scene
from chargedesign.errors import InfeasibleError, InputError
from chargedesign.physical.limits import check_limits
from chargedesign.physical.materials import MAGNET_COERCIVITY, MAGNET_DATA
from chargedesign.scene import load_scene, scene_from_dict


@pytest.fixture(scope="module")
def small_design() -> Design:
    return design_from_scene(load_scene(SMALL), frontier=False).design


def paper_field_max(a1: float, a2: float, radius: float, samples: int = 20001) -> float:
    """Largest |B| on the sphere of this radius, from the paper's Phi = a1 Z + a2 (3Z^2 - R^2):
    B = (2 a2 X, 2 a2 Y, -(a1 + 4 a2 Z)), sampled densely in the polar angle."""
    theta = np.linspace(0.0, np.pi, samples)
    rho, z = radius * np.sin(theta), radius * np.cos(theta)
    return float(np.max(np.hypot(2 * a2 * rho, a1 + 4 * a2 * z)))


def test_every_designed_magnet_sits_where_its_material_holds(small_design):
    magnet = small_design.materials["magnet"]
    assert magnet["name"] == "ndfeb-eh"
    withstood = MU_0 * (magnet["intrinsic_coercivity_A_per_m"] - MAGNET_DATA["ndfeb-eh"][0] / 3)
    a1, f2 = small_design.field("magnetic")[:2]
    volumes = small_design.magnet_volumes()
    assert len(volumes) > 0
    reach = np.linalg.norm(small_design.dipole_positions, axis=1) + np.cbrt(
        3 * volumes / (4 * np.pi)
    )
    fields = [paper_field_max(a1, f2 / 2, r) for r in reach]
    assert max(fields) <= withstood
    # and the field does vary enough over the body for the limit to exclude outer sites
    assert paper_field_max(a1, f2 / 2, 0.05) > withstood
    assert check_limits(small_design).parts_within_limits


def test_the_check_finds_a_magnet_that_would_be_demagnetised(small_design):
    """The same body written with plain N42 magnets (Hcj 12 kOe): 0.78 T withstood, >= 1 T met."""
    data = small_design.to_dict()
    data["materials"]["magnet"]["name"] = "ndfeb"
    data["materials"]["magnet"]["intrinsic_coercivity_A_per_m"] = MAGNET_COERCIVITY["ndfeb"]
    limits = check_limits(Design.from_dict(data))
    assert not limits.parts_within_limits
    (line,) = [v for v in limits.violations if "demagnetised" in v]
    assert "0.781 T" in line and "ndfeb" in line
    # an older file without the coercivity: the named material's is used
    del data["materials"]["magnet"]["intrinsic_coercivity_A_per_m"]
    assert not check_limits(Design.from_dict(data)).parts_within_limits


def test_a_scene_whose_magnets_cannot_hold_anywhere_fails_in_one_line():
    data = tomllib.loads(SMALL.read_text())
    data["magnets"] = {"material": "ndfeb"}
    with pytest.raises(InfeasibleError) as info:
        physical_setup_from_scene(scene_from_dict(data, "<test>"))
    text = str(info.value)
    assert "\n" not in text and text.startswith("magnets.material")
    assert "ndfeb-eh" in text  # what would work


@pytest.mark.parametrize("value", [-1.0, 0.0, "strong"])
def test_bad_coercivity_names_the_key(value):
    with pytest.raises(InputError, match=r"magnets\.coercivity"):
        physical_setup_from_scene(scene_with(magnets={"material": "ndfeb", "coercivity": value}))


def test_a_given_coercivity_overrides_the_grade():
    magnets = {"material": "ndfeb", "coercivity": 2.2e6}
    setup = physical_setup_from_scene(scene_with(magnets=magnets))
    assert setup.spec.magnet.to_dict()["intrinsic_coercivity_A_per_m"] == 2.2e6
    assert setup.spec.magnet.field_withstood() == pytest.approx(MU_0 * (2.2e6 - 1e6 / 3))
    assert np.any(setup.magnet_sites) and not np.all(setup.magnet_sites)
