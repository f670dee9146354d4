"""Export formats: exact round trips, the CSV and VTP layouts read by independent routes, errors."""

import csv
import json

import numpy as np
import pytest
import pyvista as pv
from hypothesis import given, settings
from hypothesis import strategies as st

from chargedesign import export
from chargedesign.body import Design, write_design
from chargedesign.cli import main
from chargedesign.errors import InputError
from chargedesign.params import Parameters
from chargedesign.quadrature import ContinuousBody
from chargedesign.validation import MAX_MAGNITUDE

FORMATS = ("json", "csv", "vtp")


def sample_design(continuous=True):
    rng = np.random.default_rng(7)
    bodies = []
    if continuous:
        bodies = [
            ContinuousBody.from_dict(
                {
                    "kind": "charge",
                    "shape": "shell",
                    "radius": 0.4,
                    "center": [0.0, 0.1, 0.0],
                    "density": {"type": "polynomial", "coefficients": {"": 0.5, "xz": -2.0}},
                }
            ),
            ContinuousBody.from_dict(
                {
                    "kind": "mass",
                    "shape": "cylinder",
                    "radius": 0.3,
                    "height": 0.5,
                    "density": {"type": "uniform", "value": 2.5},
                }
            ),
        ]
    return Design(
        parameters=Parameters(C=1.0, c=0.3, d=-0.4, n=0.7, K=0.5, kappa=0.9),
        fields={"magnetic": (1.0, 1.0), "gravity": (9.81,)},
        charge_positions=rng.normal(size=(5, 3)),
        charge_values=rng.normal(size=5) * 1e-7,
        mass_positions=rng.normal(size=(3, 3)),
        mass_values=rng.uniform(0.0, 2.0, size=3),
        dipole_positions=rng.normal(size=(2, 3)),
        dipole_moments=rng.normal(size=(2, 3)),
        realises=["mu", "V", "inertia"],
        continuous=bodies,
        provenance={"solver": "clarabel", "scene": "<default>"},
        units={"positions": "m"},
        further_keys={"made_by": "a test"},
    )


def bits(array):
    return np.ascontiguousarray(array, dtype=np.float64).view(np.uint64)


def assert_identical(a, b):
    """Bit-identical arrays and the same design.json mapping."""
    for name in (
        "charge_positions",
        "charge_values",
        "mass_positions",
        "mass_values",
        "dipole_positions",
        "dipole_moments",
    ):
        x, y = getattr(a, name), getattr(b, name)
        assert y.dtype == np.float64 and x.shape == y.shape, name
        assert np.array_equal(bits(x), bits(y)), name
    assert a.to_dict() == b.to_dict()


@pytest.mark.parametrize("fmt", FORMATS)
def test_round_trip_is_exact(tmp_path, fmt):
    design = sample_design()
    path = export.export_design(design, fmt, tmp_path / f"body.{fmt}")
    assert_identical(design, export.import_design(path))
    assert sorted(p.name for p in tmp_path.iterdir()) == [f"body.{fmt}"]


@pytest.mark.parametrize("fmt", FORMATS)
def test_empty_design_round_trips(tmp_path, fmt):
    design = Design(parameters=Parameters())
    path = export.export_design(design, None, tmp_path / f"empty.{fmt}")
    assert_identical(design, export.import_design(path))


# any float64 a file may hold: the input range of docs/reliability.md (|x| <= 1e30)
finite = st.floats(min_value=-MAX_MAGNITUDE, max_value=MAX_MAGNITUDE, allow_nan=False, width=64)


@settings(max_examples=30, deadline=None)
@given(
    charges=st.lists(st.tuples(finite, finite, finite, finite), max_size=4),
    dipoles=st.lists(st.tuples(finite, finite, finite, finite, finite, finite), max_size=3),
)
def test_any_floats_survive_every_format(tmp_path_factory, charges, dipoles):
    c = np.array(charges, dtype=float).reshape(-1, 4)
    d = np.array(dipoles, dtype=float).reshape(-1, 6)
    design = Design(
        parameters=Parameters(),
        charge_positions=c[:, :3],
        charge_values=c[:, 3],
        dipole_positions=d[:, :3],
        dipole_moments=d[:, 3:],
    )
    folder = tmp_path_factory.mktemp("floats")
    for fmt in FORMATS:
        path = export.export_design(design, fmt, folder / f"d.{fmt}")
        assert_identical(design, export.import_design(path))


def test_vtp_refuses_vectors_whose_norm_overflows(tmp_path):
    design = Design(
        parameters=Parameters(), dipole_positions=[[0, 0, 0]], dipole_moments=[[1e300, 1e300, 0]]
    )
    # a kernel guard (ValueError, the same words): no design read from a file reaches it
    with pytest.raises(ValueError, match=r"dipoles\.moments: expected vectors whose length fits"):
        export.export_design(design, "vtp", tmp_path / "big.vtp")
    assert not any(tmp_path.iterdir())
    json_path = export.export_design(design, "json", tmp_path / "big.json")
    # a file's numbers must lie in the supported range: reading it back names the range
    with pytest.raises(InputError, match=r"dipoles\.moments.*outside the supported range"):
        export.import_design(json_path)


def test_csv_rows_read_by_the_csv_module(tmp_path):
    design = sample_design(continuous=False)
    path = export.export_design(design, "csv", tmp_path / "body.csv")
    lines = path.read_text().splitlines()
    assert lines[0] == "kind,x,y,z,value,mx,my,mz,design"  # a plain header row, no comments
    assert not any(line.startswith("#") for line in lines)
    rows = list(csv.DictReader(lines))
    assert list(rows[0]) == ["kind", "x", "y", "z", "value", "mx", "my", "mz", "design"]
    header = json.loads(rows[0]["design"])
    assert rows[0]["kind"] == "design" and header["provenance"]["solver"] == "clarabel"
    assert header["csv_units"].startswith("positions m, charge C, mass kg, dipole moment A m^2")
    by_kind = {k: [r for r in rows if r["kind"] == k] for k in ("charge", "mass", "dipole")}
    xyz = ("x", "y", "z")
    charge_positions = [[float(r[k]) for k in xyz] for r in by_kind["charge"]]
    assert np.array_equal(charge_positions, design.charge_positions)
    assert np.array_equal([float(r["value"]) for r in by_kind["charge"]], design.charge_values)
    assert np.array_equal([float(r["value"]) for r in by_kind["mass"]], design.mass_values)
    moments = [[float(r[k]) for k in ("mx", "my", "mz")] for r in by_kind["dipole"]]
    assert np.array_equal(moments, design.dipole_moments)
    assert all(r["value"] == "" for r in by_kind["dipole"])
    assert all(r["mx"] == "" for r in by_kind["charge"] + by_kind["mass"])


def test_vtp_arrays_read_by_pyvista(tmp_path):
    design = sample_design()
    path = export.export_design(design, "vtp", tmp_path / "body.vtp")
    mesh = pv.read(path)
    kind = np.asarray(mesh.point_data["kind"])
    points = np.asarray(mesh.points)
    assert points.dtype == np.float64
    assert mesh.n_verts == 10  # one vertex cell per element
    assert np.array_equal(points[kind == 0], design.charge_positions)
    assert np.array_equal(mesh.point_data["charge"][kind == 0], design.charge_values)
    assert np.array_equal(mesh.point_data["mass"][kind == 1], design.mass_values)
    assert np.array_equal(mesh.point_data["moment"][kind == 2], design.dipole_moments)
    assert not np.any(mesh.point_data["moment"][kind != 2])
    header = json.loads(str(mesh.field_data["chargedesign_design"][0]))
    assert header["parameters"] == design.parameters.as_dict()
    assert header["provenance"] == {"solver": "clarabel", "scene": "<default>"}
    # continuous bodies as surfaces: the shell's points on its sphere, value = density there
    shell = kind == 3
    assert np.count_nonzero(shell) > 100 and mesh.n_faces > 100
    centred = points[shell] - design.continuous[0].center
    np.testing.assert_allclose(np.linalg.norm(centred, axis=1), 0.4, rtol=1e-6)
    x, z = points[shell, 0], points[shell, 2]
    np.testing.assert_allclose(mesh.point_data["value"][shell], 0.5 - 2.0 * x * z, rtol=1e-12)
    np.testing.assert_array_equal(mesh.point_data["value"][kind == 4], 2.5)
    np.testing.assert_array_equal(np.unique(mesh.point_data["body"][kind >= 3]), [0, 1])


def test_format_from_the_extension_and_bad_formats(tmp_path):
    design = sample_design(continuous=False)
    assert export.export_design(design, None, tmp_path / "a.CSV").read_text().startswith("kind")
    with pytest.raises(InputError, match="format: expected one of json, csv, vtp, vtu, stl, step"):
        export.export_design(design, "xml", tmp_path / "a.xml")
    with pytest.raises(InputError, match=r"expected a file name ending in \.json, \.csv, \.vtp"):
        export.export_design(design, None, tmp_path / "a.txt")
    with pytest.raises(InputError, match=r"directory .* does not exist"):
        export.export_design(design, "json", tmp_path / "missing" / "a.json")
    with pytest.raises(InputError, match="it is a directory"):
        export.export_design(design, "json", tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.CSV"]


def test_failed_write_leaves_nothing_behind(tmp_path, monkeypatch):
    target = tmp_path / "body.vtp"
    target.write_text("old")

    def broken(design, path):
        path.write_text("half")
        raise RuntimeError("disk full")

    monkeypatch.setattr(export, "_write_vtp", broken)
    with pytest.raises(RuntimeError, match="disk full"):
        export.export_design(sample_design(), "vtp", target)
    assert target.read_text() == "old"
    assert [p.name for p in tmp_path.iterdir()] == ["body.vtp"]


def test_bad_imports_are_named(tmp_path):
    with pytest.raises(InputError, match="no such file"):
        export.import_design(tmp_path / "none.vtp")
    foreign = tmp_path / "sphere.vtp"
    pv.Sphere().save(foreign)
    with pytest.raises(InputError, match="not a chargedesign export"):
        export.import_design(foreign)
    bad_csv = tmp_path / "bad.csv"
    bad_csv.write_text("# design.parameters: {}\nkind,x,y,z\ncharge,0,0,0\n")
    with pytest.raises(InputError, match="columns: expected kind, x, y, z, value, mx, my, mz"):
        export.import_design(bad_csv)
    bad_row = tmp_path / "row.csv"
    bad_row.write_text("# design.parameters: {}\nkind,x,y,z,value,mx,my,mz\nquark,0,0,0,1,,,\n")
    with pytest.raises(InputError, match="row 2: kind: expected charge, mass or dipole"):
        export.import_design(bad_row)


@pytest.mark.parametrize("fmt", FORMATS)
def test_export_command_writes_each_format(tmp_path, capsys, fmt):
    design = sample_design()
    write_design(design, tmp_path / "design.json")
    out = tmp_path / f"out.{fmt}"
    argv = ["export", str(tmp_path / "design.json"), "--format", fmt, "--out", str(out)]
    assert main([*argv, "--json"]) == 0
    summary = json.loads(capsys.readouterr().out)
    assert summary == {
        "path": str(out),
        "format": fmt,
        "charges": 5,
        "masses": 3,
        "dipoles": 2,
        "continuous": 2,
    }
    assert_identical(design, export.import_design(out))


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (["design.json", "--out", "x.txt"], "x.txt: format: expected a file name ending in"),
        (["design.json", "--format", "obj", "--out", "x.obj"], "format: expected one of json"),
        (["design.json", "--format", "stl", "--out", "x.stl"], "no holder in design.json"),
        (["none.json", "--out", "x.json"], "none.json: no such design file"),
        (["design.json", "--out", "nowhere/x.vtp"], "directory nowhere does not exist"),
    ],
)
def test_export_command_errors_are_one_line(tmp_path, capsys, monkeypatch, args, fragment):
    monkeypatch.chdir(tmp_path)
    write_design(sample_design(continuous=False), tmp_path / "design.json")
    assert main(["export", *args]) == 2
    err = capsys.readouterr().err
    assert fragment in err and err.count("\n") == 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["design.json"]


def test_exported_files_get_the_usual_permissions(tmp_path):
    import os
    import stat

    mask = os.umask(0)
    os.umask(mask)
    path = export.export_design(sample_design(continuous=False), "csv", tmp_path / "body.csv")
    assert stat.S_IMODE(path.stat().st_mode) == 0o666 & ~mask


# --- the holder: stl and step ------------------------------------------------------------------


@pytest.fixture(scope="module")
def held_design(tmp_path_factory):
    """A body with a PMI-foam holder (tests/physical/holder.toml), designed at s = 1."""
    from pathlib import Path

    from chargedesign.designer.assembly import design_physical
    from chargedesign.designer.pipeline import physical_setup_from_scene
    from chargedesign.scene import load_scene

    scene = Path(__file__).parent / "physical" / "holder.toml"
    return design_physical(physical_setup_from_scene(load_scene(scene))).design


def _stl_solids(text):
    """{solid line: triangles (f, 3, 3)} of an ASCII STL."""
    solids, name, tri = {}, None, []
    for line in text.splitlines():
        words = line.split()
        if words[0] == "solid":
            name, tri = line[len("solid ") :], []
        elif words[0] == "vertex":
            tri.append([float(w) for w in words[1:]])
        elif words[0] == "endsolid":
            solids[name] = np.array(tri).reshape(-1, 3, 3)
    return solids


def _closed(tri):
    """Every edge of the shell is met twice, once each way (closed and oriented)."""
    keys = [tuple(np.round(v, 12)) for v in tri.reshape(-1, 3)]
    index = {k: i for i, k in enumerate(dict.fromkeys(keys))}
    faces = np.array([index[k] for k in keys]).reshape(-1, 3)
    edges = {}
    for a, b, c in faces:
        for e in ((a, b), (b, c), (c, a)):
            edges[e] = edges.get(e, 0) + 1
    return all(n == 1 and edges.get((j, i)) == 1 for (i, j), n in edges.items())


def test_holder_stl_is_closed_and_encloses_the_recorded_volume(held_design, tmp_path):
    path = export.export_design(held_design, "stl", tmp_path / "holder.stl")
    solids = _stl_solids(path.read_text("ascii"))
    holder = held_design.holder
    assert len(solids) == 1 + len(holder["bores"])
    assert all("units=m" in name for name in solids)
    volume = 0.0
    for tri in solids.values():
        assert _closed(tri)
        volume += np.sum(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2]))) / 6
    assert volume == pytest.approx(holder["volume_m3"], rel=1e-2)
    assert volume == pytest.approx(holder["volume_m3"], rel=1e-9)  # each shell scaled to it
    # each bore names its part, in the solid's name and in the sidecar
    parts = {b["part"].replace(" ", "_") for b in holder["bores"]}
    assert {n.split()[1].removeprefix("part=") for n in solids if n.startswith("bore")} == parts
    sidecar = json.loads((tmp_path / "holder.stl.bores.json").read_text())
    assert sidecar["units"] == "m" and sidecar["bores"] == holder["bores"]


def test_holder_step_names_every_part(held_design, tmp_path):
    pytest.importorskip("build123d")
    path = export.export_design(held_design, "step", tmp_path / "holder.step")
    text = path.read_text("utf-8", errors="replace")
    assert text.startswith("ISO-10303-21;")
    for bore in held_design.holder["bores"]:
        assert f"PRODUCT('{bore['part'].replace(' ', '_')}'" in text


def test_step_without_the_extra_is_one_line(held_design, tmp_path, monkeypatch):
    import builtins

    real = builtins.__import__

    def no_cad(name, *args, **kwargs):
        if name == "build123d":
            raise ImportError("no build123d")
        return real(name, *args, **kwargs)

    monkeypatch.setattr(builtins, "__import__", no_cad)
    with pytest.raises(InputError, match=r"pip install 'chargedesign\[cad\]'") as info:
        export.export_design(held_design, "step", tmp_path / "holder.step")
    assert "\n" not in str(info.value)
    assert list(tmp_path.iterdir()) == []


def test_holder_files_are_not_read_back(held_design, tmp_path):
    path = export.export_design(held_design, "stl", tmp_path / "holder.stl")
    with pytest.raises(InputError, match="holds the holder's shape only"):
        export.import_design(path)
