"""``volerr.cmm.api.squareness``: the computation of ``volerr squareness`` as an API result.

The straightness tables come from the model's own volumetric error with only the squareness
set (an independent route: the layout's chain, not the reference-line fit), so the planted
values must come back; the command must print the result's summary and write its files."""

import numpy as np
import pytest

import volerr
from volerr.cmm.api import squareness
from volerr.errors import InputError
from volerr.tables.table import ErrorTable, read_error_dir, write_error_dir

TRUTH = {"EC0Y": 25e-6, "EB0Z": -40e-6, "EA0Z": 15e-6}   # rad
OTHER = {"EX0Y": 3e-3}                                    # a constant kept as it is, mm


@pytest.fixture(scope="module")
def tables_dir(tmp_path_factory):
    m = volerr.load("MB1")
    s = np.linspace(0, 400, 9)
    tables = {}
    for ax in ("X", "Y", "Z"):
        pos = {a: np.zeros_like(s) for a in m.axes}
        pos[ax] = s
        d = np.asarray(m.volumetric_error(pos, TRUTH))   # (N, 3), tool relative to workpiece
        tables[ax] = ErrorTable(ax, s, {f"E{c}{ax}": d[:, i] for i, c in enumerate("XYZ")})
    d = tmp_path_factory.mktemp("sq") / "in"
    write_error_dir(d, tables, OTHER)
    return d


def test_planted_squareness_comes_back(tables_dir, tmp_path):
    res = squareness("MB1", tables_dir, tables_are="component")
    for k, v in TRUTH.items():
        assert res.values[k] == pytest.approx(v, abs=1e-12), k
        assert res.data["squareness_urad"][k] == pytest.approx(v * 1e6, abs=1e-6), k
    assert res.data["tables_are"] == "component"
    # the written folder: the squareness beside the input's other constants, slopes removed
    res.write_dir(tmp_path / "out")
    tables, (consts, _, _) = read_error_dir(tmp_path / "out", axes=("X", "Y", "Z"))
    assert consts["EX0Y"] == pytest.approx(OTHER["EX0Y"])
    for k, v in TRUTH.items():
        assert consts[k] == pytest.approx(v, abs=1e-9), k
    assert np.allclose(tables["X"].values["EYX"], 0, atol=1e-9)
    # the contract: a short repr, a table row per squareness in urad
    assert len(repr(res)) < 200 and "EC0Y" in repr(res)
    rows = res.table()
    names = list(rows["name"]) if hasattr(rows, "columns") else [r.name for r in rows]
    assert sorted(names) == sorted(TRUTH)


def test_command_prints_the_summary_and_writes_the_json(tables_dir, tmp_path, capsys):
    from volerr.cli import main

    out, js = tmp_path / "o", tmp_path / "sq.json"
    assert main(["squareness", "MB1", str(tables_dir), "--out", str(out), "--json", str(js),
                 "--tables-are", "component"]) == 0
    res = squareness("MB1", tables_dir, tables_are="component")
    assert capsys.readouterr().out == res.summary() + f"\n-> {out}\n"
    import json

    assert json.loads(js.read_text()) == res.to_dict()


def test_no_straightness_pair_is_one_line(tmp_path):
    s = np.linspace(0, 400, 5)
    write_error_dir(tmp_path / "only_x", {"X": ErrorTable("X", s, {"EXX": 1e-6 * s})})
    with pytest.raises(InputError, match="no pair of straightness tables"):
        squareness("MB1", tmp_path / "only_x")
    with pytest.raises(InputError, match="does not exist"):
        squareness("MB1", tmp_path / "missing")
