"""The bifurcation command's refusals at the boundary (scene/bifurcation.py): each check
takes plain numbers, passes at its edge and refuses just past it in one line."""

from __future__ import annotations

import pytest

from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.scene import bifurcation as checks
from chargedesign.topology.diagram import check_parameters


def _refused(call, *args) -> str:
    with pytest.raises(InputError) as error:
        call(*args)
    line = str(error.value)
    assert "\n" not in line
    return line


def test_each_check_passes_at_its_edge_and_refuses_past_it() -> None:
    checks.check_regular(0.0, 0.0)
    assert _refused(checks.check_regular, 0.0, 1e-300).startswith("parameters: the bifurcation")
    checks.check_not_free_top(0.0, 1e-300, 0.0, 1e-300)
    assert "got c = 0, d = 0" in _refused(checks.check_not_free_top, 0.0, 0.0, 1.0, 1.0)
    checks.check_larmor_shift(1e10, 1.0)
    assert "C n^2 = 1e+10" in _refused(checks.check_larmor_shift, 1.0000001e10, 1.0)
    checks.check_h_range(0.0, 1e-300)
    assert _refused(checks.check_h_range, 1.0, 1.0).endswith("got 1 1")
    checks.check_range_width(0.0, 1.0, 1e-6, 1.0)
    assert "too narrow" in _refused(checks.check_range_width, 0.0, 1.0, 0.9e-6, 1.0)
    checks.check_energy_in_scale("--tori", 1000.0, 0.0, 1.0)
    assert "give energies up to 1000 J" in _refused(
        checks.check_energy_in_scale, "--tori", 1000.001, 0.0, 1.0
    )
    checks.check_regular_value(1.0, 2.0, None)
    assert "on the hyperbolic" in _refused(checks.check_regular_value, 1.0, 2.0, "hyperbolic")
    assert "no sample found" in _refused(checks.refuse_unresolved_chamber, 1, 2, (1, 2), [], [])
    assert "lies in no chamber" in _refused(checks.refuse_no_chamber, 1.0, 2.0)


def test_the_kernel_computes_the_figures_and_the_boundary_refuses() -> None:
    """The spread of the critical energies the kernel hands over is the one in the line."""
    closed = check_parameters(Parameters(C=1.0, c=1.0, d=0.5, K=1.0, kappa=0.3))
    line = _refused(
        checks.check_energy_in_scale, "--h-range", 1e6, closed.h_min, closed.energy_scale
    )
    assert "(1.00541 J)" in line and "least energy -0.545 J" in line
