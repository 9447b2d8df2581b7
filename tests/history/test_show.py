"""``volerr history show``: the weekly scenario's event, trend and forecast against the
planted truth, the map= forecast against the model's volumetric error on a dense grid, the
HTML page."""

import datetime as dt
import itertools
import json

import numpy as np
import pytest

import volerr

from .conftest import START, add_all, run, weekly, write_cal


def test_weekly_calibrations_event_trend_forecast(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", weekly(tmp_path, weeks=21, seed=7), capsys)
    code, out, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                          "EX0C=15 um,EY0C=0.003 mm", "--json", tmp_path / "s.json", "--html",
                          tmp_path / "s.html"], capsys)
    assert code == 0, err
    d = json.loads((tmp_path / "s.json").read_text())
    ev = d["events"]
    assert [(e["parameter"], e["date"]) for e in ev] == [
        ("EY0C", (START + dt.timedelta(weeks=12)).isoformat())]
    assert abs(ev[0]["change"] - 4.0) < 3 * ev[0]["std"]
    slope = d["trends"]["EX0C"]["slope_per_day"]
    assert abs(slope - 0.3 / 7) < 3 * d["trends"]["EX0C"]["std"]
    truth = START + dt.timedelta(days=(15 - 5) / (0.3 / 7))
    f = d["forecast"]["EX0C"]
    assert abs((dt.date.fromisoformat(f["date"]) - truth).days) <= 20
    lo, hi = (dt.date.fromisoformat(x) for x in f["interval"])
    assert lo <= truth <= hi
    assert d["forecast"]["EY0C"]["tolerance"] == pytest.approx(3.0)
    page = (tmp_path / "s.html").read_text()
    assert page.count("data:image/png;base64,") == 3 and "EY0C" in page


def test_map_forecast_against_a_dense_grid(tmp_path, capsys):
    """Only EX0C drifts (0.5 um/week from 2 um): the map's date is when 2 + 0.5 w times the
    largest |error| per um of EX0C over a dense grid of the travel reaches the tolerance."""
    m = volerr.load("DMU50")
    grids = [np.linspace(*m.travel[a], 2) if a not in m.rotary_axes else
             np.arange(m.travel[a][0], m.travel[a][1] + 1e-9, 5.0) for a in m.axes]
    pos = np.array(list(itertools.product(*grids)))
    k = np.linalg.norm(m.volumetric_error(pos, {"EX0C": 1e-3}), axis=1).max() * 1e3
    rng = np.random.default_rng(2)
    files = []
    for w in range(10):
        f = write_cal(tmp_path / f"c{w}.json", {"EX0C": 2 + 0.5 * w + rng.normal(0, 0.05)},
                      {"EX0C": 0.05})
        files.append((f, (START + dt.timedelta(weeks=w)).isoformat()))
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", files, capsys)
    tol = 30.0
    code, _, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                        f"map={tol} um", "--json", tmp_path / "s.json"], capsys)
    assert code == 0, err
    f = json.loads((tmp_path / "s.json").read_text())["forecast"]["map"]
    truth = START + dt.timedelta(weeks=(tol / k - 2) / 0.5)
    assert abs((dt.date.fromisoformat(f["date"]) - truth).days) <= 7
    lo, hi = (dt.date.fromisoformat(x) for x in f["interval"])
    assert lo <= truth <= hi


def test_map_without_constants_and_unknown_tolerance(tmp_path, capsys):
    f = write_cal(tmp_path / "c.json", {"EXX@slope": 1.0}, {"EXX@slope": 0.1})
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", [(f, "2025-01-06")], capsys)
    code, _, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                        "map=30 um", "--json", tmp_path / "s.json"], capsys)
    assert code == 0, err
    m = json.loads((tmp_path / "s.json").read_text())["forecast"]["map"]
    assert m["date"] is None and m["left_out"] == ["EXX@slope"]
    for tol, word in (("EX0C=3 um", "not a parameter"), ("EXX@slope=3 urad", "given in urad"),
                      ("map=3 urad", "map=VALUE um"), ("EXX@slope", "NAME=VALUE")):
        code, _, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                            tol], capsys)
        assert code == 2 and word in err and len(err.strip().splitlines()) == 1, (tol, err)
    code, _, err = run(["history", "show", "--db", db, "--machine", "M2"], capsys)
    assert code == 2 and "no entries" in err and "M1" in err


def test_history_result_contract(tmp_path, capsys):
    """``volerr.history.show`` returns a result: ``summary()`` is what the command prints,
    ``table()`` holds the printed numbers (the planted step of EY0C, the planted drift of
    EX0C per day, the tolerances), a short repr, ``to_dict()`` the --json document."""
    from volerr.results import Row

    db = tmp_path / "h.sqlite"
    add_all(db, "M1", weekly(tmp_path, weeks=21, seed=7), capsys)
    code, out, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                          "EX0C=15 um,EY0C=3 um", "--json", tmp_path / "s.json"], capsys)
    assert code == 0, err
    h = volerr.history.show(str(db), "M1", "EX0C=15 um,EY0C=3 um")
    assert h.summary() == out.rstrip("\n")
    assert h.to_dict() == json.loads((tmp_path / "s.json").read_text())
    r = repr(h)
    assert r.startswith("<volerr History: M1 (DMU50): 21 entries") and "\n" not in r
    assert len(r) < 130
    rows = {row.name: row for row in h._rows()}
    assert all(isinstance(x, Row) and x.k == 1.0 for x in rows.values())
    jump = (START + dt.timedelta(weeks=12)).isoformat()
    step = rows[f"EY0C step {jump}"]
    assert step.unit == "um" and abs(step.value - 4.0) < 3 * step.std
    slope = [x for n, x in rows.items() if n.startswith("EX0C slope since")]
    assert len(slope) == 1 and slope[0].unit == "um/d"
    assert abs(slope[0].value - 0.3 / 7) < 3 * slope[0].std
    assert rows["EX0C tolerance"].value == 15 and rows["EY0C tolerance"].value == 3
    table = h.table()
    assert len(table) == len(rows) > 0
    assert list(getattr(table, "columns", Row._fields)) == list(Row._fields)
    assert h.events == h.to_dict()["events"] and h["machine"] == "M1"
