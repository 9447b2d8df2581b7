"""More hostile inputs of the thermal drift commands (``volerr loop`` on drift files, ``volerr
iso230-3``, ``volerr drift convert``), beyond tests/loop/test_drift_hostile_inputs.py: the files
a user's logger, spreadsheet or typing produces.  A refusal is exit 2, one stderr line naming
the file or column and the likely mistake, no traceback, no warning, nothing written and an
output that was there before left as it was; an acceptance is a file whose data can be right
(the reason with the case).

The runs are written here (a first-order warming, time constant 30 min, readings every 60 s
for 3 h, a fixed seed), independently of the readers."""

from __future__ import annotations

import csv

import numpy as np
import pytest

from helpers.in_process import volerr

KEEP = "an output of an earlier run\n"


def _cols(seed: int = 0, temps: int = 3, room: bool = True) -> dict:
    """One run: ``t_s``, channel ``d_X_um`` (4 um warming, 0.3 um noise), ``temps``
    temperatures ``T_spindle``, ``T_s1`` ... (20 degC warming 1-3 K), ``T_room``."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 3 * 3600.0, 60.0)
    heat = 1 - np.exp(-t / 1800.0)
    cols = {"t_s": t, "d_X_um": 4 * heat + 0.3 * rng.standard_normal(len(t)),
            "T_spindle": 20 + 3 * heat + 0.02 * rng.standard_normal(len(t))}
    for j in range(1, temps):
        cols[f"T_s{j}"] = (20 + (0.5 + 0.5 * j) * heat + 0.3 * np.sin(t / (3000.0 + 500 * j))
                           + 0.02 * rng.standard_normal(len(t)))
    if room:
        cols["T_room"] = 20 + 0.5 * np.sin(t / 5000.0) + 0.02 * rng.standard_normal(len(t))
    return cols


def _write(path, cols: dict, head: str = "# channel d_X: X\n", sep: str = ",",
           fmt=lambda v: f"{v:.10g}"):
    """``cols`` as a drift file (text cells as given, numbers by ``fmt``)."""
    names = list(cols)
    n = len(cols[names[0]])
    body = [sep.join(x if isinstance(x, str) else fmt(x) for x in (cols[k][i] for k in names))
            for i in range(n)]
    path.write_text(head + sep.join(names) + "\n" + "\n".join(body) + "\n", encoding="utf-8")
    return path


def _loop(d, *files, extra=()):
    return volerr("loop", "DMU50", *[f"drift:{f}" for f in files], "--json", d / "out.json",
                  "--predictions-out", d / "p.csv", *extra, cwd=d)


def _iso(d, f):
    return volerr("iso230-3", f, "--json", d / "out.json", cwd=d)


def _convert(d, raw):
    return volerr("drift", "convert", raw, "--out", d / "out.json", cwd=d)


# --- the cases: name -> (run(d) -> result, words of the refusal line or None: accepted) ------

def _nm_single(d):
    c = _cols()
    c["d_X_um"] = c["d_X_um"] * 1000.0
    return _loop(d, _write(d / "nm.csv", c))


def _mm_single(d):
    c = _cols()
    c["d_X_um"] = c["d_X_um"] * 1e-3
    return _loop(d, _write(d / "mm.csv", c))


def _degf_no_room(d):
    """Every sensor on the machine, in degF: each alone could be a hot spindle's."""
    c = _cols(room=False)
    for k in [k for k in c if k.startswith("T_")]:
        c[k] = c[k] * 9 / 5 + 32
    return _loop(d, _write(d / "f.csv", c))


def _degf_room_iso(d):
    c = _cols()
    c["T_room"] = c["T_room"] * 9 / 5 + 32
    return _iso(d, _write(d / "f.csv", c))


def _kelvin_convert(d):
    raw = d / "raw.csv"
    raw.write_text("Time(min),ch1(um),t1(°C)\n0,0.0,293.2\n1,0.3,293.9\n2,0.5,294.4\n",
                   encoding="utf-8")
    return _convert(d, raw)


def _swapped(d):
    c = _cols()
    c["d_X_um"], c["T_spindle"] = c["T_spindle"], c["d_X_um"]
    return _loop(d, _write(d / "swapped.csv", c))


def _hours_two_sensors(d):
    c = _cols(temps=1)
    c["t_s"] = c["t_s"] / 3600.0
    return _loop(d, _write(d / "hours.csv", c))


def _european_excel(d):
    """UTF-8 BOM, semicolons, decimal commas: a spreadsheet saved in Germany."""
    p = _write(d / "eu.csv", _cols(), head="", sep=";",
               fmt=lambda v: f"{v:.6f}".replace(".", ","))
    p.write_bytes(b"\xef\xbb\xbf" + p.read_bytes())
    return _loop(d, p)


def _dup_time_iso(d):
    c = _cols()
    c["t_s"][10] = c["t_s"][9]
    return _iso(d, _write(d / "dup.csv", c))


def _back_time(d):
    c = _cols()
    c["t_s"][10] = c["t_s"][5]
    return _loop(d, _write(d / "back.csv", c))


def _channel_all_nan_iso(d):
    c = _cols()
    c["d_X_um"] = ["NaN"] * len(c["t_s"])
    return _iso(d, _write(d / "nan.csv", c))


def _temperature_gaps(d):
    c = _cols()
    c["T_s1"] = [("" if i % 7 == 3 else "NaN" if i % 11 == 5 else f"{v:.6f}")
                 for i, v in enumerate(c["T_s1"])]
    return _loop(d, _write(d / "gaps.csv", c))


def _three_readings(d):
    return _loop(d, _write(d / "three.csv", {k: v[:3] for k, v in _cols().items()}))


def _three_readings_iso(d):
    """Accepted: three readings an hour apart are a manual drift test; ISO 230-3's figures
    (range, max, min) are what they say."""
    c = {k: v[::60][:3] for k, v in _cols().items()}
    r = _iso(d, _write(d / "three.csv", c))
    assert "3 readings over 2.00 h" in r.stdout, r.stdout
    return r


def _header_line_twice(d):
    return _loop(d, _write(d / "two.csv", _cols(), head="# channel d_X: X\n# channel X: Y\n"))


def _header_only_iso(d):
    p = d / "head.csv"
    p.write_text("# channel d_X: X\nt_s,d_X_um,T_spindle,T_room\n", encoding="utf-8")
    return _iso(d, p)


def _holdout_reversed(d):
    return _loop(d, _write(d / "a.csv", _cols()), extra=("--holdout-time", "2h:1h"))


def _holdout_from_end(d):
    """``-1h:2h`` (with ``=``, past argparse) read by the rule ``A <= t < B`` holds out the
    first 2 h; the likely meaning, a time counted from the end, is another stretch."""
    return _loop(d, _write(d / "a.csv", _cols()), extra=("--holdout-time=-1h:2h",))


def _huge_line(d):
    """One 5 MB line (a binary dump or a file without line ends)."""
    p = d / "big.csv"
    p.write_text("t_s,d_X_um,T_spindle\n" + "1" * (5 * 2 ** 20) + "\n", encoding="utf-8")
    return _loop(d, p)


def _environment_every_row(d):
    c = _cols()
    c["environment"] = [f"e{i}" for i in range(len(c["t_s"]))]
    return _loop(d, _write(d / "env.csv", c))


def _nm_column_beside(d):
    """A second channel headed ``_nm``: was read as a logged input (a traceback)."""
    c = _cols()
    c["d_Y_nm"] = c["d_X_um"] * 1000.0 + 5.0
    return _loop(d, _write(d / "nmcol.csv", c))


def _inch_channel_iso(d):
    c = _cols()
    c["d_X_in"] = c.pop("d_X_um") / 25400.0
    return _iso(d, _write(d / "inch.csv", c, head=""))


def _channel_copy(d):
    """The channel exported again as an input (was a traceback)."""
    c = _cols()
    c["disp_raw"] = c["d_X_um"] * 1.0
    return _loop(d, _write(d / "copy.csv", c))


def _nm_logger_convert(d):
    raw = d / "raw.csv"
    raw.write_text("Time(min),ch1(um),t1(°C)\n0,0,20.0\n1,3000,21.0\n2,4500,21.5\n",
                   encoding="utf-8")
    return _convert(d, raw)


def _ms_time_iso(d):
    c = _cols()
    c["t_s"] = c["t_s"] * 1000.0
    return _iso(d, _write(d / "ms.csv", c))


def _heldout_file_is_data(d):
    """Accepted: ``--holdout-files`` names which of the data files is held out (the other is
    the training); the same readings under another name are refused (hostile_inputs)."""
    a, b = _write(d / "a.csv", _cols(0)), _write(d / "b.csv", _cols(1))
    r = _loop(d, a, b, extra=("--holdout-files", a))
    assert "runs of a.csv held out" in r.stdout, r.stdout
    with open(d / "p.csv", newline="") as fh:
        split = {(row["file"], row["split"]) for row in csv.DictReader(fh)}
    assert ("b.csv", "test") not in split and ("a.csv", "train") not in split, split
    return r


def _negative_speed(d):
    """Accepted: a negative speed is the spindle turning counter-clockwise (M04)."""
    c = _cols()
    c["S_rpm"] = np.where(c["t_s"] > 600, -8000.0, 0.0)
    return _loop(d, _write(d / "m04.csv", c))


def _unicode_names(d):
    """Accepted: names in any script are names."""
    c = _cols()
    c["T_Spindel_ü"] = c.pop("T_s1")
    c["d_Δx_um"] = c.pop("d_X_um")
    r = _loop(d, _write(d / "prüfung.csv", c, head="# channel d_Δx: X\n"))
    assert "channel Δx" in r.stdout, r.stdout
    with open(d / "p.csv", newline="", encoding="utf-8") as fh:
        assert {row["channel"] for row in csv.DictReader(fh)} == {"Δx"}
    return r


def _hot_spindle_alone(d):
    """Accepted: one sensor at 68-74 degC may be a spindle housing at speed (in degF it
    would be 20-23 degC, but a lone sensor cannot tell; two or more all above 50 degC are
    refused, :func:`_degf_no_room`)."""
    c = _cols(temps=1, room=False)
    c["T_spindle"] = c["T_spindle"] * 9 / 5 + 32
    return _loop(d, _write(d / "hot.csv", c))


CASES = {
    "nm under _um, one run": (_nm_single, ["nm.csv", "d_X_um", "nm under the _um header"]),
    "mm under _um, one run": (_mm_single, ["mm.csv", "d_X_um", "mm under the _um header"]),
    "degF, no room sensor": (_degf_no_room, ["f.csv", "every temperature column", "degF"]),
    "degF room sensor, iso230-3": (_degf_room_iso, ["f.csv", "T_room", "degF"]),
    "kelvin, drift convert": (_kelvin_convert, ["raw.csv", "T_1", "in K?"]),
    "temperature and drift swapped": (_swapped, ["swapped.csv", "T_spindle", "d_X_um",
                                                 "swapped"]),
    "hours under t_s, two sensors": (_hours_two_sensors, ["hours.csv", "hours under t_s"]),
    "BOM, semicolons, decimal commas": (_european_excel, ["eu.csv", "decimal comma"]),
    "duplicated time stamp, iso230-3": (_dup_time_iso, ["dup.csv", "row 12 repeats the time"]),
    "time goes back": (_back_time, ["back.csv", "time goes back at row 12"]),
    "channel all NaN, iso230-3": (_channel_all_nan_iso, ["nan.csv", "d_X_um", "NaN"]),
    "temperature with '' and NaN gaps": (_temperature_gaps, ["gaps.csv", "T_s1 row 5"]),
    "a run of three readings": (_three_readings, ["fewer than 20 training readings"]),
    "a channel's header line twice": (_header_line_twice, ["two.csv", "two header lines"]),
    "header only, iso230-3": (_header_only_iso, ["head.csv", "no data rows"]),
    "--holdout-time reversed": (_holdout_reversed, ["--holdout-time '2h:1h'", "A >= B"]),
    "--holdout-time from the end": (_holdout_from_end, ["'-1h:2h'", "-3600 s is before every "
                                                        "reading", "from the end", "7140s:"]),
    "a 5 MB line": (_huge_line, ["big.csv", "not a readable CSV"]),
    "environment label on every row": (_environment_every_row, ["env.csv", "environment",
                                                                "changes within"]),
    "a channel in nm beside one in um": (_nm_column_beside, ["nmcol.csv", "d_Y_nm", "'nm'"]),
    "a channel in inches, iso230-3": (_inch_channel_iso, ["inch.csv", "d_X_in", "'in'"]),
    "the channel again as an input": (_channel_copy, ["copy.csv", "disp_raw", "d_X_um again"]),
    "nm in a logger's (um) column, convert": (_nm_logger_convert, ["raw.csv", "d_ch1_um",
                                                                   "nm under the _um"]),
    "time in ms under t_s, iso230-3": (_ms_time_iso, ["ms.csv", "likely in ms"]),
    "three readings an hour apart, iso230-3": (_three_readings_iso, None),
    "held-out file one of the data files": (_heldout_file_is_data, None),
    "negative spindle speed (M04)": (_negative_speed, None),
    "unicode names": (_unicode_names, None),
    "one hot spindle sensor": (_hot_spindle_alone, None),
}


@pytest.mark.parametrize("command", ["loop", "iso230-3", "convert"])
def test_a_file_too_large_to_read_is_refused_before_reading(tmp_path, monkeypatch, command):
    """Readings every 0.01 s for a week (3 GB) would exhaust the memory: refused by size
    before reading (the limit lowered here to 64 kB for a 0.25 MB file: 0.01 s for 80 s)."""
    from volerr.instruments import drift

    monkeypatch.setattr(drift, "MAX_FILE_BYTES", 2 ** 16)
    t = np.arange(0.0, 80.0, 0.01)
    f = _write(tmp_path / "week.csv", {"t_s": t, "d_X_um": 1e-3 * t, "T_spindle": 20 + 1e-3 * t,
                                       "T_room": 20 + 1e-4 * t})
    assert f.stat().st_size > 2 ** 17
    (tmp_path / "out.json").write_text(KEEP)
    run = {"loop": lambda: _loop(tmp_path, f), "iso230-3": lambda: _iso(tmp_path, f),
           "convert": lambda: _convert(tmp_path, f)}[command]
    r = run()
    assert r.returncode == 2 and r.stderr.count("\n") == 1, r.stderr
    assert "week.csv" in r.stderr and "every 0.01 s?" in r.stderr, r.stderr
    assert (tmp_path / "out.json").read_text() == KEEP and not (tmp_path / "p.csv").exists()


@pytest.mark.parametrize("case", list(CASES))
def test_hostile_drift_input(tmp_path, case):
    run, words = CASES[case]
    if words is None:
        r = run(tmp_path)
        assert r.returncode == 0 and r.stderr == "", (r.returncode, r.stderr)
        return
    (tmp_path / "out.json").write_text(KEEP)
    r = run(tmp_path)
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    lines = r.stderr.strip().splitlines()
    assert len(lines) == 1 and "Traceback" not in r.stderr and "Warning" not in r.stderr, \
        r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    assert (tmp_path / "out.json").read_text() == KEEP
    assert not (tmp_path / "p.csv").exists()


def test_a_noise_free_ramp_is_no_copy_and_fits_exactly(tmp_path):
    """A simulated or hand-written run with no noise: the channel and a temperature both
    straight lines in time agree to correlation 1 without one being the other (not refused
    as a copy), and the loop fits the exact slope (the least-score tie rule holds for a
    score at the rounding floor, which may fall below 0) instead of failing."""
    t = np.arange(0.0, 200 * 15.0, 15.0)
    i = t / 15.0
    f = _write(tmp_path / "ramp.csv", {"t_s": t, "d_X_um": 0.1 * i, "T_head": 20 + 0.01 * i,
                                       "T_bed": 21 + 0.003 * i * ((i % 7) - 3)})
    r = _loop(tmp_path, f)
    assert r.returncode == 0 and r.stderr == "", r.stderr
    import json
    doc = json.loads((tmp_path / "out.json").read_text())
    (term,) = [t for e in doc["effects"] for t in e["terms"]]
    assert term["basis"] == "T_head" and term["value"] == pytest.approx(10.0, rel=1e-9)
