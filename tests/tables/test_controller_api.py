"""The controller capability as an API (issue 42 item 4): ``volerr.controller_export`` /
``controller_import`` return result objects; the command is argparse and one call of them,
so the API's texts, JSON and console text are the command's."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

import volerr
from volerr.cli import main


@pytest.fixture(scope="module")
def errors_mb1(tmp_path_factory):
    from volerr.cmm.examples import write_example_errors

    d = tmp_path_factory.mktemp("ctl") / "errors_MB1"
    write_example_errors(d, "MB1")
    return d


@pytest.mark.parametrize("fmt", ["fanuc", "isg"])
def test_the_api_is_the_command(fmt, errors_mb1, tmp_path, capsys):
    out, js = tmp_path / f"cmd_{fmt}.txt", tmp_path / f"cmd_{fmt}.json"
    capsys.readouterr()
    assert main(["controller", "export", "MB1", "--errors", str(errors_mb1), "--format", fmt,
                 "--out", str(out), "--json", str(js)]) == 0
    printed = capsys.readouterr().out
    r = volerr.controller_export("MB1", errors_mb1, format=fmt)      # nothing written
    assert set(tmp_path.iterdir()) == {out, js}
    assert list(r.files.values()) == [out.read_text()]
    assert r.to_dict() == json.loads(js.read_text())
    assert r.summary().replace("(not written)", str(out)) == printed.rstrip("\n")
    written = volerr.controller_export("MB1", errors_mb1, format=fmt,
                                       out=tmp_path / "api.txt")
    assert (tmp_path / "api.txt").read_bytes() == out.read_bytes()
    assert written.summary().replace(str(tmp_path / "api.txt"), str(out)) == \
        printed.rstrip("\n")


def test_the_table_is_what_is_left_against_none(errors_mb1):
    """Rows before/left max/rms in um, recomputed here from the grid the result holds."""
    r = volerr.controller_export("MB1", errors_mb1, format="sinumerik-lec", grid=5)
    b = np.linalg.norm(r.left.before, axis=1) * 1e3
    a = np.linalg.norm(r.left.after, axis=1) * 1e3
    rows = r.table()
    rows = rows.to_dict("records") if hasattr(rows, "to_dict") else [x._asdict() for x in rows]
    got = {x["name"]: x["value"] for x in rows}
    assert got["before_max"] == pytest.approx(b.max(), rel=1e-12)
    assert got["left_rms"] == pytest.approx(np.sqrt(np.mean(a ** 2)), rel=1e-12)
    assert {x["unit"] for x in rows} == {"um"} and r.left.positions.shape[0] == 125
    assert set(r.figures()) == {"left"}


def test_worse_than_none_at_one_nanometre():
    from volerr.tables.controller_tables import worse_than_none

    base = {"before_um": {"max": 10.0, "rms": 5.0}, "left_um": {"max": 10.0, "rms": 5.0}}
    assert not worse_than_none(base)
    assert not worse_than_none({**base, "left_um": {"max": 10.0009, "rms": 5.0009}})
    assert worse_than_none({**base, "left_um": {"max": 10.0011, "rms": 1.0}})
    assert worse_than_none({**base, "left_um": {"max": 1.0, "rms": 5.0011}})


def test_a_refused_export_writes_nothing_and_says_one_line(errors_mb1, tmp_path):
    with pytest.raises(volerr.InputError) as e:
        volerr.controller_export("MB1", None, format="fanuc", out=tmp_path / "t.txt")
    assert str(e.value) == "--errors DIR is needed for --format fanuc"
    assert not list(tmp_path.iterdir())


def test_import_reads_back_what_export_wrote(errors_mb1, tmp_path):
    """ISG holds every parameter: the tables read back equal the error directory's."""
    from volerr.tables.table import read_error_dir

    volerr.controller_export("MB1", errors_mb1, format="isg", out=tmp_path / "m.csv")
    r = volerr.controller_import("MB1", tmp_path / "m.csv", out=tmp_path / "back")
    tables, (consts, _, _) = read_error_dir(errors_mb1, ("X", "Y", "Z"))
    assert set(r.tables) == set(tables) and set(r.constants) == set(consts)
    for a, t in tables.items():
        for name, v in t.values.items():
            np.testing.assert_allclose(r.tables[a].values[name], v, rtol=1e-9, atol=1e-12)
    assert sorted(p.name for p in (tmp_path / "back").iterdir()) == [
        "X.csv", "Y.csv", "Z.csv", "constants.csv"]
    assert r.summary().startswith("MB1: read ") and str(tmp_path / "back") in r.summary()
    assert len(r.table()) == sum(len(t.positions) * len(t.values) for t in tables.values()) \
        + len(consts)
