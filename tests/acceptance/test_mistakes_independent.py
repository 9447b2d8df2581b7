"""Independent acceptance suite for issue 43 ("never a confident wrong answer").

Written by someone who did not write the checks.  Each case is a mistake a metrologist makes at
the machine, built by a small mutation of a shipped example (``volerr examples``) or of a file
``volerr simulate`` writes -- never hand-typed data.  The expected behaviour of a mistake:

* exit 2, exactly ONE non-empty stderr line, no traceback, no Python warning;
* the line names the file (or the option), the column, and the likely cause;
* no output file written (every case passes ``--json`` / ``--errors-out`` / ``--out`` ... paths
  and checks afterwards that none exists).

The opposite is tested too (false alarms are defects): the shipped examples and correctly
formed variants (another ballbar radius, a simulated sphere campaign, a noisy file, shuffled
rows) run with exit 0 and write their outputs.

Cases the program gets wrong are kept, marked ``xfail(strict=True)`` with what goes wrong, so
the list of defects is explicit and the suite stays green.  Run:
``python -m pytest -p no:xdist -q tests/acceptance/test_mistakes_independent.py``.
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from volerr.cli import main

# ---------------------------------------------------------------------------------------------
# helpers


@pytest.fixture(scope="module")
def ex(tmp_path_factory):
    """The shipped example files, written once for the module (read only: copy before use)."""
    d = tmp_path_factory.mktemp("examples")
    assert main(["examples", "--out", str(d)]) == 0
    return d


def _split_comments(path: Path):
    """Leading '#' lines of a CSV and the table below them."""
    lines = path.read_text().splitlines(keepends=True)
    head = [ln for ln in lines if ln.startswith("#")]
    return "".join(head), pd.read_csv(path, comment="#")


def mutate(src: Path, dst: Path, fn) -> Path:
    """Copy ``src`` to ``dst`` with ``fn(DataFrame) -> DataFrame`` applied (comments kept)."""
    head, df = _split_comments(src)
    df = fn(df.copy())
    dst.write_text(head + df.to_csv(index=False, float_format="%.9g"))
    return dst


def scale(columns, factor):
    """A mutation: ``columns`` multiplied by ``factor`` (a unit mistake)."""
    def fn(d):
        for c in columns:
            d[c] = d[c] * factor
        return d
    return fn


def um_columns_in_nm(d):
    """A mutation: every ``*_um`` column of an error table in nm (x 1000) under its um header."""
    return scale([c for c in d.columns if c.endswith("_um")], 1000.0)(d)


def copy_dir(src: Path, dst: Path) -> Path:
    shutil.copytree(src, dst)
    return dst


def run(capsys, argv):
    """``volerr.cli.main(argv)`` in-process: (exit code, stdout, stderr, warnings)."""
    capsys.readouterr()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        code = main([str(a) for a in argv])
    cap = capsys.readouterr()
    return code, cap.out, cap.err, [str(w.message) for w in caught]


def _mentions(line: str, word: str) -> bool:
    """``word`` in ``line`` (case-insensitive; a short column name as a whole word)."""
    if len(word) <= 2:
        return re.search(rf"(?<![A-Za-z0-9_]){re.escape(word)}(?![A-Za-z0-9_])", line) is not None
    return word.lower() in line.lower()


def refused(capsys, argv, outputs, name, columns=(), causes=()):
    """Exit 2, one stderr line naming ``name``, any of ``columns``, any of ``causes``; no
    warning, no traceback, none of ``outputs`` written."""
    code, out, err, warned = run(capsys, argv)
    lines = [ln for ln in err.splitlines() if ln.strip()]
    written = [str(p) for p in outputs if Path(p).exists()]
    report = f"exit {code}; stderr {err!r}; warnings {warned}; written {written}; stdout {out[-300:]!r}"
    assert code == 2, report
    assert len(lines) == 1 and "Traceback" not in err, report
    assert not warned, report
    assert not written, report
    line = lines[0]
    assert _mentions(line, name), f"does not name {name!r}: {line}"
    # a list of the causes ruled out names none of them as the likely one
    judged = re.sub(r"no usual mistake \([^)]*\) explains it", "", line)
    if columns:
        assert any(_mentions(judged, c) for c in columns), f"names none of {columns}: {line}"
    if causes:
        assert any(_mentions(judged, c) for c in causes), f"names none of the causes {causes}: {line}"
    return line


def accepted(capsys, argv, outputs=()):
    """Exit 0, no traceback, every one of ``outputs`` written."""
    code, out, err, warned = run(capsys, argv)
    assert code == 0, f"exit {code}; stderr {err!r}"
    assert "Traceback" not in err and "error:" not in err, err
    for p in outputs:
        assert Path(p).exists(), f"{p} not written; stderr {err!r}"
    return out, err, warned


def xfail(reason):
    return pytest.mark.xfail(strict=True, reason=reason)


RAD = np.pi / 180.0
INCH = 25.4


def outs_cal(t):
    """The outputs of a calibrate run: a JSON report and an error directory (parent exists)."""
    return [t / "cal.json", t / "cal_errors"]


def cal_argv(layout, files, t, *extra):
    o = outs_cal(t)
    return ["calibrate", layout, *files, "--json", o[0], "--errors-out", o[1], *extra]


# ---------------------------------------------------------------------------------------------
# sphere / R-test (calibrate DMU50)
SPHERE = "sphere_example_DMU50.csv"


def test_sphere_rotary_axes_in_radians(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_rad.csv", scale(("B", "C"), RAD))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("B", "C"), ("radian",))


def test_sphere_tool_offset_wrong_sign(ex, tmp_path, capsys):
    def fn(d):
        d["Zp"] = -d["Zp"]
        return d
    f = mutate(ex / SPHERE, tmp_path / "sph_zp.csv", fn)
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("Zp",), ("sign",))


def test_sphere_centre_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_inch.csv",
               scale(("sphere_x", "sphere_y", "sphere_z"), 1.0 / INCH))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("sphere_x", "sphere_y", "sphere_z", "sphere"), ("inch",))


def test_sphere_x_and_y_columns_swapped(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_xy.csv", lambda d: d.rename(columns={"X": "Y", "Y": "X"}))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("X", "Y"), ("swap",))


def test_sphere_one_placement_centre_off_by_an_inch(ex, tmp_path, capsys):
    def fn(d):
        d.loc[d["placement"] == 2, "sphere_x"] += INCH
        return d
    f = mutate(ex / SPHERE, tmp_path / "sph_p2.csv", fn)
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("sphere_x", "sphere"), ("inch", "25.4"))


def test_sphere_deviations_in_nm(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_nm.csv", scale(("dx_um", "dy_um", "dz_um"), 1000.0))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("dx_um", "dy_um", "dz_um"), ("nm", "unit"))


def test_sphere_tool_offset_in_the_wrong_column(ex, tmp_path, capsys):
    """The 120 mm tool length typed into Xp instead of Zp."""
    def fn(d):
        d["Xp"], d["Zp"] = d["Zp"].copy(), d["Xp"].copy()
        return d
    f = mutate(ex / SPHERE, tmp_path / "sph_xp.csv", fn)
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("Xp", "Zp"), ("swap", "wrong column", "Xp", "Zp"))


def test_sphere_file_given_to_a_cmm_layout(ex, tmp_path, capsys):
    f = shutil.copy(ex / SPHERE, tmp_path / "sph.csv")
    refused(capsys, cal_argv("MB1", [f], tmp_path), outs_cal(tmp_path), "sph.csv",
            ("B", "C"), ("layout", "MB1", "DMU50", "rotary"))


def test_sphere_tool_length_in_metres(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_zp_m.csv", scale(("Zp",), 1.0 / 1000.0))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("Zp",), ("unit", " m", "metre", "tool"))


def test_sphere_rotary_column_stuck_constant(ex, tmp_path, capsys):
    """The export lost the B axis: every row says B = 0."""
    f = mutate(ex / SPHERE, tmp_path / "sph_b0.csv", lambda d: d.assign(B=0.0))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name, ("B",),
            ("constant", "B", "rotary", "stuck"))


def test_sphere_c_counted_from_zero_to_360_passes(ex, tmp_path, capsys):
    """C + 360 deg is the same table position: a correctly formed variant."""
    f = mutate(ex / SPHERE, tmp_path / "sph_c360.csv", lambda d: d.assign(C=d["C"] + 360.0))
    accepted(capsys, ["calibrate", "DMU50", f, "--json", tmp_path / "s.json"], [tmp_path / "s.json"])


def test_sphere_file_given_to_another_five_axis_layout(ex, tmp_path, capsys):
    """The DMU50's file (B/C table) given to a machine with a tilting A / rotary C table."""
    f = shutil.copy(ex / SPHERE, tmp_path / "sph.csv")
    refused(capsys, cal_argv("TT_AC", [f], tmp_path), outs_cal(tmp_path), "sph.csv",
            ("A", "B", "C"), ("layout", "TT_AC", "DMU50", "rotary", "axis", "column"))


def test_sphere_c_axis_sense_reversed(ex, tmp_path, capsys):
    """A controller whose C counts the other way: every C negated."""
    f = mutate(ex / SPHERE, tmp_path / "sph_cneg.csv", scale(("C",), -1.0))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name, ("C",),
            ("sign", "sense", "direction", "revers", "negat"))


# ---------------------------------------------------------------------------------------------
# tracking interferometer / multilateration distances (calibrate DMU50)
MULTI = "multilateration_DMU50.csv"


def test_multilateration_rotary_axes_in_radians(ex, tmp_path, capsys):
    f = mutate(ex / MULTI, tmp_path / "ml_rad.csv", scale(("B", "C"), RAD))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("B", "C"), ("radian",))


def test_multilateration_distances_in_um(ex, tmp_path, capsys):
    f = mutate(ex / MULTI, tmp_path / "ml_um.csv", scale(("dd_mm",), 1000.0))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("dd_mm",), ("um", "unit", "µm"))


def test_multilateration_tool_offset_wrong_sign(ex, tmp_path, capsys):
    def fn(d):
        d["Zp"] = -d["Zp"]
        return d
    f = mutate(ex / MULTI, tmp_path / "ml_zp.csv", fn)
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("Zp",), ("sign",))


def test_multilateration_file_given_to_a_cmm_layout(ex, tmp_path, capsys):
    f = shutil.copy(ex / MULTI, tmp_path / "ml.csv")
    refused(capsys, cal_argv("MB1", [f], tmp_path), outs_cal(tmp_path), "ml.csv",
            ("B", "C"), ("layout", "MB1", "DMU50", "rotary"))


def test_multilateration_b_and_c_columns_swapped(ex, tmp_path, capsys):
    f = mutate(ex / MULTI, tmp_path / "ml_bc.csv", lambda d: d.rename(columns={"B": "C", "C": "B"}))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name, ("B", "C"),
            ("swap", "travel"))


# ---------------------------------------------------------------------------------------------
# ballbar (ballbar evaluate; calibrate MB1)
BALLBAR = "ballbar_example_XY.csv"


def bb_outs(t):
    return [t / "bb.json", t / "bb.png", t / "bb.html"]


def bb_argv(f, t, *extra):
    o = bb_outs(t)
    return ["ballbar", "evaluate", f, "--json", o[0], "--plot", o[1], "--html", o[2], *extra]


def test_ballbar_diameter_for_the_length(ex, tmp_path, capsys):
    f = mutate(ex / BALLBAR, tmp_path / "bb_len.csv", scale(("length_mm",), 2.0))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name,
            ("length_mm",), ("diameter", "length", "pivot", "radius"))


def test_ballbar_length_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / BALLBAR, tmp_path / "bb_len_in.csv", scale(("length_mm",), 1.0 / INCH))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name, ("length_mm",), ("inch",))


def test_ballbar_readings_in_nm(ex, tmp_path, capsys):
    f = mutate(ex / BALLBAR, tmp_path / "bb_nm.csv", scale(("dr_um",), 1000.0))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name, ("dr_um",), ("nm", "unit"))


def test_ballbar_pivot_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / BALLBAR, tmp_path / "bb_inch.csv",
               scale(("pivot_x", "pivot_y", "pivot_z"), 1.0 / INCH))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name,
            ("pivot_x", "pivot_y", "pivot_z", "pivot"), ("inch",))


def test_ballbar_x_and_y_columns_swapped(ex, tmp_path, capsys):
    f = mutate(ex / BALLBAR, tmp_path / "bb_xy.csv", lambda d: d.rename(columns={"X": "Y", "Y": "X"}))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name, ("X", "Y"),
            ("swap", "pivot", "length"))


def test_ballbar_set_calibrated_with_one_trace_in_nm(ex, tmp_path, capsys):
    d = copy_dir(ex / "ballbar", tmp_path / "bb")
    mutate(ex / "ballbar" / "ballbar_YZ.csv", d / "ballbar_YZ.csv", scale(("dr_um",), 1000.0))
    files = [d / "ballbar_XY.csv", d / "ballbar_YZ.csv", d / "ballbar_ZX.csv"]
    refused(capsys, cal_argv("MB1", files, tmp_path), outs_cal(tmp_path), "ballbar_YZ.csv",
            ("dr_um",), ("nm", "unit"))


def test_ballbar_cmm_file_evaluated_on_the_dmu50(ex, tmp_path, capsys):
    """MB1's circle about X 450 mm given with --layout DMU50 (X travel about +-250 mm)."""
    f = shutil.copy(ex / BALLBAR, tmp_path / "bb.csv")
    refused(capsys, bb_argv(f, tmp_path, "--layout", "DMU50"), bb_outs(tmp_path), "bb.csv",
            ("X", "Y", "Z"), ("travel", "layout", "DMU50"))


# ---------------------------------------------------------------------------------------------
# ball plate / artifact (calibrate MB1)
PLATE = "ballplate_MB1.csv"
PLATE_EXTRA = ("--parameters", "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z", "--degree", "1")


def test_ballplate_centres_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / PLATE, tmp_path / "bp_inch.csv", scale(("x_mm", "y_mm", "z_mm"), 1.0 / INCH))
    refused(capsys, cal_argv("MB1", [f], tmp_path, *PLATE_EXTRA), outs_cal(tmp_path), f.name,
            ("x_mm", "y_mm", "z_mm"), ("inch",))


def test_ballplate_nominal_positions_in_inches(ex, tmp_path, capsys):
    """The plate's calibrated ball positions (u, v, w) typed from an inch certificate."""
    f = mutate(ex / PLATE, tmp_path / "bp_uvw.csv", scale(("u_mm", "v_mm", "w_mm"), 1.0 / INCH))
    refused(capsys, cal_argv("MB1", [f], tmp_path, *PLATE_EXTRA), outs_cal(tmp_path), f.name,
            ("u_mm", "v_mm", "w_mm"), ("inch", "unit"))


def test_ballplate_x_and_y_swapped(ex, tmp_path, capsys):
    f = mutate(ex / PLATE, tmp_path / "bp_xy.csv",
               lambda d: d.rename(columns={"x_mm": "y_mm", "y_mm": "x_mm"}))
    refused(capsys, cal_argv("MB1", [f], tmp_path, *PLATE_EXTRA), outs_cal(tmp_path), f.name,
            ("x_mm", "y_mm"), ("swap",))


def test_ballplate_one_ball_duplicated(ex, tmp_path, capsys):
    f = mutate(ex / PLATE, tmp_path / "bp_dup.csv",
               lambda d: pd.concat([d, d.iloc[[3]]], ignore_index=True))
    refused(capsys, cal_argv("MB1", [f], tmp_path, *PLATE_EXTRA), outs_cal(tmp_path), f.name,
            ("ball", "B04"), ("duplicate", "twice", "more than once"))


# ---------------------------------------------------------------------------------------------
# tracker files (identify)
TRACKER = "tracker_example_X.csv"


def id_outs(t):
    return [t / "id_errors", t / "id.json", t / "id.png"]


def id_argv(f, t, axis="X", layout="MB1"):
    o = id_outs(t)
    return ["identify", layout, "--axis", axis, f, "--errors-out", o[0], "--json", o[1],
            "--plot", o[2]]


def test_tracker_coordinates_in_metres(ex, tmp_path, capsys):
    f = mutate(ex / TRACKER, tmp_path / "tr_m.csv", scale(("x", "y", "z"), 1.0 / 1000.0))
    refused(capsys, id_argv(f, tmp_path), id_outs(tmp_path), f.name, ("x", "y", "z", "coordinates"),
            ("metre", " m,", " m ", "in m", "unit"))


def test_tracker_coordinates_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / TRACKER, tmp_path / "tr_in.csv", scale(("x", "y", "z"), 1.0 / INCH))
    refused(capsys, id_argv(f, tmp_path), id_outs(tmp_path), f.name, ("x", "y", "z", "coordinates"),
            ("inch",))


def test_tracker_positions_in_inches(ex, tmp_path, capsys):
    """The commanded positions typed in inches while the tracker reads mm."""
    f = mutate(ex / TRACKER, tmp_path / "tr_pos.csv", scale(("position",), 1.0 / INCH))
    refused(capsys, id_argv(f, tmp_path), id_outs(tmp_path), f.name, ("position",),
            ("inch", "unit"))


def test_tracker_file_of_another_axis(ex, tmp_path, capsys):
    """The Y axis' file given as --axis X."""
    f = shutil.copy(ex / "tracker_example_Y.csv", tmp_path / "tr_y.csv")
    refused(capsys, id_argv(f, tmp_path, axis="X"), id_outs(tmp_path), "tr_y.csv",
            ("position", "axis", "X"), ("axis", "direction", "Y"))


def test_tracker_rows_duplicated(ex, tmp_path, capsys):
    """A round exported twice into one file (the same round number again)."""
    f = mutate(ex / TRACKER, tmp_path / "tr_dup.csv",
               lambda d: pd.concat([d, d[d["round"] == 1]], ignore_index=True))
    refused(capsys, id_argv(f, tmp_path), id_outs(tmp_path), f.name, ("round", "point", "position"),
            ("duplicate", "twice", "more than once"))


def test_tracker_file_given_to_another_machine(ex, tmp_path, capsys):
    """MB1's X-axis file (positions 0 .. 650 mm) identified on the DMU50."""
    f = shutil.copy(ex / TRACKER, tmp_path / "tr.csv")
    refused(capsys, id_argv(f, tmp_path, layout="DMU50"), id_outs(tmp_path), "tr.csv",
            ("position", "X"), ("travel", "layout", "DMU50"))


def test_tracker_z_column_lost(ex, tmp_path, capsys):
    """A 2-D export: every z reads 0."""
    f = mutate(ex / TRACKER, tmp_path / "tr_z0.csv", lambda d: d.assign(z=0.0))
    refused(capsys, id_argv(f, tmp_path), id_outs(tmp_path), f.name, ("z",),
            ("constant", "zero", "0"))


# ---------------------------------------------------------------------------------------------
# probe calibration (probe-cal)
PROBE = "probe_sphere.csv"


def pc_outs(t):
    return [t / "probe_map.csv", t / "probe.json"]


def pc_argv(f, t, *extra):
    o = pc_outs(t)
    return ["probe-cal", f, "--out", o[0], "--json", o[1], *extra]


def test_probecal_sphere_diameter_for_the_radius(ex, tmp_path, capsys):
    f = shutil.copy(ex / PROBE, tmp_path / "ps.csv")
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", "50.012"), pc_outs(tmp_path),
            "--sphere-radius", (), ("diameter",))


def test_probecal_sphere_radius_in_um(ex, tmp_path, capsys):
    f = shutil.copy(ex / PROBE, tmp_path / "ps.csv")
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", "25006"), pc_outs(tmp_path),
            "--sphere-radius", (), ("um", "µm", "unit", "mm"))


def test_probecal_points_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / PROBE, tmp_path / "ps_in.csv", scale(("x", "y", "z"), 1.0 / INCH))
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", "25.006"), pc_outs(tmp_path),
            f.name, ("x", "y", "z"), ("inch",))


def test_probecal_sphere_radius_not_finite(ex, tmp_path, capsys):
    f = shutil.copy(ex / PROBE, tmp_path / "ps.csv")
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", "nan"), pc_outs(tmp_path),
            "--sphere-radius", (), ("finite", "nan", "number"))


def test_probecal_sphere_radius_in_inches(ex, tmp_path, capsys):
    f = shutil.copy(ex / PROBE, tmp_path / "ps.csv")
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", f"{25.006 / INCH:.5f}"),
            pc_outs(tmp_path), "--sphere-radius", (), ("inch", "unit", "mm"))


def test_probecal_stylus_ball_diameter_for_the_radius(ex, tmp_path, capsys):
    """The example's stylus ball is about 1 mm in radius (centre sphere ~26 mm about a 25.006 mm
    master); --ball-radius 2 is its diameter."""
    f = shutil.copy(ex / PROBE, tmp_path / "ps.csv")
    refused(capsys, pc_argv(f, tmp_path, "--sphere-radius", "25.006", "--ball-radius", "2"),
            pc_outs(tmp_path), "--ball-radius", (), ("diameter", "radius"))


# ---------------------------------------------------------------------------------------------
# measured deviations (loop MB1)
DEV = "deviations_MB1.csv"


def lp_outs(t):
    return [t / "loop.json", t / "loop_errors"]


def lp_argv(f, t, layout="MB1"):
    o = lp_outs(t)
    return ["loop", layout, f, "--json", o[0], "--errors-out", o[1]]


def test_deviations_in_nm(ex, tmp_path, capsys):
    f = mutate(ex / DEV, tmp_path / "dev_nm.csv", scale(("dx_um", "dy_um", "dz_um"), 1000.0))
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("dx_um", "dy_um", "dz_um"),
            ("nm", "unit"))


def test_deviations_temperature_in_fahrenheit(ex, tmp_path, capsys):
    def fn(d):
        d["T_C"] = d["T_C"] * 9.0 / 5.0 + 32.0
        return d
    f = mutate(ex / DEV, tmp_path / "dev_F.csv", fn)
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("T_C",), ("fahrenheit", "°F", "degF"))


def test_deviations_time_in_ms_labelled_seconds(ex, tmp_path, capsys):
    f = mutate(ex / DEV, tmp_path / "dev_ms.csv", scale(("t_s",), 1000.0))
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("t_s",), ("ms", "millisecond"))


def test_deviations_channel_overflowing(ex, tmp_path, capsys):
    def fn(d):
        d.loc[7, "dy_um"] = 1e300
        return d
    f = mutate(ex / DEV, tmp_path / "dev_big.csv", fn)
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("dy_um",),
            ("finite", "overflow", "1e+300", "1e300", "implausible", "large"))


def test_deviations_given_to_a_five_axis_layout(ex, tmp_path, capsys):
    f = shutil.copy(ex / DEV, tmp_path / "dev.csv")
    refused(capsys, lp_argv(f, tmp_path, layout="DMU50"), lp_outs(tmp_path), "dev.csv",
            ("B", "C", "X", "Y", "Z"), ("layout", "MB1", "DMU50", "travel", "rotary"))


# ---------------------------------------------------------------------------------------------
# laser-interferometer positioning runs (iso230-2)
RUN = "iso230_2_run_X.csv"


def pos_outs(t):
    return [t / "pos.json", t / "pos_tables", t / "pos.html"]


def pos_argv(f, t, *extra):
    o = pos_outs(t)
    return ["iso230-2", f, "--json", o[0], "--errors-out", o[1], "--html", o[2], *extra]


def test_positioning_deviations_in_nm(ex, tmp_path, capsys):
    f = mutate(ex / RUN, tmp_path / "run_nm.csv", scale(("deviation_um",), 1000.0))
    refused(capsys, pos_argv(f, tmp_path), pos_outs(tmp_path), f.name, ("deviation_um",),
            ("nm", "unit"))


@xfail("NOT refused: exit 0, pos.json, pos_tables/ and pos.html written: 'axis X, 9 targets x 5 "
       "cycles: A 9.41 ...' over a 31.5 mm 'travel' (inches read as mm); note: iso230-2 knows no"
       " machine travel, a plausibility check would need one (e.g. a --layout or --travel "
       "option)")
def test_positioning_targets_in_inches(ex, tmp_path, capsys):
    f = mutate(ex / RUN, tmp_path / "run_in.csv", scale(("target_mm",), 1.0 / INCH))
    refused(capsys, pos_argv(f, tmp_path), pos_outs(tmp_path), f.name, ("target_mm",),
            ("inch",))


def test_positioning_a_reading_duplicated(ex, tmp_path, capsys):
    f = mutate(ex / RUN, tmp_path / "run_dup.csv",
               lambda d: pd.concat([d, d.iloc[[5]]], ignore_index=True))
    refused(capsys, pos_argv(f, tmp_path), pos_outs(tmp_path), f.name,
            ("cycle", "direction", "target"), ("twice", "duplicate", "once", "more than"))


def test_positioning_deviation_column_all_zero(ex, tmp_path, capsys):
    """The interferometer recorded nothing: every deviation 0 (no repeatability is exactly 0)."""
    f = mutate(ex / RUN, tmp_path / "run_zero.csv", lambda d: d.assign(deviation_um=0.0))
    refused(capsys, pos_argv(f, tmp_path), pos_outs(tmp_path), f.name, ("deviation_um",),
            ("constant", "zero", "all 0"))


def test_positioning_date_in_the_future(ex, tmp_path, capsys):
    f = shutil.copy(ex / RUN, tmp_path / "run.csv")
    refused(capsys, pos_argv(f, tmp_path, "--date", "2099-01-01"), pos_outs(tmp_path),
            "--date", (), ("future", "after today", "today"))


def test_positioning_tolerance_in_mm_without_unit(ex, tmp_path, capsys):
    """A = 0.012 meant in mm, typed bare: the bare unit is um, 0.012 um is no tolerance of a
    machine tool (the positioning uncertainty alone is larger)."""
    f = shutil.copy(ex / RUN, tmp_path / "run.csv")
    refused(capsys, pos_argv(f, tmp_path, "--tolerance", "A=0.012"), pos_outs(tmp_path),
            "--tolerance", ("A",), ("mm", "unit"))


# ---------------------------------------------------------------------------------------------
# drift loggers (iso230-3, drift convert)
DRIFT = "drift_spindle.csv"
LOGGER = "drift_logger_raw.csv"


def dr_outs(t):
    return [t / "drift.json", t / "drift.html", t / "drift.png"]


def dr_argv(f, t, *extra):
    o = dr_outs(t)
    return ["iso230-3", f, "--json", o[0], "--html", o[1], "--plot", o[2], *extra]


def test_drift_time_in_ms_labelled_seconds(ex, tmp_path, capsys):
    f = mutate(ex / DRIFT, tmp_path / "drift_ms.csv", scale(("t_s",), 1000.0))
    refused(capsys, dr_argv(f, tmp_path), dr_outs(tmp_path), f.name, ("t_s",), ("ms", "millisecond"))


def test_drift_channel_holding_1e300(ex, tmp_path, capsys):
    def fn(d):
        d.loc[40, "d_x1_um"] = 1e300
        return d
    f = mutate(ex / DRIFT, tmp_path / "drift_big.csv", fn)
    refused(capsys, dr_argv(f, tmp_path), dr_outs(tmp_path), f.name, ("d_x1_um",),
            ("finite", "overflow", "1e+300", "1e300", "implausible", "large"))


def test_drift_temperature_in_fahrenheit(ex, tmp_path, capsys):
    def fn(d):
        for c in ("T_spindle", "T_motor", "T_room"):
            d[c] = d[c] * 9.0 / 5.0 + 32.0
        return d
    f = mutate(ex / DRIFT, tmp_path / "drift_F.csv", fn)
    refused(capsys, dr_argv(f, tmp_path), dr_outs(tmp_path), f.name,
            ("T_spindle", "T_motor", "T_room"), ("fahrenheit", "°F", "degF"))


def test_drift_time_going_backwards(ex, tmp_path, capsys):
    """Two readings exchanged (a logger's buffer flushed out of order)."""
    def fn(d):
        d.loc[[10, 11], "t_s"] = d.loc[[11, 10], "t_s"].to_numpy()
        return d
    f = mutate(ex / DRIFT, tmp_path / "drift_order.csv", fn)
    refused(capsys, dr_argv(f, tmp_path), dr_outs(tmp_path), f.name, ("t_s",),
            ("order", "increas", "backward", "decreas", "sorted"))


def test_drift_rows_duplicated(ex, tmp_path, capsys):
    """The logger's last block appended twice (the same times again)."""
    f = mutate(ex / DRIFT, tmp_path / "drift_dup.csv",
               lambda d: pd.concat([d, d.iloc[-20:]], ignore_index=True))
    refused(capsys, dr_argv(f, tmp_path), dr_outs(tmp_path), f.name, ("t_s",),
            ("duplicate", "twice", "order", "increas", "repeat"))


def test_drift_logger_channel_headed_mm_over_um(ex, tmp_path, capsys):
    """The logger's ch1 column headed (mm) over readings in um: drift convert multiplies by
    1000, a spindle drifting by millimetres."""
    f = mutate(ex / LOGGER, tmp_path / "raw_mm.csv",
               lambda d: d.rename(columns={"ch1(um)": "ch1(mm)"}))
    out = tmp_path / "conv.csv"
    refused(capsys, ["drift", "convert", f, "--out", out, "--channel", "ch1=X at z=20",
                     "--channel", "ch2=Z"], [out], f.name, ("ch1",), ("um", "unit", "µm"))


def test_drift_date_in_the_future(ex, tmp_path, capsys):
    f = shutil.copy(ex / DRIFT, tmp_path / "d.csv")
    refused(capsys, dr_argv(f, tmp_path, "--date", "2099-01-01"), dr_outs(tmp_path), "--date", (),
            ("future", "after today", "today"))


def test_drift_convert_channel_height_in_inches(ex, tmp_path, capsys):
    """'at z=0.8' meant in inches: the two heights of one direction then 0.8 and 120 ... the
    option with an inch unit must be refused or converted, never read as mm silently."""
    f = shutil.copy(ex / LOGGER, tmp_path / "raw.csv")
    out = tmp_path / "conv.csv"
    refused(capsys, ["drift", "convert", f, "--out", out, "--channel", "ch1=X at z=0.8in",
                     "--channel", "ch2=Z"], [out], "channel", ("ch1", "height", "z="), ("in", "unit", "mm"))


# ---------------------------------------------------------------------------------------------
# error tables (map, diagonals, compensate, controller, tcpmap)


def _rename_unit(d, old, new):
    return d.rename(columns={c: c.replace(old, new) for c in d.columns})


def test_map_translation_table_headed_mm_over_um(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "X.csv", e / "X.csv", lambda d: _rename_unit(d, "_um", "_mm"))
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "MB1", "--errors", e, "--out", out, "--json", tmp_path / "m.json"],
            [out, tmp_path / "m.json"], "X.csv", ("EXX_mm", "EYX_mm", "EZX_mm", "_mm"),
            ("um", "µm", "unit"))


def test_map_angular_table_headed_rad_over_urad(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "Y.csv", e / "Y.csv", lambda d: _rename_unit(d, "_urad", "_rad"))
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "MB1", "--errors", e, "--out", out], [out], "Y.csv",
            ("EAY_rad", "EBY_rad", "ECY_rad", "_rad"), ("urad", "µrad", "unit"))


def test_map_squareness_in_urad_declared_rad(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "constants.csv", e / "constants.csv",
           lambda d: d.assign(unit=d["unit"].replace("urad", "rad")))
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "MB1", "--errors", e, "--out", out], [out], "constants.csv",
            ("EC0Y", "EB0Z", "EA0Z", "unit"), ("urad", "µrad", "unit"))


def test_diagonals_table_in_nm_headed_um(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "Z.csv", e / "Z.csv", um_columns_in_nm)
    out = tmp_path / "diag.json"
    refused(capsys, ["diagonals", "MB1", "--errors", e, "--json", out], [out], "Z.csv",
            ("EZZ_um",), ("nm", "unit"))


def test_map_tables_of_another_machine(ex, tmp_path, capsys):
    """The DMU50's tables (X from -250 mm, rotary tables B and C) given to the CMM MB1."""
    e = copy_dir(ex / "dmu50" / "errors", tmp_path / "tables_dmu50")
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "MB1", "--errors", e, "--out", out], [out], "tables_dmu50",
            ("B.csv", "C.csv", "B", "C", "X"), ("layout", "MB1", "axis", "travel", "range"))


def test_compensate_tables_headed_mm_over_um(ex, tmp_path, capsys):
    e = copy_dir(ex / "dmu50" / "errors", tmp_path / "err")
    mutate(ex / "dmu50" / "errors" / "Z.csv", e / "Z.csv", lambda d: _rename_unit(d, "_um", "_mm"))
    out = tmp_path / "comp.nc"
    refused(capsys, ["compensate", "DMU50", "--errors", e, ex / "dmu50" / "hemisphere.nc",
                     "--out", out, "--json", tmp_path / "c.json"], [out, tmp_path / "c.json"],
            "Z.csv", ("EXZ_mm", "EYZ_mm", "EZZ_mm", "_mm"), ("um", "µm", "unit"))


def test_compensate_rotary_table_angles_in_radians(ex, tmp_path, capsys):
    """B.csv tabulated at radians (0, 0.157, ...) under a B column of degrees."""
    e = copy_dir(ex / "dmu50" / "errors", tmp_path / "err")
    def fn(d):
        d["B"] *= RAD
        return d
    mutate(ex / "dmu50" / "errors" / "B.csv", e / "B.csv", fn)
    out = tmp_path / "comp.nc"
    refused(capsys, ["compensate", "DMU50", "--errors", e, ex / "dmu50" / "hemisphere.nc",
                     "--out", out], [out], "B.csv", ("B",), ("radian",))


def test_compensate_negative_tool_length(ex, tmp_path, capsys):
    e = ex / "dmu50" / "errors"
    out = tmp_path / "comp.nc"
    refused(capsys, ["compensate", "DMU50", "--errors", e, ex / "dmu50" / "hemisphere.nc",
                     "--out", out, "--tool-length", "-85"], [out], "tool length", (),
            ("sign", "negative", "positive", ">= 0"))


def test_compensate_datum_in_um_outside_travel(ex, tmp_path, capsys):
    """A datum of 30, 20, 20 mm typed in um (30000, 20000, 20000): outside the travel."""
    e = ex / "dmu50" / "errors"
    out = tmp_path / "comp.nc"
    refused(capsys, ["compensate", "DMU50", "--errors", e, ex / "dmu50" / "hemisphere.nc",
                     "--out", out, "--datum", "30000,20000,20000"], [out], "--datum", (),
            ("travel", "um", "unit", "outside"))


def test_controller_export_of_tables_in_nm(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "X.csv", e / "X.csv", um_columns_in_nm)
    out = tmp_path / "ctl"
    code, o, err, _ = run(capsys, ["controller", "export", "--help"])
    fmt = re.search(r"--format \{([a-z0-9_,-]+)\}", o)
    argv = ["controller", "export", "MB1", "--errors", e, "--out", out]
    if fmt:
        argv += ["--format", fmt.group(1).split(",")[0]]
    refused(capsys, argv, [out], "X.csv", ("EXX_um", "EYX_um", "EZX_um"), ("nm", "unit"))


def test_tcpmap_angular_table_headed_rad(ex, tmp_path, capsys):
    e = copy_dir(ex / "dmu50" / "errors", tmp_path / "err")
    mutate(ex / "dmu50" / "errors" / "C.csv", e / "C.csv", lambda d: _rename_unit(d, "_urad", "_rad"))
    out = tmp_path / "tcp.png"
    refused(capsys, ["tcpmap", "DMU50", "--errors", e, "--point", "30", "20", "60", "--plot", out,
                     "--steps", "9"], [out], "C.csv", ("EAC_rad", "EBC_rad", "ECC_rad", "_rad"),
            ("urad", "µrad", "unit"))


def test_uncertainty_tables_in_nm(ex, tmp_path, capsys):
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    mutate(ex / "errors_MB1" / "Y.csv", e / "Y.csv", um_columns_in_nm)
    out = tmp_path / "u.json"
    refused(capsys, ["uncertainty", "MB1", "--task", ex / "task_distance.csv", "--evaluate",
                     "distance", "--errors", e, "--samples", "200", "--json", out, "--quiet"],
            [out], "Y.csv", ("EYY_um", "EXY_um", "EZY_um", "EYY_s_um"), ("nm", "unit"))


def test_map_probe_offset_in_um(ex, tmp_path, capsys):
    """--probe 0 0 -100000 (100 mm typed in um): a stylus 100 m long."""
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "MB1", "--errors", ex / "errors_MB1", "--probe", "0", "0", "-100000",
                     "--out", out], [out], "--probe", (), ("um", "unit", "mm", "long", "large"))


def test_map_rotary_position_outside_travel(ex, tmp_path, capsys):
    """--at B=1.5708 is a legitimate angle; --at B=-500 is beyond any tilting table."""
    out = tmp_path / "map.csv"
    refused(capsys, ["map", "DMU50", "--errors", ex / "dmu50" / "errors", "--at", "B=-500",
                     "--out", out], [out], "--at", ("B",), ("travel", "outside", "range"))


# ---------------------------------------------------------------------------------------------
# mistakes no geometry or magnitude check can see: only the fit's residual (chi^2 per degree of
# freedom against the declared reading uncertainty, issue 43 item 3) or the trace itself tells


def test_sphere_dy_and_dz_columns_swapped(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "sph_dyz.csv",
               lambda d: d.rename(columns={"dy_um": "dz_um", "dz_um": "dy_um"}))
    refused(capsys, cal_argv("DMU50", [f], tmp_path), outs_cal(tmp_path), f.name,
            ("dy_um", "dz_um", "residual"), ("swap", "residual", "chi"))


@xfail("NOT refused: exit 0, loop.json and loop_errors/ written; held-out RMS 9.827 -> 1.966 um "
       "(shipped file: 9.540 -> 0.540 um), 'effects found: thermal (thermal_X)'; the residual "
       "stays ~4x the example's -- for the chi^2 residual gate (other branch)")
def test_deviations_probe_offsets_with_the_wrong_sign(ex, tmp_path, capsys):
    """Xp and Yp of the side styli negated (the stylus at +80 written -80)."""
    f = mutate(ex / DEV, tmp_path / "dev_sign.csv", lambda d: d.assign(Xp=-d["Xp"], Yp=-d["Yp"]))
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("Xp", "Yp"),
            ("sign", "residual", "chi"))


@xfail("NOT refused: exit 0, loop.json and loop_errors/ written; held-out RMS 9.857 -> 1.546 um "
       "and invented effects 'thermal_EC0Y_T_C, drift warmup_probe_Xp_t_s, warmup_probe_Yp_t_s' "
       "-- for the chi^2 residual gate (other branch)")
def test_deviations_dx_and_dy_columns_swapped(ex, tmp_path, capsys):
    f = mutate(ex / DEV, tmp_path / "dev_xy.csv",
               lambda d: d.rename(columns={"dx_um": "dy_um", "dy_um": "dx_um"}))
    refused(capsys, lp_argv(f, tmp_path), lp_outs(tmp_path), f.name, ("dx_um", "dy_um"),
            ("swap", "residual", "chi"))


def test_ballbar_direction_column_inverted(ex, tmp_path, capsys):
    """direction +1/-1 exchanged: the positions run counter-clockwise where the column says
    clockwise (the sense of the trace is in the X, Y sequence itself)."""
    f = mutate(ex / BALLBAR, tmp_path / "bb_dir.csv", lambda d: d.assign(direction=-d["direction"]))
    refused(capsys, bb_argv(f, tmp_path), bb_outs(tmp_path), f.name, ("direction",),
            ("sense", "clockwise", "cw", "invert", "swap"))


# ---------------------------------------------------------------------------------------------
# options with units and dates on check and history


@pytest.fixture(scope="module")
def reference(ex, tmp_path_factory):
    d = tmp_path_factory.mktemp("ref")
    assert main(["calibrate", "DMU50", str(ex / SPHERE), "--json", str(d / "cal.json")]) == 0
    return d / "cal.json"


def test_check_dated_in_the_future(ex, reference, tmp_path, capsys):
    out = tmp_path / "check.json"
    refused(capsys, ["check", "DMU50", "--reference", reference, ex / SPHERE, "--date",
                     "2099-01-01", "--json", out], [out], "--date", (),
            ("future", "after today", "today"))


def test_check_tolerance_typed_in_mm_for_um(
        ex, reference, tmp_path, capsys):
    """--tolerance EX0C=22 mm (a typo of um) is a 22 mm tolerance: no machine parameter of a
    five-axis machine is judged against 22 mm; the line must name the option."""
    out = tmp_path / "check.json"
    params = json.loads(reference.read_text())
    text = json.dumps(params)
    name = next(n for n in ("EX0B", "EX0C", "EY0B", "EY0C") if n in text)
    refused(capsys, ["check", "DMU50", "--reference", reference, ex / SPHERE, "--tolerance",
                     f"{name}=22 mm", "--json", out], [out], "--tolerance", (name,),
            ("um", "implausible", "unit", "large"))


def test_check_tolerance_without_unit(ex, reference, tmp_path, capsys):
    """Issue 43 item 5: every option value with a unit needs it (as history show refuses
    EX0C=22)."""
    out = tmp_path / "check.json"
    name = next(n for n in ("EX0B", "EX0C", "EY0B", "EY0C") if n in reference.read_text())
    refused(capsys, ["check", "DMU50", "--reference", reference, ex / SPHERE, "--tolerance",
                     f"{name}=22", "--json", out], [out], "--tolerance", (name,), ("unit", "um"))


def test_history_show_tolerance_without_unit(reference, tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    assert main(["history", "add", "--db", str(db), "--machine", "A", str(reference)]) == 0
    refused(capsys, ["history", "show", "--db", db, "--machine", "A", "--tolerance",
                     "EX0C=22"], [], "--tolerance", ("EX0C",), ("unit", "um"))


def test_history_add_dated_in_the_future(reference, tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    refused(capsys, ["history", "add", "--db", db, "--machine", "A", "--date", "2099-01-01",
                     reference], [db], "--date", (), ("future", "after today", "today"))


def test_check_with_rotary_axes_in_radians(ex, reference, tmp_path, capsys):
    """The interim check's sphere file exported in radians: the geometry check must hold in
    check as in calibrate."""
    f = mutate(ex / SPHERE, tmp_path / "chk_rad.csv", scale(("B", "C"), RAD))
    out = tmp_path / "check.json"
    refused(capsys, ["check", "DMU50", "--reference", reference, f, "--json", out], [out],
            f.name, ("B", "C"), ("radian",))


def test_check_with_a_file_of_another_machine(ex, reference, tmp_path, capsys):
    f = shutil.copy(ex / BALLBAR, tmp_path / "chk_bb.csv")
    out = tmp_path / "check.json"
    refused(capsys, ["check", "DMU50", "--reference", reference, f, "--json", out], [out],
            "chk_bb.csv", ("X", "Y", "Z", "pivot"), ("travel", "layout", "DMU50", "MB1"))


def test_loop_with_a_sphere_file_in_radians(ex, tmp_path, capsys):
    f = mutate(ex / SPHERE, tmp_path / "lp_rad.csv", scale(("B", "C"), RAD))
    refused(capsys, lp_argv(f, tmp_path, layout="DMU50"), lp_outs(tmp_path), f.name, ("B", "C"),
            ("radian",))


def test_compensate_tool_offset_with_the_wrong_sign(ex, tmp_path, capsys):
    """--tool 0 0 85 for an 85 mm tool: the documented offset is 0 0 -L (the tip below the
    spindle nose); +85 puts the tip inside the spindle."""
    out = tmp_path / "comp.nc"
    refused(capsys, ["compensate", "DMU50", "--errors", ex / "dmu50" / "errors",
                     ex / "dmu50" / "hemisphere.nc", "--out", out, "--tool", "0", "0", "85"],
            [out], "--tool", (), ("sign", "-85", "0 0 -L", "negative"))


def test_positioning_material_temperature_in_fahrenheit(ex, tmp_path, capsys):
    f = shutil.copy(ex / RUN, tmp_path / "run.csv")
    refused(capsys, pos_argv(f, tmp_path, "--cte-ppm-per-K", "11.5", "--material-temp-C", "68"),
            pos_outs(tmp_path), "--material-temp-C", (), ("fahrenheit", "°F", "degF", "implausible"))


def test_positioning_expansion_coefficient_in_per_kelvin(ex, tmp_path, capsys):
    """11.5e-6 (1/K) typed where ppm/K is asked: a correction a million times too small."""
    f = shutil.copy(ex / RUN, tmp_path / "run.csv")
    refused(capsys, pos_argv(f, tmp_path, "--cte-ppm-per-K", "11.5e-6", "--material-temp-C",
                             "23"), pos_outs(tmp_path), "--cte-ppm-per-K", (),
            ("ppm", "1/K", "unit"))


def test_uncertainty_part_expansion_in_ppm(ex, tmp_path, capsys):
    """--part-cte 11.5 1 (ppm/K typed where 1/K is asked): a part growing 1150 % per kelvin."""
    out = tmp_path / "u.json"
    refused(capsys, ["uncertainty", "MB1", "--task", ex / "task_distance.csv", "--evaluate",
                     "distance", "--errors", ex / "errors_MB1", "--samples", "200", "--quiet",
                     "--part-cte", "11.5", "1", "--part-dt", "1", "0.2", "--json", out], [out],
            "--part-cte", (), ("ppm", "1/K", "unit", "1e-6"))


def test_identify_tracker_position_in_metres(ex, tmp_path, capsys):
    """--tracker 1.5 -2 0.3 (m typed for mm): the tracker 144 mm from the nearest point."""
    f = shutil.copy(ex / TRACKER, tmp_path / "tr.csv")
    refused(capsys, id_argv(f, tmp_path) + ["--tracker", "1.5", "-2", "0.3"], id_outs(tmp_path),
            "--tracker", (), ("m", "unit", "metre", "close"))


def test_iso10360_mpe_constant_in_mm(ex, tmp_path, capsys):
    """--mpe 'E0=0.002+L/300': the 2 um constant typed in mm; 0.002 um is no CMM's MPE."""
    out = [tmp_path / "e0.json", tmp_path / "e0.html"]
    refused(capsys, ["iso10360", "MB1", "--errors", ex / "errors_MB1", "--mpe", "E0=0.002+L/300",
                     "--json", out[0], "--html", out[1]], out, "--mpe", (), ("mm", "unit", "um"))


def _race(db, jobs):
    """Start ``volerr history add`` for every (machine, result) of ``jobs`` at once; their
    (exit code, stdout + stderr)."""
    procs = [subprocess.Popen([sys.executable, "-m", "volerr", "history", "add", "--db", str(db),
                               "--machine", m, str(r)], stdout=subprocess.PIPE,
                              stderr=subprocess.STDOUT, text=True) for m, r in jobs]
    return [(p.wait(timeout=120), p.stdout.read()) for p in procs]


def _entries(capsys, db, machine, tmp_path):
    out = tmp_path / f"show_{machine}.json"
    code, _, err, _ = run(capsys, ["history", "show", "--db", db, "--machine", machine,
                                   "--json", out])
    assert code == 0, err
    return json.loads(out.read_text())["entries"]


@pytest.mark.parametrize("round_", [0, 1])
def test_history_race_same_result_on_two_machines_loses_nothing(reference, tmp_path, capsys,
                                                                round_):
    """The issue's case: the same result added to A and B of a NEW database at once.  One
    result is one machine at one time: exactly one may say added, and that entry must be in
    the database afterwards (the file must exist)."""
    db = tmp_path / f"race{round_}.sqlite"
    said = _race(db, [("A", reference), ("B", reference)])
    added = [m for (code, text), m in zip(said, "AB") if code == 0 and "added" in text]
    assert len(added) == 1, said
    assert db.exists(), f"database gone after {said}"
    assert len(_entries(capsys, db, added[0], tmp_path)) == 1, said


# ---------------------------------------------------------------------------------------------
# false alarms: correct files must pass


def test_every_shipped_example_runs(ex, tmp_path, capsys):
    """The commands of the examples' README, with outputs, exit 0."""
    t = tmp_path
    cases = [
        (["identify", "MB1", "--axis", "X", ex / TRACKER, "--errors-out", t / "tx"], [t / "tx"]),
        (["calibrate", "DMU50", ex / SPHERE, "--json", t / "s.json", "--errors-out", t / "se"],
         [t / "s.json", t / "se"]),
        (["ballbar", "evaluate", ex / BALLBAR, "--json", t / "b.json"], [t / "b.json"]),
        (["map", "MB1", "--errors", ex / "errors_MB1", "--out", t / "m.csv"], [t / "m.csv"]),
        (["calibrate", "MB1", ex / PLATE, *PLATE_EXTRA, "--json", t / "p.json"], [t / "p.json"]),
        (["calibrate", "DMU50", ex / MULTI, "--json", t / "ml.json"], [t / "ml.json"]),
        (["probe-cal", ex / PROBE, "--sphere-radius", "25.006", "--out", t / "pm.csv"],
         [t / "pm.csv"]),
        (["iso230-2", ex / RUN, "--json", t / "r.json"], [t / "r.json"]),
        (["iso230-3", ex / DRIFT, "--json", t / "d.json"], [t / "d.json"]),
        (["compensate", "DMU50", "--errors", ex / "dmu50" / "errors", ex / "dmu50" / "hemisphere.nc",
          "--out", t / "h.nc"], [t / "h.nc"]),
        (["diagonals", "MB1", "--errors", ex / "errors_MB1", "--json", t / "dg.json"],
         [t / "dg.json"]),
    ]
    for argv, outs in cases:
        accepted(capsys, argv, outs)


def test_ballbar_at_another_radius_passes(ex, tmp_path, capsys):
    """The example's circle shrunk consistently to a 100 mm bar about the same pivot."""
    def fn(d):
        k = 100.0 / 150.0
        d["X"] = d["pivot_x"] + (d["X"] - d["pivot_x"]) * k
        d["Y"] = d["pivot_y"] + (d["Y"] - d["pivot_y"]) * k
        d["length_mm"] = 100.0
        return d
    f = mutate(ex / BALLBAR, tmp_path / "bb100.csv", fn)
    accepted(capsys, ["ballbar", "evaluate", f, "--json", tmp_path / "b.json"], [tmp_path / "b.json"])


def test_ballbar_pivot_moved_consistently_passes(ex, tmp_path, capsys):
    def fn(d):
        for a, c in (("X", "pivot_x"), ("Y", "pivot_y")):
            d[a] -= 100.0
            d[c] -= 100.0
        return d
    f = mutate(ex / BALLBAR, tmp_path / "bbmv.csv", fn)
    accepted(capsys, ["ballbar", "evaluate", f, "--json", tmp_path / "b.json"], [tmp_path / "b.json"])


def test_simulated_sphere_and_ballbar_campaigns_pass(tmp_path, capsys):
    sph, bb = tmp_path / "sph.csv", tmp_path / "bb.csv"
    assert main(["simulate", "DMU50", "--instrument", "sphere", "--seed", "3", "--out", str(sph)]) == 0
    assert main(["simulate", "MB1", "--instrument", "ballbar", "--radius", "80", "--seed", "3",
                 "--out", str(bb)]) == 0
    accepted(capsys, ["calibrate", "DMU50", sph, "--errors-out", tmp_path / "e1"], [tmp_path / "e1"])
    accepted(capsys, ["calibrate", "MB1", bb, "--errors-out", tmp_path / "e2"], [tmp_path / "e2"])


def test_noisy_and_shuffled_sphere_file_passes(ex, tmp_path, capsys):
    rng = np.random.default_rng(43)
    def fn(d):
        for c in ("dx_um", "dy_um", "dz_um"):
            d[c] += rng.normal(0.0, 0.5, len(d))
        return d.sample(frac=1.0, random_state=43).reset_index(drop=True)
    f = mutate(ex / SPHERE, tmp_path / "sph_noisy.csv", fn)
    accepted(capsys, ["calibrate", "DMU50", f, "--errors-out", tmp_path / "e"], [tmp_path / "e"])


def test_sphere_placement_numbers_renamed_passes(ex, tmp_path, capsys):
    def fn(d):
        d["placement"] = d["placement"].map({1: 7, 2: 3})
        return d
    f = mutate(ex / SPHERE, tmp_path / "sph_pl.csv", fn)
    accepted(capsys, ["calibrate", "DMU50", f, "--json", tmp_path / "s.json"], [tmp_path / "s.json"])


def test_tracker_rows_shuffled_and_noisy_passes(ex, tmp_path, capsys):
    rng = np.random.default_rng(7)
    def fn(d):
        for c in ("x", "y", "z"):
            d[c] += rng.normal(0.0, 0.001, len(d))
        return d.sample(frac=1.0, random_state=7).reset_index(drop=True)
    f = mutate(ex / TRACKER, tmp_path / "tr.csv", fn)
    accepted(capsys, ["identify", "MB1", "--axis", "X", f, "--errors-out", tmp_path / "e"],
             [tmp_path / "e"])


def test_positioning_run_in_mm_column_passes(ex, tmp_path, capsys):
    """deviation_mm is a documented header: the same run in mm gives the same A."""
    def fn(d):
        return d.assign(deviation_um=d["deviation_um"] / 1000.0).rename(
            columns={"deviation_um": "deviation_mm"})
    f = mutate(ex / RUN, tmp_path / "run_mm.csv", fn)
    accepted(capsys, ["iso230-2", ex / RUN, "--json", tmp_path / "a.json"], [tmp_path / "a.json"])
    accepted(capsys, ["iso230-2", f, "--json", tmp_path / "b.json"], [tmp_path / "b.json"])
    a = json.loads((tmp_path / "a.json").read_text())["A_um"]
    b = json.loads((tmp_path / "b.json").read_text())["A_um"]
    assert abs(a - b) < 1e-3


def test_compensate_tool_length_is_used(ex, tmp_path, capsys):
    """--tool-length 85 on a program without TCPM: the output differs from no tool length
    (the tip 85 mm from the spindle sees other angular errors)."""
    e, prog = ex / "dmu50" / "errors", ex / "dmu50" / "hemisphere.nc"
    accepted(capsys, ["compensate", "DMU50", "--errors", e, prog, "--out", tmp_path / "a.nc"],
             [tmp_path / "a.nc"])
    accepted(capsys, ["compensate", "DMU50", "--errors", e, prog, "--out", tmp_path / "b.nc",
                      "--tool-length", "85"], [tmp_path / "b.nc"])
    assert (tmp_path / "a.nc").read_text() != (tmp_path / "b.nc").read_text()


def test_tables_in_mm_and_rad_correctly_headed_give_the_same_map(ex, tmp_path, capsys):
    """X.csv converted to mm (values / 1000 under _mm headers) and the constants to rad
    (values x 1e-6, unit rad): the same map as the shipped um / urad tables."""
    e = copy_dir(ex / "errors_MB1", tmp_path / "err")
    def to_mm(d):
        cols = [c for c in d.columns if c.endswith("_um")]
        return _rename_unit(scale(cols, 1e-3)(d), "_um", "_mm")
    mutate(ex / "errors_MB1" / "X.csv", e / "X.csv", to_mm)
    mutate(ex / "errors_MB1" / "constants.csv", e / "constants.csv",
           lambda d: d.assign(value=d["value"] * 1e-6, unit="rad"))
    a, b = tmp_path / "a.csv", tmp_path / "b.csv"
    accepted(capsys, ["map", "MB1", "--errors", ex / "errors_MB1", "--out", a], [a])
    accepted(capsys, ["map", "MB1", "--errors", e, "--out", b], [b])
    ma, mb = pd.read_csv(a), pd.read_csv(b)
    assert list(ma.columns) == list(mb.columns)
    assert np.allclose(ma.to_numpy(float), mb.to_numpy(float), atol=2e-3)


def test_ballplate_rows_shuffled_passes(ex, tmp_path, capsys):
    f = mutate(ex / PLATE, tmp_path / "bp_shuffled.csv",
               lambda d: d.sample(frac=1.0, random_state=11).reset_index(drop=True))
    accepted(capsys, ["calibrate", "MB1", f, *PLATE_EXTRA, "--json", tmp_path / "p.json"],
             [tmp_path / "p.json"])


def test_noisy_ballbar_trace_passes(ex, tmp_path, capsys):
    rng = np.random.default_rng(5)
    f = mutate(ex / BALLBAR, tmp_path / "bb_noisy.csv",
               lambda d: d.assign(dr_um=d["dr_um"] + rng.normal(0.0, 0.5, len(d))))
    accepted(capsys, ["ballbar", "evaluate", f, "--json", tmp_path / "b.json"], [tmp_path / "b.json"])

