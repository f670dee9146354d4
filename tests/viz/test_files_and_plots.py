"""Exports read by other tools (pandas, meshio) and the bench plots (one line per method)."""

import numpy as np
import pandas as pd
import pytest

from chargedesign import export
from chargedesign.bench.common import BenchTable
from chargedesign.bench.runner import plot_table
from chargedesign.body import Design
from chargedesign.params import Parameters


def design():
    return Design(
        parameters=Parameters(C=1.0, n=0.7),
        fields={"magnetic": (1.0, 1.0)},
        charge_positions=[[0.5, 0.0, 0.0], [0.0, 0.5, 0.1]],
        charge_values=[1e-6, -2e-6],
        mass_positions=[[0.0, 0.0, -0.5]],
        mass_values=[0.4],
        dipole_positions=[[0.0, 0.0, 0.3]],
        dipole_moments=[[0.0, 0.1, 0.0]],
        realises=["mu"],
        provenance={"scene": "<test>"},
    )


def test_csv_reads_with_plain_pandas_and_round_trips(tmp_path):
    d = design()
    path = export.export_design(d, "csv", tmp_path / "body.csv")
    table = pd.read_csv(path)  # no comment="#" needed
    assert list(table.columns) == ["kind", "x", "y", "z", "value", "mx", "my", "mz", "design"]
    assert table["x"].dtype == np.float64 and table["value"].dtype == np.float64
    charges = table[table.kind == "charge"]
    np.testing.assert_array_equal(charges[["x", "y", "z"]].to_numpy(), d.charge_positions)
    np.testing.assert_array_equal(charges["value"].to_numpy(), d.charge_values)
    back = export.import_design(path)
    np.testing.assert_array_equal(back.dipole_moments, d.dipole_moments)
    assert back.provenance == {"scene": "<test>"}


def test_csv_of_the_earlier_commented_form_is_still_read(tmp_path):
    old = tmp_path / "old.csv"
    old.write_text(
        '# design.parameters: {"C": 1.0}\nkind,x,y,z,value,mx,my,mz\ncharge,0.5,0.0,0.0,1e-06,,,\n'
    )
    assert export.import_design(old).charge_values.tolist() == [1e-06]


def test_vtu_is_read_by_meshio_and_round_trips(tmp_path):
    meshio = pytest.importorskip("meshio")
    d = design()
    path = export.export_design(d, None, tmp_path / "body.vtu")
    mesh = meshio.read(path)
    assert len(mesh.points) == 4
    kinds = np.asarray(mesh.point_data["kind"])
    np.testing.assert_array_equal(mesh.points[kinds == 0], d.charge_positions)
    np.testing.assert_array_equal(
        np.asarray(mesh.point_data["charge"])[kinds == 0], d.charge_values
    )
    back = export.import_design(path)
    np.testing.assert_array_equal(back.mass_values, d.mass_values)
    assert back.parameters == d.parameters


def bench_table():
    rows = [
        ["DOP853", "rtol 1e-08", 1e-8, 0.1],
        ["DOP853", "rtol 1e-12", 1e-12, 0.5],
        ["gauss-legendre", "step 0.1", 1e-14, 0.2],
        ["gauss-legendre", "step 0.05", 1e-15, 0.4],
    ]
    return BenchTable(
        title="t",
        columns=["method", "setting", "I4 rel drift", "seconds"],
        rows=rows,
        plot={"x": "seconds", "y": ["I4 rel drift"], "logx": True, "logy": True},
    )


def test_bench_plot_keeps_methods_apart_and_labels_y():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots()
    try:
        assert plot_table(bench_table(), ax) is fig
        lines = ax.get_lines()
        assert len(lines) == 2  # DOP853 and Gauss-Legendre: two lines, never one
        assert sorted(len(line.get_xdata()) for line in lines) == [2, 2]
        assert ax.get_ylabel() == "I4 rel drift"
        assert {line.get_label() for line in lines} == {
            "DOP853: I4 rel drift",
            "gauss-legendre: I4 rel drift",
        }
    finally:
        plt.close(fig)


def test_bench_says_what_runs_on_stderr(capsys):
    from chargedesign.cli import main

    assert main(["bench", "--quick", "--only", "fields"]) == 0
    err = capsys.readouterr().err
    assert "bench: fields ..." in err and "bench: fields done in" in err
    assert "bench: all areas in" in err


def test_a_long_area_is_said_while_it_runs():
    import io
    import threading

    from chargedesign.commands import progress as progress_module
    from chargedesign.commands.bench import AreaLines
    from chargedesign.commands.progress import Progress

    stream = io.StringIO()
    saved = progress_module.FIRST_AFTER, progress_module.EVERY
    progress_module.FIRST_AFTER, progress_module.EVERY = 0.0, 0.01
    try:
        bar = Progress("bench", unit="areas", stream=stream, tty=False)
        said = AreaLines(bar, 2)
        said.start("simulate")
        threading.Event().wait(0.1)
        said.start("fields")
        said.end()
        bar.close()
    finally:
        progress_module.FIRST_AFTER, progress_module.EVERY = saved
    text = stream.getvalue()
    assert "bench: 0/2 areas (simulate)" in text  # the heartbeat while simulate ran
    assert "bench: simulate done in" in text and "bench: fields done in" in text
    assert "bench: 2/2 areas" in text and "bench: all areas in" in text


@pytest.mark.parametrize("fmt", ["csv", "vtp", "vtu", "json"])
def test_physical_sizes_survive_every_export(tmp_path, fmt):
    d = design()
    d.charge_radii = np.array([0.01, 0.02])
    d.charge_masses = np.array([0.003, 0.004])
    d.dipole_volumes = np.array([1e-6])
    d.dipole_masses = np.array([0.0075])
    d = Design.from_dict(d.to_dict())  # validated again
    back = export.import_design(export.export_design(d, fmt, tmp_path / f"body.{fmt}"))
    np.testing.assert_array_equal(back.charge_radii, d.charge_radii)
    np.testing.assert_array_equal(back.charge_masses, d.charge_masses)
    np.testing.assert_array_equal(back.dipole_volumes, d.dipole_volumes)
    np.testing.assert_array_equal(back.dipole_masses, d.dipole_masses)
    assert back.total_mass == d.total_mass
