"""Hostile inputs of the drift loop (issue 44's acceptance pass, D4-D10), through the command
line: a refusal is one stderr line naming the file (or option) and the likely mistake, exit
2, nothing written; an accepted oddity is named in the console and the JSON.

The campaigns are written here from a first-order warming (time constant 30 min, readings
every 60 s, a fixed seed), independently of the loop."""

from __future__ import annotations

import csv
import json

import numpy as np
import pytest

from helpers import in_process

HOURS = 4.0


def _rows(seed: int, t0: float = 0.0, temps: int = 2, room=None):
    """(header, rows) of one run: ``t_s`` from ``t0``, channel X, ``temps`` temperatures
    (``T_spindle`` warming 3 K, the others a slow wave), ``T_room`` constant at ``room`` if
    given."""
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, HOURS * 3600.0, 60.0)
    heat = 1 - np.exp(-t / 1800.0)
    cols = {"t_s": t + t0, "d_X_um": 4 * heat + 0.3 * rng.standard_normal(len(t)),
            "T_spindle": 20 + 3 * heat + 0.02 * rng.standard_normal(len(t))}
    for j in range(1, temps):
        cols[f"T_s{j}"] = (20 + (0.5 + 0.5 * j) * heat + 0.3 * np.sin(t / (3000.0 + 500 * j))
                           + 0.02 * rng.standard_normal(len(t)))
    cols["T_room"] = (np.full(len(t), room) if room is not None
                      else 20 + 0.5 * np.sin(t / 5000.0) + 0.02 * rng.standard_normal(len(t)))
    return list(cols), np.column_stack(list(cols.values()))


def _write(path, header, rows, extra=None):
    """The run as a drift file (``extra`` {column: one value for every row})."""
    extra = extra or {}
    head = ",".join(header + list(extra))
    body = [",".join([f"{v:.10g}" for v in r] + list(extra.values())) for r in rows]
    path.write_text("# channel d_X: X\n" + head + "\n" + "\n".join(body) + "\n")
    return path


def _campaign(tmp_path, n=4, **kw):
    return [_write(tmp_path / f"day{i}.csv", *_rows(i, **kw)) for i in range(n)]


def _loop(tmp_path, *args):
    """``volerr ARGS`` in this process (``helpers.in_process``: ``main``'s exit code and
    lines; a warning a process would print is appended to stderr), without starting an
    interpreter; the entry point's own process is tests/cli/test_cli_core.py's."""
    return in_process.volerr("loop", "DMU50", *args, "--json", tmp_path / "out.json",
                             "--predictions-out", tmp_path / "p.csv", cwd=tmp_path)


def _refused(r, tmp_path, *words):
    """Exit 2, one stderr line holding every one of ``words``, no traceback, nothing written."""
    assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "Traceback" not in r.stderr, r.stderr
    for w in words:
        assert w in err[0], (w, err[0])
    assert not (tmp_path / "out.json").exists() and not (tmp_path / "p.csv").exists()
    return err[0]


def _drift(files):
    return [f"drift:{f}" for f in files]


# --- D5: a time column in minutes (or hours) under t_s --------------------------------------

def test_minutes_under_t_s_in_one_run_of_a_campaign_refused(tmp_path):
    """Two temperatures (below the physics rule's three): the campaign rule alone.  Day 2's
    time divided by 60 (a 4 h run spanning 240 "s" at 1 s steps): refused naming day2.csv,
    held out or in training."""
    files = _campaign(tmp_path)
    header, rows = _rows(2)
    rows[:, 0] /= 60.0
    _write(files[2], header, rows)
    for order in (files, files[2:3] + files[:2] + files[3:]):
        r = _loop(tmp_path, *_drift(order))
        _refused(r, tmp_path, "day2.csv", "minutes or hours", "give seconds")


def test_hours_under_t_s_of_a_single_run_refused_by_physics(tmp_path):
    """One file, three temperatures, time in hours under t_s: its median sensor changes
    ~1.5 K in 4 "s", faster than a machine warms."""
    header, rows = _rows(0, temps=3)
    rows[:, 0] /= 3600.0
    f = _write(tmp_path / "one.csv", header, rows)
    r = _loop(tmp_path, f"drift:{f}")
    _refused(r, tmp_path, "one.csv", "K/min", "minutes or hours")


def test_the_same_run_in_seconds_passes(tmp_path):
    """The physics rule's counterpart: the same single run in seconds (0.025 K/min)."""
    f = _write(tmp_path / "one.csv", *_rows(0, temps=3))
    r = _loop(tmp_path, f"drift:{f}")
    assert r.returncode == 0, r.stderr


def test_no_false_refusal_on_short_days_and_another_interval():
    """A 1-hour day at 30 s beside 4-hour days at 60 s (interval 2x, duration 4x below the
    medians) and FL_THERMAL's 46 h at 15 s: no time-slip refusal (the rule itself)."""
    from importlib import resources

    from volerr.instruments.drift import DriftRun
    from volerr.loop.drift.series import _refuse_time_slip, read_runs

    def run(seed, span_h, dt):
        t = np.arange(0.0, span_h * 3600.0, dt)
        heat = 1 - np.exp(-t / 1800.0)
        temps = {f"T_{j}": 20 + (1 + j) * heat for j in range(3)}
        return DriftRun(f"d{seed}.csv", "", t, {"X": 4 * heat}, {"X": "X"}, {"X": None}, temps)

    _refuse_time_slip([run(0, 4, 60.0), run(1, 4, 60.0), run(2, 1, 30.0), run(3, 4, 60.0)])
    fl = resources.files("volerr") / "data" / "fl_thermal_spindle.csv"
    assert len(read_runs([str(fl)])[0]) == 1


# --- D7: epoch timestamps -------------------------------------------------------------------

def test_epoch_timestamps_read_from_the_first_reading_and_said(tmp_path):
    """Day 3 in epoch seconds (1.7e9 + the same times): accepted, the console and the JSON
    say so, and every figure equals the campaign's with day 3 in seconds from 0."""
    files = _campaign(tmp_path)
    plain = _loop(tmp_path, *_drift(files))
    assert plain.returncode == 0, plain.stderr
    want = json.loads((tmp_path / "out.json").read_text())
    (tmp_path / "out.json").unlink()
    (tmp_path / "p.csv").unlink()
    _write(files[3], *_rows(3, t0=1.7e9))
    r = _loop(tmp_path, *_drift(files))
    assert r.returncode == 0, r.stderr
    assert "day3.csv holds timestamps" in r.stdout
    got = json.loads((tmp_path / "out.json").read_text())
    assert got.pop("time_origins_s") == {"day3.csv": 1.7e9}
    assert got["channels"] == want["channels"]


# --- D6, D6b: sensors constant over a run, a file without inputs ----------------------------

def test_a_sensor_constant_over_a_run_is_left_out_and_named(tmp_path):
    """T_room = 20.00 over day 1 (a room steadier than the logger's resolution): left out of
    every run and named (fault "constant"), not a refusal of the campaign."""
    files = _campaign(tmp_path)
    _write(files[1], *_rows(1, room=20.0))
    r = _loop(tmp_path, *_drift(files))
    assert r.returncode == 0, r.stderr
    assert "T_room (= 20) constant in day1.csv" in r.stdout
    left = json.loads((tmp_path / "out.json").read_text())["inputs_left_out"]
    assert [(e["input"], e["reason"]) for e in left] == [("T_room", "faulty")]
    assert left[0]["faults"][0]["fault"] == "constant" and left[0]["faults"][0]["value"] == 20.0


def test_every_sensor_constant_names_them_all(tmp_path):
    """Every temperature of day 1 constant and no other input: no input is left; one line
    naming day1.csv and every sensor."""
    files = _campaign(tmp_path)
    header, rows = _rows(1)
    rows[:, 2:] = rows[0, 2:]
    _write(files[1], header, rows)
    r = _loop(tmp_path, *_drift(files))
    line = _refused(r, tmp_path, "day1.csv", "no logged input is left")
    assert line.startswith("volerr loop: error: day1.csv:")
    for name in header[2:]:
        assert f"{name} (constant)" in line, name


def test_a_file_without_inputs_is_named(tmp_path):
    """A truth file (t_s and the channel only) given as a run: the line names it, not the
    first file."""
    files = _campaign(tmp_path, n=3)
    header, rows = _rows(9)
    truth = _write(tmp_path / "truth.csv", header[:2], rows[:, :2])
    r = _loop(tmp_path, *_drift(files + [truth]))
    line = _refused(r, tmp_path, "truth.csv: no logged input", "it lacks T_spindle")
    assert "day0.csv" not in line


# --- D4: the predictions CSV's run column ---------------------------------------------------

def test_the_run_column_is_the_label_or_the_file_name(tmp_path):
    """Files with a one-label ``run`` column carry it; a file without one, its name."""
    files = _campaign(tmp_path, n=3)
    for i in (0, 1):
        _write(files[i], *_rows(i), extra={"run": f"monday{i}"})
    r = _loop(tmp_path, *_drift(files))
    assert r.returncode == 0, r.stderr
    with open(tmp_path / "p.csv", newline="") as fh:
        pairs = {(row["file"], row["run"]) for row in csv.DictReader(fh)}
    assert pairs == {("day0.csv", "monday0"), ("day1.csv", "monday1"), ("day2.csv", "day2.csv")}


# --- D9: refusals name the option -----------------------------------------------------------

@pytest.mark.parametrize("case", ["every file held out", "all the time", "beyond the data",
                                  "missing held-out file"])
def test_refusals_name_the_option(tmp_path, case):
    files = _campaign(tmp_path, n=3)
    args = {"every file held out": ["--holdout-files", *files],
            "all the time": ["--holdout-time", "0s:"],
            "beyond the data": ["--holdout-time", "999h:"],
            "missing held-out file": ["--holdout-files", tmp_path / "nope.csv"]}[case]
    words = {"every file held out": ["--holdout-files", "3 of 3 runs", "hold out less"],
             "all the time": ["--holdout-time 0s:", "fewer than 20"],
             "beyond the data": ["--holdout-time 999h:", f"0 .. {(HOURS * 60 - 1) * 60:g} s"],
             "missing held-out file": ["--holdout-files", "nope.csv", "not found"]}[case]
    _refused(_loop(tmp_path, *_drift(files), *args), tmp_path, *words)


def test_a_duplicate_column_is_named(tmp_path):
    files = _campaign(tmp_path, n=3)
    header, rows = _rows(1)
    _write(files[1], header[:3] + ["T_spindle"] + header[4:], rows)
    _refused(_loop(tmp_path, *_drift(files)), tmp_path, "day1.csv", "'T_spindle' appears 2")


# --- D10: the engine's products by selection are the products -------------------------------

def test_selection_products_equal_the_matrix_products_bit_for_bit():
    """``Sel.right`` / ``Sel.left`` (columns picked and subtracted) against ``@`` on a model
    of run indicators, single columns and differences; any other W falls back to ``@``."""
    from volerr.loop.drift.engine import Sel

    rng = np.random.default_rng(7)
    mz = 40
    A = rng.standard_normal((mz, 3 * mz))
    G = A @ A.T
    W = np.eye(mz)[:, :6]
    for a, b in ((8, -1), (9, 30), (31, 12), (39, -1)):
        w = np.zeros(mz)
        w[a] = 1.0
        if b >= 0:
            w[b] = -1.0
        W = np.column_stack([W, w])
    S = Sel(W)
    assert S.pa is not None
    h = rng.standard_normal(mz)
    assert np.array_equal(S.right(G), G @ W)
    assert np.array_equal(S.left(G), W.T @ G)
    assert np.array_equal(S.right(S.left(G)), W.T @ G @ W)
    assert np.array_equal(S.left(h), W.T @ h)
    on = np.arange(W.shape[1]) != 2
    assert np.array_equal(S.take(on).right(G), G @ W[:, on])
    W2 = W.copy()
    W2[3, 7] = 0.5                      # not a selection: the product itself
    S2 = Sel(W2)
    assert S2.pa is None and np.array_equal(S2.right(G), G @ W2)
