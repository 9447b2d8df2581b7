"""``volerr history show --tolerance``: names matched as in every ``--tolerance`` of volerr
(:func:`volerr.units.match_name`): as written, or in any case when that names one parameter
of the history (``ex0c`` is ``EX0C``, ``MAP`` is ``map``); an unknown name refused in one line
naming the history's parameters, a name given twice in two cases refused."""

import json

from .conftest import add_all, run, write_cal


def test_names_in_any_case(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    cals = [(write_cal(tmp_path / f"c{i}.json", {"EX0C": 5.0 + i, "EA0C": 10.0},
                       {"EX0C": 0.2, "EA0C": 1.0}), f"2025-01-{6 + 7 * i:02d}") for i in range(3)]
    add_all(db, "M1", cals, capsys)
    code, _, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                        "ex0c=15um|MAP=30 um", "--json", tmp_path / "s.json"], capsys)
    assert code == 0, err
    forecast = json.loads((tmp_path / "s.json").read_text())["forecast"]
    assert sorted(forecast) == ["EX0C", "map"] and forecast["EX0C"]["tolerance"] == 15.0
    for tol, words in (("EXX=3 um", "--tolerance EXX: not a parameter of this history "
                                    "(EA0C, EX0C)"),
                       ("EX0C=3 um,ex0c=4 um", "--tolerance: ex0c given twice"),
                       ("map=3 um,MAP=4 um", "--tolerance: MAP given twice")):
        code, _, err = run(["history", "show", "--db", db, "--machine", "M1", "--tolerance",
                            tol], capsys)
        assert code == 2 and words in err and len(err.strip().splitlines()) == 1, (tol, err)
