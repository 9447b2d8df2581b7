"""Result files for the history tests: calibrate-like JSONs of a simulated DMU50 whose
planted parameter values are known (values in um / urad, as ``volerr calibrate --json``)."""

import datetime as dt
import json
import os

import numpy as np
import pytest

from volerr.cli import main

START = dt.date(2025, 1, 6)


def write_cal(path, values: dict, std: dict, layout="DMU50", extra=None):
    doc = {"layout": layout,
           "parameters": {n: {"value": float(v), "unit": "urad" if n[1] in "ABC" else "um",
                              "std": float(std[n])} for n, v in values.items()},
           "unidentifiable": []}
    doc.update(extra or {})
    path.write_text(json.dumps(doc))
    return path


def weekly(tmp_path, weeks=21, seed=1, drift=0.3, jump=4.0, jump_week=12, u=0.2):
    """``[(file, date)]``: weekly calibrations, EX0C drifting by ``drift`` um/week, EY0C
    jumping by ``jump`` um at ``jump_week``, EA0C constant; readings' noise ``u`` (um), 5 u
    (urad)."""
    rng = np.random.default_rng(seed)
    out = []
    for w in range(weeks):
        vals = {"EX0C": 5 + drift * w + rng.normal(0, u),
                "EY0C": -3 + (jump if w >= jump_week else 0) + rng.normal(0, u),
                "EA0C": 10 + rng.normal(0, 5 * u)}
        f = write_cal(tmp_path / f"cal{w:02d}.json", vals,
                      {"EX0C": u, "EY0C": u, "EA0C": 5 * u})
        out.append((f, (START + dt.timedelta(weeks=w)).isoformat()))
    return out


def run(args, capsys):
    code = main([str(a) for a in args])
    out, err = capsys.readouterr()
    return code, out, err


def add_all(db, machine, files, capsys):
    for f, d in files:
        code, _, err = run(["history", "add", "--db", db, "--machine", machine, "--date", d, f],
                           capsys)
        assert code == 0, err


@pytest.fixture
def pg_url():
    url = os.environ.get("VOLERR_TEST_PG_URL")
    if not url:
        pytest.skip("VOLERR_TEST_PG_URL is not set: no PostgreSQL server (.ci/run starts one)")
    pytest.importorskip("psycopg", reason="psycopg is not installed (pip install -e '.[test]')")
    return url


@pytest.fixture
def pg_db(pg_url):
    """A fresh database on the test server (dropped afterwards): its URL."""
    import uuid

    import psycopg

    name = "volerr_t_" + uuid.uuid4().hex[:12]
    with psycopg.connect(pg_url.replace("postgresql://", "postgresql://", 1),
                         autocommit=True) as conn:
        conn.execute(f"CREATE DATABASE {name}")
    base = pg_url.rsplit("/", 1)[0]
    yield f"{base}/{name}"
    with psycopg.connect(pg_url, autocommit=True) as conn:
        conn.execute(f"DROP DATABASE IF EXISTS {name} WITH (FORCE)")
