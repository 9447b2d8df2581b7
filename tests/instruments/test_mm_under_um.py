"""Readings in mm written under an ``_um`` header (values 1000x too small) are refused with one
line naming the column and the likely mistake, exit 2, nothing written: the ISO 230-2
positioning reader (``volerr iso230-2`` and the interferometer kind of ``volerr calibrate``),
the sphere / R-test reader, the ballbar reader and the volumetric deviations reader.  The
shipped examples and real small errors (a very good short axis spanning 0.1 um) pass.  Every
hostile case was accepted before :func:`volerr.units.check_reading_spread_um` (the first four
tests fail without it)."""

from __future__ import annotations

import csv

import numpy as np
import pytest

MM_UNDER_UM = "looks like mm written under _um (x1000)"


def _examples(tmp_path):
    from volerr.cli import main

    out = tmp_path / "ex"
    assert main(["examples", "--out", str(out)]) == 0
    return out


def _scaled(src, dst, columns, factor: float) -> None:
    """``src`` with the values of ``columns`` multiplied by ``factor`` (comment lines kept)."""
    lines = src.read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    rows = list(csv.reader(ln for ln in lines if not ln.startswith("#")))
    idx = [rows[0].index(c) for c in columns]
    for r in rows[1:]:
        for i in idx:
            r[i] = repr(float(r[i]) * factor)
    dst.write_text("\n".join(head + [",".join(r) for r in rows]) + "\n")


def _refused(args, tmp_path, capsys, column: str) -> None:
    from volerr.cli import main

    out = tmp_path / "out.json"
    code = main([*args, "--json", str(out)])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert MM_UNDER_UM in lines[0] and f"column {column}" in lines[0], lines[0]
    assert not out.exists()


def test_positioning_run_in_mm_refused(tmp_path, capsys):
    ex = _examples(tmp_path)
    bad = tmp_path / "run_mm.csv"
    _scaled(ex / "iso230_2_run_X.csv", bad, ["deviation_um"], 1e-3)
    _refused(["iso230-2", str(bad)], tmp_path, capsys, "deviation_um")
    headed = tmp_path / "run_mm_x.csv"
    headed.write_text("# axis: X\n" + bad.read_text())
    _refused(["calibrate", "MB1", f"interferometer:{headed}"], tmp_path, capsys,
             "deviation_um")


def test_sphere_readings_in_mm_refused(tmp_path, capsys):
    ex = _examples(tmp_path)
    bad = tmp_path / "sphere_mm.csv"
    _scaled(ex / "sphere_example_DMU50.csv", bad, ["dx_um", "dy_um", "dz_um"], 1e-3)
    _refused(["calibrate", "DMU50", str(bad)], tmp_path, capsys, "dx_um")


def test_ballbar_readings_in_mm_refused(tmp_path, capsys):
    ex = _examples(tmp_path)
    bad = tmp_path / "ballbar_mm.csv"
    _scaled(ex / "ballbar_example_XY.csv", bad, ["dr_um"], 1e-3)
    _refused(["calibrate", "MB1", str(bad)], tmp_path, capsys, "dr_um")


def test_deviations_in_mm_refused(tmp_path, capsys):
    ex = _examples(tmp_path)
    bad = tmp_path / "dev_mm.csv"
    # the example's spread is 53 um: in mm 0.053, above the 0.05 um bound (one-sided
    # evidence); a machine half as bad is caught
    _scaled(ex / "deviations_MB1.csv", bad, ["dx_um", "dy_um", "dz_um"], 0.5e-3)
    _refused(["loop", "MB1", str(bad)], tmp_path, capsys, "dx_um")


def test_real_small_errors_accepted(tmp_path):
    """A very good short axis: 0.1 um spread of the deviations (repeatability 0.02 um)."""
    from volerr.positioning import read_run

    rng = np.random.default_rng(5)
    lines = ["target_mm,cycle,direction,deviation_um"]
    for t in np.linspace(0.0, 100.0, 6):
        for c in range(1, 6):
            for d in ("+1", "-1"):
                v = 0.04 * np.sin(t / 30.0) + rng.normal(0.0, 0.01)
                lines.append(f"{t:g},{c},{d},{v:.4f}")
    path = tmp_path / "good_axis.csv"
    path.write_text("\n".join(lines) + "\n")
    run = read_run(path, "X")
    assert 0.05 <= 1e3 * float(np.ptp(run.deviation)) < 0.2


@pytest.mark.parametrize("name", ["iso230_2_run_X.csv", "sphere_example_DMU50.csv",
                                  "ballbar_example_XY.csv", "deviations_MB1.csv"])
def test_shipped_examples_pass(name, tmp_path):
    """The shipped examples' readings (spreads 9 to 54 um) are far above the bounds."""
    from volerr.units import check_reading_spread_um

    ex = _examples(tmp_path)
    rows = list(csv.reader(ln for ln in (ex / name).read_text().splitlines()
                           if not ln.startswith("#")))
    cols = {h: [float(r[i]) for r in rows[1:]] for i, h in enumerate(rows[0])
            if h.endswith("_um") and not h.startswith("u_")}
    check_reading_spread_um(cols, name, 0.5)


def test_the_bound_and_its_edges():
    """Refused strictly between 1 pm (round-off, a constant column: the readers' own checks)
    and the bound; the largest spread of the columns decides (one column may be flat)."""
    from volerr.errors import InputError
    from volerr.units import MIN_READING_SPREAD_UM, check_reading_spread_um

    assert MIN_READING_SPREAD_UM == 0.05
    check_reading_spread_um({"d_um": [0.0, 0.05]}, "f")                 # at the bound: kept
    check_reading_spread_um({"a_um": [0.001, 0.002], "b_um": [1.0, 3.0]}, "f")
    check_reading_spread_um({"d_um": [0.0, 0.0]}, "f")                  # zero-filled
    check_reading_spread_um({"d_um": [0.012, 0.012 + 1e-9]}, "f")       # round-off
    with pytest.raises(InputError, match=r"f: column d_um: the readings span 0.049 um"):
        check_reading_spread_um({"d_um": [0.001, 0.05]}, "f")
