"""The history store: SQLite by default, PostgreSQL by URL; its refusals (one line, exit 2,
nothing lost), duplicates, dates, machine ids, locks and concurrent writers."""

import json
import sqlite3
import subprocess
import sys

import pytest

from volerr.history.store import SCHEMA_VERSION, Store

from .conftest import add_all, run, weekly, write_cal


def n_entries(db, machine="M1"):
    return len(Store(str(db)).entries(machine))


def test_add_and_show_roundtrip(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=4)
    add_all(db, "M1", files, capsys)
    entries = Store(str(db)).entries("M1")
    assert [e.date for e in entries] == [d for _, d in files]
    doc = json.loads(files[2][0].read_text())
    assert entries[2].values["EX0C"].value == doc["parameters"]["EX0C"]["value"]
    assert entries[2].values["EA0C"].unit == "urad"
    code, out, err = run(["history", "show", "--db", db, "--machine", "M1", "--json",
                          tmp_path / "s.json"], capsys)
    assert code == 0, err
    shown = json.loads((tmp_path / "s.json").read_text())
    assert shown["machine"] == "M1" and len(shown["entries"]) == 4
    assert set(shown) >= {"machine", "entries", "events", "trends", "forecast"}


def test_same_result_twice_is_stored_once_other_machine_refused(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    (f, d), = weekly(tmp_path, weeks=1)
    add_all(db, "M1", [(f, d)], capsys)
    code, out, _ = run(["history", "add", "--db", db, "--machine", "M1", "--date", d, f], capsys)
    assert code == 0 and "already stored" in out
    assert n_entries(db) == 1
    code, _, err = run(["history", "add", "--db", db, "--machine", "M2", "--date", d, f], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1 and "one result is one" in err
    code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date",
                        "2025-02-01", f], capsys)
    assert code == 2 and "already" in err
    assert n_entries(db) == 1 and n_entries(db, "M2") == 0


@pytest.mark.parametrize("machine", ["x'; DROP TABLE volerr_entries; --", 'a"b', "a;b",
                                     " lead", "tab\tbed", "", "x" * 65])
def test_machine_id_rule(tmp_path, capsys, machine):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=2)
    add_all(db, "M1", files[:1], capsys)
    code, _, err = run(["history", "add", "--db", db, "--machine", machine, "--date",
                        files[1][1], files[1][0]], capsys)
    assert code == 2 and len(err.strip().splitlines()) == 1
    assert n_entries(db) == 1


def test_machine_ids_are_bound_parameters(tmp_path):
    """Every id the rule lets through is data: ids that look like SQL fragments to a naive
    formatter are stored and found as written."""
    from volerr.history.run import add

    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=3)
    ids = ["DMU50 #1 -- hall/2", "a:b+c.d_e", "OR 1-1"]
    for m, (f, d) in zip(ids, files):
        add(str(db), m, [f], d)
    s = Store(str(db))
    assert s.machines() == sorted(ids)
    assert [len(s.entries(m)) for m in ids] == [1, 1, 1]


def test_dates(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=3)
    add_all(db, "M1", [files[1]], capsys)
    code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date", "2999-01-01",
                        files[2][0]], capsys)
    assert code == 2 and "future" in err and len(err.strip().splitlines()) == 1
    for bad in ("2025-13-01", "01.02.2025", "2025-2-1"):
        code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date", bad,
                            files[2][0]], capsys)
        assert code == 2 and "YYYY-MM-DD" in err
    # back-filling an older result is allowed: it takes its place in date order
    add_all(db, "M1", [files[0]], capsys)
    assert [e.date for e in Store(str(db)).entries("M1")] == [files[0][1], files[1][1]]


def test_several_files_all_or_nothing(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=3)
    add_all(db, "M1", files[:1], capsys)
    other = write_cal(tmp_path / "other.json", {"EX0C": 1.0}, {"EX0C": 0.1}, layout="MB1")
    code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date",
                        files[1][1], files[1][0], other], capsys)
    assert code == 2 and "layout MB1" in err
    assert n_entries(db) == 1


def _check_json(path, changed, unchanged=(), layout="DMU50"):
    path.write_text(json.dumps({"layout": layout, "verdict": "changed" if changed else
                                "unchanged", "changed": changed, "unchanged": list(unchanged),
                                "volumetric_change_um": {"max": 1.0, "rms": 0.5}}))
    return path


def test_check_entries_take_the_reference_value(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    (ref, d0), = weekly(tmp_path, weeks=1)
    chk = _check_json(tmp_path / "c1.json",
                      [{"parameter": "EY0C", "change": 4.0, "unit": "um", "std": 0.3}],
                      ["EX0C", {"parameter": "EA0C", "change": 0.5, "unit": "urad",
                                "std": 1.0}])
    early = _check_json(tmp_path / "c0.json", [])
    code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date",
                        "2024-12-01", early], capsys)
    assert code == 2 and "no calibration" in err
    add_all(db, "M1", [(ref, d0), (chk, "2025-02-01")], capsys)
    e = Store(str(db)).entries("M1")
    refv = json.loads(ref.read_text())["parameters"]
    assert e[1].kind == "check" and e[1].reference_sha256 == e[0].sha256
    assert e[1].values["EY0C"].value == pytest.approx(refv["EY0C"]["value"] + 4.0, abs=1e-12)
    assert e[1].values["EY0C"].std == 0.3 and e[1].values["EY0C"].status == "changed"
    assert e[1].values["EX0C"].value is None
    assert e[1].values["EA0C"].value == pytest.approx(refv["EA0C"]["value"] + 0.5, abs=1e-12)
    other = _check_json(tmp_path / "c2.json", [], layout="MB1")
    code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date",
                        "2025-02-02", other], capsys)
    assert code == 2 and "layout MB1" in err and n_entries(db) == 2


@pytest.mark.parametrize("content", [b"\x00garbage, not a database" * 40, b"SQLite format 3\x00"
                                     + b"\xff" * 2000])
def test_corrupt_file_refused(tmp_path, capsys, content):
    db = tmp_path / "h.sqlite"
    db.write_bytes(content)
    (f, d), = weekly(tmp_path, weeks=1)
    for args in (["add", "--db", db, "--machine", "M1", "--date", d, f],
                 ["show", "--db", db, "--machine", "M1"]):
        code, _, err = run(["history", *args], capsys)
        assert code == 2 and "not a volerr history" in err and len(err.strip().splitlines()) == 1
    assert db.read_bytes() == content


def test_foreign_and_newer_databases_refused(tmp_path, capsys):
    (f, d), = weekly(tmp_path, weeks=1)
    foreign = tmp_path / "shop.sqlite"
    with sqlite3.connect(foreign) as c:
        c.execute("CREATE TABLE parts (id INTEGER)")
    before = foreign.read_bytes()
    code, _, err = run(["history", "add", "--db", foreign, "--machine", "M1", "--date", d, f],
                       capsys)
    assert code == 2 and "other tables: parts" in err and foreign.read_bytes() == before
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", [(f, d)], capsys)
    with sqlite3.connect(db) as c:
        c.execute("UPDATE volerr_schema_version SET version = ?", (SCHEMA_VERSION + 1,))
    code, _, err = run(["history", "show", "--db", db, "--machine", "M1"], capsys)
    assert code == 2 and "newer volerr" in err


def test_not_a_result_refused(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    bad = tmp_path / "bad.json"
    for text in ("{not json", json.dumps([1, 2]), json.dumps({"layout": "DMU50"}),
                 json.dumps({"layout": "DMU50", "parameters": {"EX0C": {"value": "x",
                                                                        "std": 1}}})):
        bad.write_text(text)
        code, _, err = run(["history", "add", "--db", db, "--machine", "M1", "--date",
                            "2025-01-01", bad], capsys)
        assert code == 2 and len(err.strip().splitlines()) == 1, err
    assert not db.exists()              # a refused first add leaves no store behind
    code, _, err = run(["history", "show", "--db", tmp_path / "none.sqlite", "--machine", "M1"],
                       capsys)
    assert code == 2 and "no such history" in err


def n_entries_safe(db):
    try:
        return n_entries(db)
    except Exception:
        return 0


ADD = [sys.executable, "-m", "volerr", "history", "add"]


def test_locked_database_one_line_nothing_lost(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=2)
    add_all(db, "M1", files[:1], capsys)
    holder = sqlite3.connect(db, isolation_level=None)
    holder.execute("BEGIN EXCLUSIVE")
    try:
        p = subprocess.run(ADD + ["--db", str(db), "--machine", "M1", "--date", files[1][1],
                                  "--wait", "0.2", str(files[1][0])],
                           capture_output=True, text=True, timeout=120)
    finally:
        holder.execute("ROLLBACK")
        holder.close()
    assert p.returncode == 2 and "locked" in p.stderr, p.stderr
    assert len(p.stderr.strip().splitlines()) == 1 and "Traceback" not in p.stderr
    assert n_entries(db) == 1


@pytest.mark.slow
def test_two_processes_adding_at_once_lose_nothing(tmp_path):
    db = tmp_path / "h.sqlite"
    files = weekly(tmp_path, weeks=12)
    procs = []
    for part, machine in ((files[0::2], "M1"), (files[1::2], "M2")):
        script = ";".join(
            ["from volerr.history.run import add"]
            + [f"add({str(db)!r}, {machine!r}, [{str(f)!r}], {d!r}, 30.0)" for f, d in part])
        procs.append(subprocess.Popen([sys.executable, "-c", script],
                                      stderr=subprocess.PIPE, text=True))
    errs = [p.communicate(timeout=300)[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], errs
    assert n_entries(db, "M1") == 6 and n_entries(db, "M2") == 6


def test_sqlite_and_postgresql_show_the_same(tmp_path, capsys, pg_db):
    files = weekly(tmp_path, weeks=16, jump_week=9)
    sq = tmp_path / "h.sqlite"
    add_all(sq, "DMU50 #1", files, capsys)
    add_all(pg_db, "DMU50 #1", files, capsys)
    outs = []
    for db, name in ((sq, "s.json"), (pg_db, "p.json")):
        code, out, err = run(["history", "show", "--db", db, "--machine", "DMU50 #1",
                              "--tolerance", "EX0C=12 um", "--json", tmp_path / name], capsys)
        assert code == 0, err
        outs.append(((tmp_path / name).read_bytes(), out))
    assert outs[0] == outs[1]
    assert len(json.loads(outs[0][0])["events"]) == 1


@pytest.mark.slow
def test_postgresql_two_processes_and_refusals(tmp_path, capsys, pg_db):
    files = weekly(tmp_path, weeks=8)
    procs = []
    for part, machine in ((files[0::2], "M1"), (files[1::2], "M2")):
        script = ";".join(
            ["from volerr.history.run import add"]
            + [f"add({pg_db!r}, {machine!r}, [{str(f)!r}], {d!r}, 30.0)" for f, d in part])
        procs.append(subprocess.Popen([sys.executable, "-c", script],
                                      stderr=subprocess.PIPE, text=True))
    errs = [p.communicate(timeout=300)[1] for p in procs]
    assert [p.returncode for p in procs] == [0, 0], errs
    assert len(Store(pg_db).entries("M1")) == 4 and len(Store(pg_db).entries("M2")) == 4
    code, _, err = run(["history", "add", "--db", pg_db, "--machine", "M'1", "--date",
                        "2025-01-01", files[0][0]], capsys)
    assert code == 2 and len(Store(pg_db).entries("M1")) == 4
    bad = pg_db.rsplit(":", 1)[0] + ":1/none"
    code, _, err = run(["history", "show", "--db", bad, "--machine", "M1"], capsys)
    assert code == 2 and "cannot connect" in err and len(err.strip().splitlines()) == 1


def test_postgresql_locked_one_line_nothing_lost(tmp_path, capsys, pg_db):
    import psycopg

    from volerr.history.store import _PG_LOCK_KEY

    files = weekly(tmp_path, weeks=2)
    add_all(pg_db, "M1", files[:1], capsys)
    with psycopg.connect(pg_db.replace("postgresql://", "postgresql://", 1)) as holder:
        holder.execute("SELECT pg_advisory_xact_lock(%s)", (_PG_LOCK_KEY,))
        code, _, err = run(["history", "add", "--db", pg_db, "--machine", "M1", "--date",
                            files[1][1], "--wait", "0.3", files[1][0]], capsys)
        holder.rollback()
    assert code == 2 and "locked" in err and len(err.strip().splitlines()) == 1, err
    assert len(Store(pg_db).entries("M1")) == 1


def test_a_combination_of_the_reference_is_a_parameter_of_the_history(tmp_path, capsys):
    """A calibration that determines only EY0B + EY0C (written as EY0B): a check's change of
    EY0B is a change of that combination."""
    ref = write_cal(tmp_path / "ref.json", {"EX0C": 1.0}, {"EX0C": 0.1}, extra={
        "unidentifiable": ["EY0B", "EY0C"],
        "combinations": [{"expression": "EY0B + EY0C", "value": -18.0, "unit": "um",
                          "std": 0.1, "written_as": "EY0B"}]})
    chk = _check_json(tmp_path / "c.json", [{"parameter": "EY0B", "change": 0.8, "unit": "um",
                                             "std": 0.2, "combination": "EY0B + EY0C"}],
                      ["EX0C"])
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", [(ref, "2025-01-06"), (chk, "2025-01-13")], capsys)
    e = Store(str(db)).entries("M1")
    assert e[0].values["EY0B"].status == "combination"
    assert e[1].values["EY0B"].value == pytest.approx(-17.2, abs=1e-12)


def test_an_unchanged_parameter_is_stored_with_the_checks_number(tmp_path, capsys):
    """A check JSON lists unchanged parameters by name; its ``parameters`` block carries the
    change it measures with the parameter free and the uncertainty of "no change": stored as
    the reference's value plus that change with that std (before: no value)."""
    (ref, d0), = weekly(tmp_path, weeks=1)
    chk = tmp_path / "c.json"
    chk.write_text(json.dumps({
        "layout": "DMU50", "verdict": "changed", "unchanged": ["EX0C", "EA0C"],
        "changed": [{"parameter": "EY0C", "change": 4.0, "unit": "um", "std": 0.3}],
        "volumetric_change_um": {"max": 4.0, "rms": 4.0},
        "parameters": {"EX0C": {"value": 5.1, "unit": "um", "std": 0.1, "status": "unchanged",
                                "change": -0.07, "change_std": 0.25},
                       "EA0C": {"value": 10.0, "unit": "urad", "std": 1.0,
                                "status": "unchanged", "change": None, "change_std": None},
                       "EY0C": {"value": 1.0, "unit": "um", "std": 0.3, "status": "changed",
                                "change": 4.0, "change_std": 0.3}}}))
    db = tmp_path / "h.sqlite"
    add_all(db, "M1", [(ref, d0), (chk, "2025-02-01")], capsys)
    e = Store(str(db)).entries("M1")
    refv = json.loads(ref.read_text())["parameters"]
    x = e[1].values["EX0C"]
    assert x.status == "unchanged" and x.std == 0.25 and x.change == -0.07
    assert x.value == pytest.approx(refv["EX0C"]["value"] - 0.07, abs=1e-12)
    assert e[1].values["EA0C"].value is None            # not seen by the check: no number
    assert e[1].values["EY0C"].value == pytest.approx(refv["EY0C"]["value"] + 4.0, abs=1e-12)


def test_a_carrier_only_in_the_covariance_block_is_accepted(tmp_path, capsys):
    """A reference whose ``parameters`` lack EY0B (it carries EY0B + EY0C) and whose
    ``combinations`` entry states no value (or that is absent): EY0B's value and std come from
    the ``covariance`` block, and a check that changed EY0B is stored (before: refused, 'the
    check names EY0B, which its reference calibration does not determine')."""
    cov = {"names": ["EX0C", "EY0B"], "units": ["um", "um"], "values": [1.0, -18.0],
           "matrix": [[0.01, 0.002], [0.002, 0.04]]}
    chk = _check_json(tmp_path / "c.json", [{"parameter": "EY0B", "change": 0.8, "unit": "um",
                                             "std": 0.2, "combination": "EY0B + EY0C"}],
                      ["EX0C"])
    for i, combos in enumerate(([{"expression": "EY0B + EY0C", "written_as": "EY0B"}], [])):
        ref = write_cal(tmp_path / f"ref{i}.json", {"EX0C": 1.0}, {"EX0C": 0.1},
                        extra={"covariance": cov, "combinations": combos})
        db = tmp_path / f"h{i}.sqlite"
        add_all(db, "M1", [(ref, "2025-01-06"), (chk, "2025-01-13")], capsys)
        e = Store(str(db)).entries("M1")
        assert e[0].values["EY0B"].value == -18.0 and e[0].values["EY0B"].std == 0.2
        assert e[1].values["EY0B"].value == pytest.approx(-17.2, abs=1e-12)
        assert e[1].values["EY0B"].status == "changed"
