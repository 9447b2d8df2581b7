"""Processes racing ``volerr history add`` (issue 43 item 6): every entry a process reports as
added is in the database afterwards, the database exists, a refused process leaves nothing
of its own behind and removes nothing of anyone else's.

Each round starts two (or three) ``python -m volerr history add`` processes at once on one
database: a new one (no file; for PostgreSQL a database without volerr's tables) or one
holding an entry already; the processes add to the same machine or to different machines;
they add the same result (one of them stores it, the others say "already stored" on the same
machine, or are refused on another machine: one result is one machine at one time) or each
its own result (all stored).  The expected outcome is derived from these rules, not from a
run: which process wins is free, what is in the database must follow from what they said."""

import hashlib
import os
import re
import subprocess
import sys
from pathlib import Path

import pytest

from volerr.history.store import Store

from .conftest import write_cal

ADD = [sys.executable, "-m", "volerr", "history", "add"]
DATE = "2025-03-03"
#: rounds started at once (each on its own database; the processes of a round race each other)
BATCH = 4
LINE = re.compile(r"(?P<src>\S+): calibration of DMU50 on (?P<date>\S+) for machine "
                  r"(?P<m>\S+): (?P<what>added|already stored)")


def rounds(n: int) -> list:
    """``(new, same_machine, same_result, n_processes)`` of each round: every combination of
    the first three, in turn; three processes every fifth round."""
    return [(i % 2 == 0, (i // 2) % 2 == 0, (i // 4) % 2 == 0, 3 if i % 5 == 4 else 2)
            for i in range(n)]


def _result(folder, name, value):
    return write_cal(folder / name, {"EX0C": value, "EA0C": 2.0 * value},
                     {"EX0C": 0.1, "EA0C": 0.5})


def start_round(tmp_path, db, i, new, same_machine, same_result, n):
    """Start one round's processes (all at once); returns ``(jobs, procs, seeded)``: per
    process (machine, file), the processes, and the (machine, file) stored before the round
    (an existing database: seeded in this process)."""
    from volerr.history.run import add

    folder = tmp_path / f"r{i:02d}"
    folder.mkdir()
    seeded = []
    if not new:
        seed = _result(folder, "seed.json", 100.0 + i)
        add(str(db), "M0", [seed], DATE)
        seeded.append(("M0", seed))
    shared = _result(folder, "shared.json", 1.0 + i)
    jobs = []
    for k in range(n):
        machine = "M1" if same_machine else f"M{k + 1}"
        f = shared if same_result else _result(folder, f"own{k}.json", 10.0 * (k + 1) + i)
        jobs.append((machine, f))
    procs = [subprocess.Popen(ADD + ["--db", str(db), "--machine", m, "--date", DATE, str(f)],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
             for m, f in jobs]
    return jobs, procs, seeded


def finish(jobs, procs) -> list:
    """(machine, file, returncode, stdout, stderr) of each process of a round."""
    reports = []
    for (m, f), p in zip(jobs, procs):
        out, err = p.communicate(timeout=600)
        reports.append((m, f, p.returncode, out, err))
    return reports


def race(tmp_path, dbs, plan, batch=BATCH) -> None:
    """Race the rounds of ``plan`` on the databases ``dbs`` (``batch`` rounds at a time,
    each on its own database) and check every round."""
    for b in range(0, len(plan), batch):
        started = [(dbs[i], plan[i], start_round(tmp_path, dbs[i], i, *plan[i]))
                   for i in range(b, min(b + batch, len(plan)))]
        for db, (new, same_m, same_r, n), (jobs, procs, seeded) in started:
            reports = finish(jobs, procs)
            if "://" not in str(db):
                assert Path(db).is_file(), f"{db}: the history is gone"
            check_round(db, reports, seeded, same_m, same_r)


def check_round(db, reports, seeded, same_machine, same_result):
    """What the processes said against what the database holds."""
    added, stored = set(seeded), {}
    for m, f, code, out, err in reports:
        assert code in (0, 2), err
        assert "Traceback" not in err and len(err.strip().splitlines()) <= 1, err
        if code == 2:
            # the only refusal a race may bring: the same result on another machine
            assert same_result and not same_machine and "one result is one" in err, err
            continue
        got = LINE.fullmatch(out.strip())
        assert got is not None and got["src"] == f.name and got["m"] == m, out
        assert got["date"] == DATE
        if got["what"] == "added":
            added.add((m, f))
    s = Store(str(db))
    for m in {m for m, *_ in reports} | {m for m, _ in seeded}:
        stored[m] = {e.sha256 for e in s.entries(m)}
    sha = {f: hashlib.sha256(f.read_bytes()).hexdigest() for _, f, *_ in reports}
    sha.update({f: hashlib.sha256(f.read_bytes()).hexdigest() for _, f in seeded})
    for m, f in added:                  # every entry reported as added is there
        assert sha[f] in stored[m], (m, f.name)
    # and nothing else: one entry per distinct result, on the machine that reported it
    assert sum(len(v) for v in stored.values()) == len(added)
    distinct = {f for _, f, *_ in reports}
    assert len(added) - len(seeded) == len(distinct)


@pytest.mark.slow
def test_sqlite_adders_racing_20_rounds_lose_nothing(tmp_path):
    plan = rounds(20)
    race(tmp_path, [tmp_path / f"h{i:02d}.sqlite" for i in range(len(plan))], plan)
    # no staging folder of any process left beside the histories
    assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


@pytest.mark.slow
def test_postgresql_adders_racing_lose_nothing(tmp_path, pg_url):
    import uuid

    import psycopg

    base = pg_url.rsplit("/", 1)[0]
    plan = rounds(8)
    names = ["volerr_r_" + uuid.uuid4().hex[:12] for _ in plan]
    try:
        with psycopg.connect(pg_url, autocommit=True) as conn:
            for name in names:
                conn.execute(f"CREATE DATABASE {name}")
        race(tmp_path, [f"{base}/{name}" for name in names], plan)
    finally:
        with psycopg.connect(pg_url, autocommit=True) as conn:
            for name in names:
                conn.execute(f"DROP DATABASE IF EXISTS {name} WITH (FORCE)")


def test_a_refused_first_add_leaves_no_file_and_keeps_a_racers_history(tmp_path,
                                                                        monkeypatch):
    """A first add that fails after its store was made (a check without its reference)
    leaves neither the history nor its staging folder; a history another process made in
    the meantime is never removed by a failing add."""
    import json

    from volerr.errors import InputError
    from volerr.history import store as st
    from volerr.history.run import add

    db = tmp_path / "h.sqlite"
    chk = tmp_path / "c.json"
    chk.write_text(json.dumps({"layout": "DMU50", "verdict": "unchanged", "changed": [],
                               "unchanged": ["EX0C"]}))
    with pytest.raises(InputError, match="no calibration"):
        add(str(db), "M1", [chk], DATE)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c.json"]
    # a racer creates the history while this add works in its staging folder: a failing
    # add leaves the racer's history and entry; a succeeding one adds to the racer's file
    racer = _result(tmp_path, "racer.json", 7.0)
    mine = _result(tmp_path, "mine.json", 8.0)
    real = st.add_to_new_file
    pending = [("M2", racer), ("M3", racer)]

    def racing(path, wait_s, work):
        if pending:
            m, f = pending.pop(0)
            done = real(path, wait_s, lambda s: s.add(m, [st_entry(f)], lambda e, x: None))
            assert done[0]
        return real(path, wait_s, work)

    def st_entry(f):
        from volerr.history import results

        e = results.read(f)
        e.date = DATE
        return e

    monkeypatch.setattr(st, "add_to_new_file", racing)
    with pytest.raises(InputError, match="no calibration"):
        add(str(db), "M1", [chk], DATE)
    assert db.is_file() and [e.source for e in Store(str(db)).entries("M2")] == ["racer.json"]
    db.unlink()
    pending[:] = [("M3", racer)]
    done = add(str(db), "M1", [mine], DATE)
    assert [(e.source, what) for e, what in done] == [("mine.json", "added")]
    s = Store(str(db))
    assert [e.source for e in s.entries("M3")] == ["racer.json"]
    assert [e.source for e in s.entries("M1")] == ["mine.json"]
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".")]


@pytest.mark.parametrize("existing", [False, True])
def test_a_unique_conflict_is_rolled_back_and_the_add_run_again(tmp_path, monkeypatch,
                                                                  existing):
    """A writer that breaks the unique SHA-256 (as one that did not take the lock would):
    its transaction is rolled back whole (:class:`Conflict`) and ``add`` runs again against
    what is stored, reporting what it then stores."""
    from volerr.history import store as st
    from volerr.history.run import add

    db = tmp_path / "h.sqlite"
    if existing:
        add(str(db), "M0", [_result(tmp_path, "seed.json", 3.0)], DATE)
    f = _result(tmp_path, "one.json", 5.0)
    real, calls = st.Store._insert, []

    def twice_on_first_call(self, conn, machine, entry):
        calls.append(entry.source)
        real(self, conn, machine, entry)
        if len(calls) == 1:
            real(self, conn, machine, entry)       # the same sha256 again: IntegrityError

    monkeypatch.setattr(st.Store, "_insert", twice_on_first_call)
    done = add(str(db), "M1", [f], DATE)
    assert [(e.source, what) for e, what in done] == [("one.json", "added")]
    assert calls == ["one.json", "one.json"]
    assert [e.source for e in Store(str(db)).entries("M1")] == ["one.json"]
    assert len(Store(str(db)).entries("M0")) == int(existing)


def test_a_killed_adders_staging_folder_is_removed_by_the_next_add(tmp_path):
    """A first add killed before it linked its file leaves its staging folder; the next add
    beside it removes it (its process is gone), and keeps that of a live process."""
    from volerr.fileio import _host
    from volerr.history.run import add

    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    dead = tmp_path / f".volerr-staging-{gone.pid}@{_host()}-abc"
    live = tmp_path / f".volerr-staging-{os.getppid()}@{_host()}-def"
    for d in (dead, live):
        d.mkdir()
        (d / "h.sqlite").write_bytes(b"")
    db = tmp_path / "h.sqlite"
    add(str(db), "M1", [_result(tmp_path, "one.json", 5.0)], DATE)
    assert not dead.exists() and live.is_dir() and db.is_file()
    assert [e.source for e in Store(str(db)).entries("M1")] == ["one.json"]
