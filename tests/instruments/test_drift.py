"""The ``drift`` instrument (issue 35 item 1): the reader, its rows of the layout's model, the
logger mapping and ``volerr drift convert``, the refusals (one line, exit 2, nothing written).

The rows are checked against physics, not against the reader's own arithmetic: a pure
translation error of the tool moves every sensor of one direction alike, a tilt of the tool
moves two sensors at two heights by the angle times their height difference."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from volerr.cli import main
from volerr.errors import InputError
from volerr.instruments import detect, drift, read
from volerr.machine import load

FL = Path("/work/shared/data/thermal/fl_thermal_spindle.csv")
if not FL.is_file():
    FL = Path(__file__).resolve().parents[3] / "shared" / "data" / "thermal" / FL.name


@pytest.fixture(scope="module")
def dmu():
    return load("DMU50")


def _write(path: Path, header: str, rows, comments=()) -> Path:
    lines = list(comments) + [header] + [",".join(str(v) for v in r) for r in rows]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path


def _good_rows(n=40, seed=1):
    rng = np.random.default_rng(seed)
    t = np.arange(n) * 15.0
    return [(f"{t[i]:g}", f"{rng.normal():.4f}", f"{rng.normal():.4f}", f"{rng.normal():.4f}",
             f"{20 + 0.01 * i + rng.normal(0, 0.01):.4f}", 1000 if i > 5 else 0)
            for i in range(n)]


GOOD_HEADER = "t_s,d_x1_um,d_x2_um,d_ax_um,T_spindle,S_rpm"
GOOD_COMMENTS = ("# channel d_x1: X at z=20", "# channel d_x2: X at z=120", "# channel ax: ?")


def test_real_file_reads():
    if not FL.is_file():
        pytest.skip(f"{FL} not present")
    assert detect(FL) == "drift"
    runs = drift.read_runs(FL)
    assert len(runs) == 1
    r = runs[0]
    assert r.n == 11115 and r.t_s[0] == 0 and r.t_s[-1] == 166710
    assert list(r.channels) == [f"ch{i}" for i in range(1, 6)]
    assert set(r.directions.values()) == {"?"}
    assert sorted(k for k in r.inputs if k.startswith("T_")) == sorted(
        f"T_{i}" for i in range(1, 17))
    assert "S_rpm" in r.inputs and set(np.unique(r.inputs["S_rpm"])) >= {0, 1250, 5000}


def test_rows_of_the_model(tmp_path, dmu):
    f = _write(tmp_path / "run.csv", GOOD_HEADER, _good_rows(), GOOD_COMMENTS)
    assert detect(f) == "drift"
    obs = read(f, dmu)
    n = 40
    assert obs.n == 3 * n and obs.n_readings == 3 * n
    assert list(obs.info["channel"][::n]) == ["x1", "x2", "ax"]
    # readings in mm, in channel order
    raw = np.array([[float(v) for v in r[1:4]] for r in _good_rows()])
    np.testing.assert_allclose(obs.deviation[:, 0], raw.T.ravel() * 1e-3)
    sens = obs.sensitivity(dmu)[:, 0, :]            # (N, parameters) mm/mm | mm/rad
    x1, x2, ax = sens[:n], sens[n:2 * n], sens[2 * n:]
    assert np.all(ax == 0)                            # '?': no row of the model
    names = list(dmu.parameters)
    # a translation of the tool along X moves both X sensors alike, by 1 mm/mm
    i = names.index("EXX")
    assert abs(x1[0, i]) == pytest.approx(1.0) and x2[0, i] == pytest.approx(x1[0, i])
    # every parameter: the two heights differ by 100 mm times a rotation about Y, so the
    # difference / 100 is 0 (a translation) or a rotation's unit effect (+-1, or a cosine)
    diff = (x2[0] - x1[0]) / 100.0
    assert np.all(np.abs(diff) <= 1 + 1e-9)
    j = names.index("EBZ")                            # Z axis' rotation about Y
    assert abs(diff[j]) == pytest.approx(1.0)
    assert diff[names.index("EXZ")] == pytest.approx(0.0, abs=1e-12)
    # each channel's zero is its own set-up unknown
    assert obs.setup_labels == ["run.csv:x1.zero", "run.csv:x2.zero", "run.csv:ax.zero"]
    assert set(obs.covariates) == {"T_spindle", "S_rpm", "t_s"}


def test_direction_sign_and_runs(tmp_path, dmu):
    rows = _good_rows(40)
    rows = [r + ("a" if k < 20 else "b",) for k, r in enumerate(rows)]
    f = _write(tmp_path / "two.csv", GOOD_HEADER + ",run", rows,
               ("# channel d_x1: -X", "# channel d_x2: X"))
    obs = read(f, dmu)
    s = obs.sensitivity(dmu)[:, 0, list(dmu.parameters).index("EXX")]
    assert s[0] == pytest.approx(-s[20])              # -X reads the opposite sign of X
    assert [fi.name for fi in obs.files] == ["two.csv[a]", "two.csv[b]"]
    assert len(obs.setup_labels) == 6                 # a zero per channel per run
    runs = drift.read_runs(f)
    assert [r.run for r in runs] == ["a", "b"] and runs[1].t_s[0] == 300.0


BAD = {
    "time goes back": (GOOD_HEADER, lambda r: r[:5] + [("10",) + r[5][1:]] + r[6:],
                       "time goes back at row 7"),
    "duplicated": (GOOD_HEADER, lambda r: r[:5] + [(r[4][0],) + r[5][1:]] + r[6:],
                   "row 7 repeats the time of row 6"),
    "empty channel": (GOOD_HEADER, lambda r: [x[:1] + ("",) + x[2:] for x in r],
                      "column d_x1_um is empty"),
    "nan": (GOOD_HEADER, lambda r: r[:3] + [r[3][:2] + ("nan",) + r[3][3:]] + r[4:],
            "column d_x2_um row 5 is NaN"),
    "blank cell": (GOOD_HEADER, lambda r: r[:3] + [r[3][:2] + ("",) + r[3][3:]] + r[4:],
                   "column d_x2_um row 5 is empty"),
    "constant sensor": (GOOD_HEADER, lambda r: [x[:3] + ("0.5",) + x[4:] for x in r],
                        "d_ax_um is constant"),
    "constant temperature": (GOOD_HEADER, lambda r: [x[:4] + ("21",) + x[5:] for x in r],
                             "T_spindle is constant"),
    "no channel": ("t_s,a,b,c,T_spindle,S_rpm", lambda r: r, "no displacement channel"),
    "no time": ("time_x,d_x1_um,d_x2_um,d_ax_um,T_spindle,S_rpm", lambda r: r, "no time column"),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_files_one_line(tmp_path, dmu, case, capsys):
    header, edit, message = BAD[case]
    f = _write(tmp_path / "bad.csv", header, edit(_good_rows()), GOOD_COMMENTS[:2])
    with pytest.raises(InputError) as exc:
        read(f"drift:{f}", dmu)
    assert message in str(exc.value) and "\n" not in str(exc.value)
    out = tmp_path / "out.csv"
    assert main(["drift", "convert", str(f), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err and not out.exists()


def test_unknown_direction(tmp_path, dmu):
    f = _write(tmp_path / "bad.csv", GOOD_HEADER, _good_rows(), ("# channel d_x1: sideways",))
    with pytest.raises(InputError, match="direction 'sideways' is not one of X Y Z"):
        read(f, dmu)
    f = _write(tmp_path / "bad2.csv", GOOD_HEADER, _good_rows(), ("# channel d_q: X",))
    with pytest.raises(InputError, match="header line for channel d_q but no column"):
        read(f, dmu)


def test_logger_file_read_and_converted(tmp_path, dmu, capsys):
    # ch3 logged in mm: a drift of micrometres (0.001 mm), as a real mm channel reads (issue
    # 43: a (mm) channel drifting by millimetres is refused as um under a (mm) header)
    rows = [r[:3] + (f"{float(r[3]) / 1000:.7f}",) + r[4:] for r in _good_rows()]
    raw_rows = [(f"{float(r[0]) / 60:g}",) + r[1:] + ("ok",) for r in rows]
    raw = _write(tmp_path / "logger.csv", "Time(min),ch1(um),ch2(µm),ch3(mm),t1(°C),"
                 "spindle(RPM),comment", raw_rows)
    runs = drift.read_runs(raw)                       # read as saved (the mapping)
    r = runs[0]
    assert list(r.channels) == ["ch1", "ch2"] or "ch3" in r.channels
    np.testing.assert_allclose(r.t_s, [float(x[0]) for x in rows], rtol=1e-12)
    assert set(r.inputs) == {"T_1", "S_rpm"}
    out = tmp_path / "drift.csv"
    assert main(["drift", "convert", str(raw), "--out", str(out), "--channel",
                 "ch1=X at z=50", "--channel", "ch2=?"]) == 0
    text = out.read_text(encoding="utf-8")
    assert "# channel d_ch1: X at z=50" in text
    assert text.splitlines()[3] == "t_s,d_ch1_um,d_ch2_um,d_ch3_um,T_1,S_rpm,comment"
    back = drift.read_runs(out)[0]
    np.testing.assert_allclose(back.t_s, r.t_s, rtol=1e-12)
    np.testing.assert_allclose(back.channels["ch3"], [float(x[3]) * 1000 for x in rows])
    assert back.directions == {"ch1": "X", "ch2": "?", "ch3": "?"} and back.heights["ch1"] == 50


def test_logger_mapping_rules():
    from volerr.instruments._drift_logger import drift_name, map_header

    assert [drift_name(c, "f") for c in ("時間(s)", "Time [min]", "Zeit(h)", "ch1(um)",
                                         "t16(°C)", "motor(degC)", "spindle(RPM)",
                                         "feed(mm/min)", "d_ch1_um", "T_4")] == [
        "t_s", "t_min", "t_h", "d_ch1_um", "T_16", "T_motor", "S_rpm", "feed_mm_min",
        "d_ch1_um", "T_4"]
    with pytest.raises(InputError, match="time column 'Time' has no unit"):
        drift_name("Time", "f")
    assert drift_name("Time", "f", "min") == "t_min"
    assert map_header(["Time", "A"], "f", {"Time": "t_h", "A": "d_a_um"}) == ["t_h", "d_a_um"]
    with pytest.raises(InputError, match="both become"):
        map_header(["ch1(um)", "ch1 [um]"], "f")


def test_detect_leaves_other_instruments_alone():
    assert drift.detect(["t_s", "d_ch1_um"]) and drift.detect(["Time(min)", "ch1(um)"])
    assert drift.detect(["Time", "ch1(um)"])          # read: refused for the missing unit
    for names in (["t_s", "dr_um", "X", "Y"], ["t_s", "dx_um", "dy_um", "dz_um"],
                  ["time_s", "d_mm", "station"]):
        assert not drift.detect(names)


def test_clock_times(tmp_path):
    """A logger's clock column (with a date column, or alone across midnight) is read as
    seconds from the first reading; an ambiguous date is refused in one line."""
    rng = np.random.default_rng(4)
    secs = 23 * 3600 + 50 * 60 + 60 * np.arange(30)           # 23:50 .. 00:19 next day

    def clock(s):
        s = int(s) % 86400
        return f"{s // 3600:02d}:{s % 3600 // 60:02d}:{s % 60:02d}"

    rows = [(("2024-03-01" if s < 86400 else "2024-03-02"), clock(s), f"{rng.normal():.3f}",
             f"{20 + 0.01 * k:.3f}") for k, s in enumerate(secs)]
    f = _write(tmp_path / "dated.csv", "Date,Time,ch1(um),t1(°C)", rows)
    r = drift.read_runs(f)[0]
    np.testing.assert_array_equal(r.t_s, secs - secs[0])
    assert list(r.inputs) == ["T_1"] and r.notes == []
    g = _write(tmp_path / "clock.csv", "Timestamp,ch1(um),t1(°C)", [x[1:] for x in rows])
    assert detect(g) == "drift"
    np.testing.assert_array_equal(drift.read_runs(g)[0].t_s, secs - secs[0])
    out = tmp_path / "conv.csv"
    assert main(["drift", "convert", str(f), "--out", str(out)]) == 0
    assert out.read_text(encoding="utf-8").splitlines()[1] == "t_s,d_ch1_um,T_1"
    bad = _write(tmp_path / "us.csv", "Timestamp,ch1(um),t1(°C)",
                 [(f"03/01/2024 {x[1]}",) + x[2:] for x in rows])
    with pytest.raises(InputError, match="is neither a number nor a clock time"):
        drift.read_runs(bad)
