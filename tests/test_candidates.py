import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from chargedesign.candidates import (
    MAX_CANDIDATES,
    candidates_from_points,
    candidates_from_table,
    geometry_of,
    symmetrise,
    symmetry_images,
)
from chargedesign.errors import InputError


def _same_set(a, b, tol=1e-12):
    """Equal as sets of points (order ignored)."""
    if a.shape != b.shape:
        return False
    ka = a[np.lexsort(np.round(a / tol).T)]
    kb = b[np.lexsort(np.round(b / tol).T)]
    return np.allclose(ka, kb, atol=tol, rtol=0)


def _near(a, b, rtol):
    """Every point of a is within rtol (of the size) of a point of b."""
    from scipy.spatial import cKDTree

    scale = max(1.0, float(np.abs(b).max()))
    return bool(np.all(cKDTree(b).query(a)[0] <= rtol * scale))


def _invariant_under_group(points, rtol=1e-12):
    """Each of the 16 images of every point is (within rtol of the size) a point of the set.

    (``symmetrise`` merges points closer than 1e-9 of the size, so a closure is invariant up
    to that.)
    """
    return _near(symmetry_images(points), points, rtol)


def test_ball_is_the_lattice_in_the_ball():
    cand = candidates_from_table({"shape": "ball", "radius": 1.0, "spacing": 0.25})
    pts = cand.points
    # independent count: integer triples (i, j, k) with i^2 + j^2 + k^2 <= 16
    expected = sum(
        1
        for i in range(-4, 5)
        for j in range(-4, 5)
        for k in range(-4, 5)
        if i * i + j * j + k * k <= 16
    )
    assert len(pts) == expected
    assert np.all(np.linalg.norm(pts, axis=1) <= 1.0 + 1e-12)
    assert np.allclose(pts / 0.25, np.round(pts / 0.25), atol=1e-12)
    assert _invariant_under_group(pts)
    assert cand.description["n"] == expected
    assert cand.region == {"shape": "ball", "radius": 1.0}
    assert cand.notes == ()


def test_box_half_size_and_size_agree_and_stay_inside():
    a = candidates_from_table({"shape": "box", "half_size": [0.5, 0.5, 0.3], "spacing": 0.1})
    b = candidates_from_table({"shape": "box", "size": [1.0, 1.0, 0.6], "spacing": 0.1})
    assert _same_set(a.points, b.points)
    assert len(a.points) == 11 * 11 * 7
    assert np.all(np.abs(a.points) <= np.array([0.5, 0.5, 0.3]) + 1e-12)
    assert a.region == {"shape": "box", "half_size": [0.5, 0.5, 0.3]}


def test_box_with_unequal_xy_is_not_symmetrised_unless_asked():
    table = {"shape": "box", "half_size": [1.0, 0.5, 0.5], "spacing": 0.25}
    plain = candidates_from_table(table)
    assert np.all(np.abs(plain.points[:, 1]) <= 0.5 + 1e-12)
    closed = candidates_from_table({**table, "symmetric": True})
    assert len(closed.points) > len(plain.points)
    assert _invariant_under_group(closed.points)


def test_cylinder_points():
    cand = candidates_from_table(
        {"shape": "cylinder", "radius": 0.05, "height": 0.1, "spacing": 0.0125}
    )
    pts = cand.points
    assert np.all(np.hypot(pts[:, 0], pts[:, 1]) <= 0.05 * (1 + 1e-9))
    assert np.all(np.abs(pts[:, 2]) <= 0.05 * (1 + 1e-9))
    assert np.isclose(pts[:, 2].max(), 0.05) and np.isclose(pts[:, 2].min(), -0.05)
    assert _invariant_under_group(pts)


@pytest.mark.parametrize("n_points", [16, 100, 500])
def test_symmetric_shell(n_points):
    cand = candidates_from_table({"shape": "shell", "radius": 2.0, "n_points": n_points})
    pts = cand.points
    assert np.allclose(np.linalg.norm(pts, axis=1), 2.0, rtol=1e-14)
    assert len(pts) % 16 == 0
    assert abs(len(pts) - n_points) <= max(16, 0.2 * n_points)
    assert _invariant_under_group(pts)
    # no two points coincide
    d = np.linalg.norm(pts[:, None] - pts[None], axis=2) + np.eye(len(pts))
    assert d.min() > 1e-6


def test_plain_fibonacci_shell_has_the_requested_count():
    cand = candidates_from_table(
        {"shape": "shell", "radius": 1.0, "n_points": 37, "symmetric": False}
    )
    assert len(cand.points) == 37


def test_center_offset_moves_the_set():
    cand = candidates_from_table(
        {"shape": "ball", "radius": 0.5, "spacing": 0.25, "center": [0.0, 0.0, 2.0]}
    )
    assert np.allclose(cand.geometry.centroid, [0.0, 0.0, 2.0], atol=1e-12)
    assert cand.description["symmetric"] is False
    assert cand.region["center"] == [0.0, 0.0, 2.0]


def test_point_files(tmp_path):
    pts = np.array([[0.1, 0.2, 0.3], [-0.1, 0.0, 0.5], [0.0, 0.0, -0.2]])
    (tmp_path / "p.csv").write_text(
        "x,y,z\n" + "\n".join(",".join(map(str, p)) for p in pts) + "\n"
    )
    (tmp_path / "p.txt").write_text(
        "# comment\n" + "\n".join(" ".join(map(str, p)) for p in pts) + "\n"
    )
    np.save(tmp_path / "p.npy", pts)
    for name in ("p.csv", "p.txt", "p.npy"):
        cand = candidates_from_table({"shape": "points", "path": name}, base_dir=tmp_path)
        assert np.array_equal(cand.points, pts)
        assert cand.region == {"shape": "points"}
    scaled = candidates_from_table(
        {"shape": "points", "path": str(tmp_path / "p.npy"), "scale": 0.01}
    )
    assert np.allclose(scaled.points, pts * 0.01, rtol=1e-15)


def test_bad_point_file_names_the_line(tmp_path):
    (tmp_path / "bad.csv").write_text("x,y,z\n1,2,3\n4,5\n")
    with pytest.raises(InputError, match=r"line 3: expected three numbers"):
        candidates_from_table({"shape": "points", "path": "bad.csv"}, base_dir=tmp_path)


def test_mesh_surface_and_volume(tmp_path):
    import pyvista as pv

    sphere = pv.Sphere(radius=1.0, theta_resolution=16, phi_resolution=16)
    sphere.save(tmp_path / "sphere.vtp")
    surface = candidates_from_table({"shape": "mesh", "path": str(tmp_path / "sphere.vtp")})
    assert np.allclose(np.linalg.norm(surface.points, axis=1), 1.0, rtol=1e-6)
    volume = candidates_from_table(
        {
            "shape": "mesh",
            "path": str(tmp_path / "sphere.vtp"),
            "sample": "volume",
            "spacing": 0.25,
            "scale": 2.0,
        }
    )
    radii = np.linalg.norm(volume.points, axis=1)
    assert radii.max() <= 2.0 + 1e-9 and len(volume.points) > 100
    # the faceted sphere is slightly inside the true one: the lattice count is close to it
    full = candidates_from_table({"shape": "ball", "radius": 2.0, "spacing": 0.25})
    assert 0.8 * len(full.points) <= len(volume.points) <= len(full.points)


def test_open_mesh_has_no_interior(tmp_path):
    import pyvista as pv

    pv.Plane().triangulate().save(tmp_path / "plane.vtp")
    with pytest.raises(InputError, match="not closed"):
        candidates_from_table(
            {
                "shape": "mesh",
                "path": str(tmp_path / "plane.vtp"),
                "sample": "volume",
                "spacing": 0.1,
            }
        )


@pytest.mark.parametrize(
    ("table", "message"),
    [
        (
            {"shape": "ball", "radius": 1.0, "spacing": -1},
            "body.spacing: expected a number > 0, got -1",
        ),
        ({"shape": "ball", "radius": "1"}, "body.radius: expected a real number"),
        ({"shape": "ball", "spacing": 0.1}, "body.radius: required for shape = 'ball'"),
        ({"shape": "cube", "radius": 1.0}, "body.shape: expected one of ball, box"),
        ({"shape": "ball", "radius": 1.0, "height": 2.0}, "body.height: expected a key of shape"),
        ({"shape": "box", "spacing": 0.1}, "body.half_size: required"),
        ({"shape": "box", "half_size": 1.0, "size": 2.0}, "body.size: give either"),
        ({"shape": "box", "half_size": [1, 0, 1]}, "body.half_size: expected three numbers > 0"),
        ({"shape": "shell", "radius": 1.0, "n_points": 2.5}, "body.n_points: expected an integer"),
        (
            {"shape": "ball", "radius": 1.0, "symmetric": "yes"},
            "body.symmetric: expected true or false",
        ),
        ({"shape": "ball", "radius": 1.0, "center": [0, 0]}, "body.center: expected shape (3,)"),
        ({"shape": "points"}, "body.path: expected a file name"),
        ({"shape": "points", "path": "/no/such/file.csv"}, "body.path: no such file"),
        ({"shape": "ball", "radius": 1.0, "spacing": 0.01}, f"at most {MAX_CANDIDATES}"),
        ({"shape": "mesh", "path": "x.vtp", "sample": "inside"}, "body.sample: expected"),
    ],
)
def test_bad_body_tables_name_the_key(table, message):
    with pytest.raises(InputError) as info:
        candidates_from_table(table)
    assert message in str(info.value)
    assert "\n" not in str(info.value)


def test_planar_and_nearly_planar_sets_are_named():
    flat = candidates_from_table({"shape": "box", "half_size": [1.0, 1.0, 0.1], "spacing": 0.25})
    assert flat.geometry.dimension == 2
    assert flat.notes == ("candidates all lie in the plane z = 0",)
    thin = candidates_from_points(
        np.array([[x, y, z] for x in range(5) for y in range(5) for z in (-1e-3, 1e-3)], float)
    )
    assert thin.geometry.dimension == 3
    assert "nearly planar" in thin.notes[0] and "z = 0" in thin.notes[0]


def test_tilted_plane_and_line_texts():
    rng = np.random.default_rng(1)
    uv = rng.uniform(-1, 1, (50, 2))
    normal = np.array([1.0, 2.0, 2.0]) / 3.0
    e1 = np.array([2.0, -1.0, 0.0]) / math.sqrt(5.0)
    e2 = np.cross(normal, e1)
    pts = uv[:, :1] * e1 + uv[:, 1:] * e2 + 0.5 * normal
    geom = geometry_of(pts)
    assert geom.dimension == 2
    text = geom.plane_text()
    assert text.startswith("the plane 0.333 x + 0.667 y + 0.667 z = 0.5")
    line = geometry_of(np.outer(np.linspace(-1, 1, 7), [0.0, 1.0, 0.0]))
    assert line.dimension == 1 and line.plane_text().startswith("the line through")


@settings(max_examples=30, deadline=None)
@given(
    st.lists(
        st.tuples(*[st.floats(-2, 2, allow_nan=False, allow_infinity=False)] * 3),
        min_size=1,
        max_size=12,
    )
)
def test_symmetrise_is_closed_and_idempotent(raw):
    pts = np.array(raw, dtype=float)
    closed = symmetrise(pts)
    assert _invariant_under_group(closed, rtol=1e-8)
    again = symmetrise(closed)
    assert len(again) == len(closed)
    assert _near(again, closed, 1e-8) and _near(closed, again, 1e-8)
    # every original point is in the closure
    for p in pts:
        assert np.min(np.linalg.norm(closed - p, axis=1)) <= 1e-8 * max(1.0, np.abs(pts).max())


@pytest.mark.parametrize("spacing", [1e-30, 1e-20, 1e-12])
def test_a_spacing_too_fine_for_the_lattice_is_refused_by_its_spacing(spacing):
    """A spacing of 1e-30 made 1e29 lattice steps, which overflowed int64 into one wrong point
    near O (with two RuntimeWarnings; the design then failed for "all in one point"). It is
    refused by its spacing, before any point is made."""
    with pytest.raises(InputError, match=r"^body\.spacing: expected a spacing giving at most"):
        candidates_from_table({"shape": "ball", "radius": 0.05, "spacing": spacing})
