"""Acceptance defects of `uncertainty` / `iso10360`: travel, option order, option names in
messages, negative zero in print, histogram size and labels."""

from __future__ import annotations

import json
import struct

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.errors import InputError
from volerr.tables import ErrorTable, write_error_dir
from volerr.uncertainty import ensemble, iso10360, montecarlo as mc, plots, tasks

MB1 = volerr.load("MB1")     # travel X 0..900, Y 0..575, Z 0..400 mm (runtime/layouts/MB1.toml)


def _err(capsys, argv):
    code = main(argv)
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err
    return err.strip()


def _task(tmp_path, rows, name="t.csv"):
    f = tmp_path / name
    f.write_text("X,Y,Z\n" + "\n".join(",".join(map(str, r)) for r in rows) + "\n")
    return str(f)


def _errors_dir(tmp_path):
    nodes = np.linspace(0, 900, 10)
    d = tmp_path / "err"
    write_error_dir(d, {"X": ErrorTable("X", nodes, {"EXX": 1e-6 * nodes},
                                        std={"EXX": np.full(10, 0.5e-3)})})
    return str(d)


# ----------------------------------------------------------------------------- travel
MSG = "task point 3: X = 1000 mm outside the travel 0..900 mm of MB1"


@pytest.mark.parametrize("machine", [["--spec", "E0=3+L/300"], ["--noise-um", "1"], "errors"])
def test_task_point_outside_travel_refused_for_every_machine(tmp_path, capsys, machine):
    """X = 1000 on MB1 (X travel 0..900): one message whatever the machine knowledge is; no
    output written."""
    task = _task(tmp_path, [(100, 100, 100), (300, 100, 100), (1000, 100, 100)])
    if machine == "errors":
        machine = ["--errors", _errors_dir(tmp_path)]
    out = tmp_path / "o.json"
    err = _err(capsys, ["uncertainty", "MB1", "--task", task, "--evaluate", "circle",
                        *machine, "--json", str(out), "--samples", "300", "--quiet"])
    assert err.endswith(MSG)
    assert not out.exists()


def test_travel_check_every_axis_both_ends_and_first_point(tmp_path, capsys):
    task = _task(tmp_path, [(100, 100, 100), (100, 100, -5), (100, 600, 100)])
    err = _err(capsys, ["uncertainty", "MB1", "--task", task, "--evaluate", "circle",
                        "--noise-um", "1", "--json", str(tmp_path / "o.json"), "--quiet"])
    assert err.endswith("task point 2: Z = -5 mm outside the travel 0..400 mm of MB1")
    # the travel ends themselves are inside
    t = tasks.Task({"X": np.array([0.0, 900.0]), "Y": np.array([0.0, 575.0]),
                    "Z": np.array([400.0, 0.0])}, np.zeros((2, 3)))
    tasks.check_travel(MB1, t.positions)
    mc.prepare(MB1, "MB1", t, "distance", ensemble.Ensemble.build(noise_um=1.0))


def test_rotary_axis_travel_checked_in_deg():
    dmu = volerr.load("DMU50")           # B travel 0..180 deg, C -360..360 deg
    lo, hi = dmu.travel["B"]
    pos = {"X": np.zeros(2), "Y": np.zeros(2), "Z": np.full(2, 100.0),
           "B": np.array([90.0, hi + 20.0]), "C": np.zeros(2)}
    with pytest.raises(InputError, match=rf"^task point 2: B = {hi + 20:g} deg outside the "
                                         rf"travel {lo:g}\.\.{hi:g} deg of DMU50$"):
        tasks.check_travel(dmu, pos)
    pos["B"] = np.array([90.0, hi])
    tasks.check_travel(dmu, pos)


def test_iso10360_geometry_outside_the_travel_refused():
    box = {"X": (0.0, 2000.0), "Y": (0.0, 575.0), "Z": (0.0, 400.0)}  # X line 300..1700
    with pytest.raises(InputError, match="ISO 10360-2 test point .*: X = .* outside the travel "
                                         "0..900 mm of MB1"):
        iso10360.length_test(MB1, box)
    iso10360.length_test(MB1)            # the default box is the travel


# ----------------------------------------------------------------------------- options
def test_option_values_checked_before_what_is_uncertain(tmp_path, capsys):
    task = _task(tmp_path, [(100, 100, 100), (300, 100, 100)])
    base = ["uncertainty", "MB1", "--task", task, "--evaluate", "distance",
            "--json", str(tmp_path / "o.json"), "--quiet"]
    assert _err(capsys, base + ["--noise-um", "-1"]).endswith("--noise-um must be >= 0")
    assert _err(capsys, base + ["--correlation-mm", "-3"]).endswith(
        "--correlation-mm must be >= 0")
    assert _err(capsys, base + ["--samples", "1"]).endswith(
        "--samples must be between 2 and 1e8")
    assert "nothing is uncertain" in _err(capsys, base)


def test_iso10360_mpe_message_names_the_option(tmp_path, capsys):
    err = _err(capsys, ["iso10360", "MB1", "--errors", _errors_dir(tmp_path),
                        "--mpe", "E0=abc"])
    assert "--mpe 'E0=abc': expected" in err and "--spec" not in err
    # the uncertainty command keeps naming its own option
    with pytest.raises(InputError, match="^--spec 'E0=abc'"):
        ensemble.parse_spec("E0=abc")


# ----------------------------------------------------------------------------- printing
def test_iso10360_zero_errors_print_no_negative_zero(tmp_path, capsys):
    """A perfect machine: every E0 is zero; -(0.0) must not print as -0.000."""
    d = tmp_path / "zero"
    write_error_dir(d, {"X": ErrorTable("X", np.linspace(0, 900, 4), {"EXX": np.zeros(4)})})
    out = tmp_path / "z.json"
    assert main(["iso10360", "MB1", "--errors", str(d), "--json", str(out)]) == 0
    text = capsys.readouterr().out
    assert "-0.000" not in text and "+0.000" in text
    doc = json.loads(out.read_text())
    assert all(str(v) == "0.0" for p in doc["positions"] for row in p["E_um"] for v in row)


def test_report_number_format_has_no_negative_zero():
    from volerr.uncertainty.report import num
    assert num(-0.0, "+.3f") == "+0.000"
    assert num(-4e-5, ".3f") == "0.000"
    assert num(-4e-3, ".3f") == "-0.004"


def test_histogram_wide_with_one_unit_on_x(tmp_path):
    rng = np.random.default_rng(1)
    values = np.column_stack([200.0 + 1e-3 * rng.normal(size=3000),
                              5.0 + 2e-3 * rng.normal(size=3000)])
    summary = {n: {"estimate_mm": float(v.mean()), "standard_uncertainty_um": 1.0,
                   "expanded_uncertainty_um": 2.0,
                   "coverage_interval_mm": [float(v.mean()) - 2e-3, float(v.mean()) + 2e-3]}
               for n, v in zip(("distance", "other"), values.T)}
    for k in (1, 2):
        names = ("distance", "other")[:k]
        png = plots.histogram_png(values[:, :k], names, summary, "MB1 distance (3000 samples)")
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
        width, height = struct.unpack(">II", png[16:24])
        assert width >= 1000 and height >= 400
    fig = plots.histogram_figure(values, ("distance", "other"), summary, "t")
    try:
        for ax, n in zip(fig.axes, ("distance", "other")):
            assert ax.get_xlabel() == "deviation from the estimate / \u00b5m"
            assert f"estimate {summary[n]['estimate_mm']:.6f} mm" in ax.get_title()
            assert ax.xaxis.label.get_fontsize() >= 10
    finally:
        import matplotlib.pyplot as plt
        plt.close(fig)
