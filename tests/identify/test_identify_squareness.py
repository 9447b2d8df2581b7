"""Squareness from straightness reference lines, and fitted error functions."""

import numpy as np
import pytest

import volerr
from volerr.tables.errorfit import fit, fit_table
from volerr.errors import InputError
from volerr.cmm.squareness import reference_line, squareness
from volerr.tables.table import ErrorTable


@pytest.mark.parametrize("layout", ["MB1", "MH2", "FB1"])
def test_squareness_consistent_with_layout_model(layout):
    """Lines of motion from the model's own volumetric error with only squareness set."""
    m = volerr.load(layout)
    truth = {"EC0Y": 25e-6, "EB0Z": -40e-6, "EA0Z": 15e-6}
    truth = {k: v for k, v in truth.items() if k in m.parameters}
    s = np.linspace(0, 400, 9)
    tables = {}
    for ax in ("X", "Y", "Z"):
        pos = {a: np.zeros_like(s) for a in m.axes}
        pos[ax] = s
        d = np.asarray(m.volumetric_error(pos, truth))  # (N, 3) tool relative to workpiece
        vals = {f"E{c}{ax}": d[:, i] for i, c in enumerate("XYZ")}
        tables[ax] = ErrorTable(ax, s, vals)
    values, std, corrected, _ = squareness(tables, m_layout(layout), "component")
    for k, v in truth.items():
        assert values[k] == pytest.approx(v, abs=1e-12), k
    for ax, t in corrected.items():
        for name, v in t.values.items():
            if name[1] != ax:
                assert np.allclose(v, 0, atol=1e-12)


def m_layout(name):
    from volerr.machine.layout import read_layout
    return read_layout(name)


def test_squareness_exact_lines():
    """X moves along Rz(psi) e_x, Y along Rz(phi) e_y: EC0Y = phi - psi (right-hand about z)."""
    psi, phi = 40e-6, -15e-6
    s = np.linspace(0, 600, 7)
    ex = np.array([np.cos(psi), np.sin(psi)])
    ey = np.array([-np.sin(phi), np.cos(phi)])
    X = ErrorTable("X", s, {"EYX": s * ex[1] + 1e-4 * np.sin(s / 100)})
    Y = ErrorTable("Y", s, {"EXY": s * ey[0]})
    values, _, corrected, _ = squareness({"X": X, "Y": Y})
    curv = reference_line(s, 1e-4 * np.sin(s / 100))[0]
    assert values["EC0Y"] == pytest.approx(phi - psi - curv, abs=1e-9)
    # slope removed, the reference position stays zero
    assert corrected["X"].values["EYX"][0] == 0
    assert abs(reference_line(s, corrected["X"].values["EYX"])[0]) < 1e-15


def test_table_axis_sign():
    """identify writes the table's own motion for a table axis: its slope flips sign."""
    from volerr.machine.layout import parse_layout

    lay = parse_layout("""
name = "T"
[axes.X]
kind = "linear"
direction = [1, 0, 0]
travel = [0, 500]
[axes.Y]
kind = "linear"
direction = [0, 1, 0]
travel = [0, 500]
[chain]
tool = ["X"]
workpiece = ["Y"]
""")
    s = np.linspace(0, 500, 6)
    X = ErrorTable("X", s, {"EYX": 0 * s})
    Y = ErrorTable("Y", s, {"EXY": 1e-5 * s})
    comp, _, _, _ = squareness({"X": X, "Y": Y}, lay, "component")
    carr, _, _, _ = squareness({"X": X, "Y": Y}, lay, "carrier")
    assert carr["EC0Y"] == pytest.approx(-comp["EC0Y"])


def test_poly_fit_degree_and_residual():
    rng = np.random.default_rng(3)
    x = np.linspace(0, 500, 21)
    u = x / 500
    y = 0.01 * (u - 2 * u ** 2 + 1.5 * u ** 3) + rng.normal(0, 2e-5, x.size)
    f = fit("EXX", x, y, "poly")
    assert 2 <= f.degree <= 5
    assert f.rms_residual < 4e-5
    assert f(250.0) == pytest.approx(0.01 * (0.5 - 0.5 + 1.5 / 8), abs=1e-4)
    with pytest.raises(InputError, match="outside the measured range"):
        f(600.0)
    assert np.isfinite(f(600.0, extrapolate=True))


def test_fit_table_weighted_and_smooth():
    x = np.linspace(0, 360, 19)
    y = 1e-5 * np.sin(np.radians(x))
    std = np.full(x.size, 1e-6)
    std[0] = 0
    t = ErrorTable("C", x, {"ECC": y}, {"ECC": std})
    fits = fit_table(t, "poly", weighted=True)
    assert fits["ECC"].rms_residual < 5e-7
    s = fit_table(t, "smooth")["ECC"]
    assert s.report()["unit"] == "urad" and s.rms_residual < 1e-6


def test_shipped_example_identifies_and_gives_squareness(tmp_path):
    """The shipped example tracker data (simulated, tests/tracker_sim.example_set) through
    identify and squareness recovers the simulated truth within the stated uncertainty."""
    from importlib import resources
    from helpers.tracker_sim import example_set

    from volerr.identify.solve import identify
    from volerr.machine.layout import read_layout
    from volerr.identify.tracker_io import read_tracker_csv

    data, sq = example_set()
    tables = {}
    for axis in "XYZ":
        f = resources.files("volerr") / "data" / f"tracker_example_{axis}.csv"
        res = identify(read_tracker_csv(f), "MB1", axis)
        pos, rounds, e = data[axis]
        assert np.allclose(res.positions, pos)
        z = np.abs(res.values - e)[1:] / (res.u_tracker[1:] / 2.0)  # 4 rounds: u of mean
        assert z.max() < 5.0
        tables[axis] = res.errors_table()
    values, std, _, _ = squareness(tables, read_layout("MB1"))
    for k, v in sq.items():
        assert abs(values[k] - v) < 3 * std[k] + 2e-6, k
