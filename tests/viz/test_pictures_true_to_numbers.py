"""design.png says what the numbers say: its counts are check's (every mass of the body), a
round-off charge (|q| < 1e-9 of the largest) carries no sign colour nor a legend entry, and
its caption is legible (design.png once had an 8-pixel title, "160 masses" where check
counted 208, and 1e-12 C round-off drawn as "charge > 0")."""

from __future__ import annotations

import numpy as np
from test_viz import blue_pixels, make_design, red_pixels

from chargedesign import viz


def test_round_off_charges_get_no_sign_colour() -> None:
    q = np.array([1e-9, -1e-9, 1e-19, -1e-20, 0.0])
    assert list(viz.significant_charges(q)) == [1e-9, -1e-9, 0.0, 0.0, 0.0]
    colours = viz.charge_colors(q)
    np.testing.assert_array_equal(colours[2:], np.ones((3, 3)))  # white, as a zero charge
    assert colours[0][0] > colours[0][2] and colours[1][2] > colours[1][0]  # red, blue


def test_the_picture_draws_no_sign_a_round_off_charge_does_not_have() -> None:
    """No blue at all (neither a sphere nor the legend's "charge < 0" entry) when the only
    negative charge is round-off (the colour bar's map then has no blue either)."""
    design = make_design(charges=[1.0, 0.5, -1e-12])
    image = viz.render_image(design, window_size=(320, 240))
    assert red_pixels(image) > 0 and blue_pixels(image) == 0


def test_the_caption_counts_every_mass_as_check_does() -> None:
    design = make_design(charges=[1.0, -1.0], masses=[0.2, 0.2, 0.1])
    design = type(design).from_dict(
        {**design.to_dict(), "charges": {**design.to_dict()["charges"], "masses": [0.01, 0.01]}}
    )
    assert len(design.point_elements().mass_values) == 5  # what check counts
    assert viz.caption_counts(make_design(charges=[1.0], masses=[0.2])).startswith(
        "1 charges, 1 masses, 0 dipoles"
    )  # massless point charges add no mass
    assert viz.caption_counts(design) == "2 charges, 5 masses (3 ballast), 0 dipoles"
