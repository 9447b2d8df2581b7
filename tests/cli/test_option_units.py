"""Options with units and dates (issue 43 item 5): one quantity parser and one date parser
(:mod:`volerr.units`) behind every ``--tolerance`` and ``--date``.

A value whose unit the option does not state needs it (``history show --tolerance EX0C=22``
is refused); a unit given is converted (factors derived here from their definitions, not
read from the code); a date after today, or not written YYYY-MM-DD, is refused.  Each
refusal: exit 2, one stderr line naming the option and the mistake, nothing written."""

from __future__ import annotations

import datetime as dt
import json
import math
from types import SimpleNamespace

import numpy as np
import pytest

from volerr.cli import main
from volerr.errors import InputError
from volerr.units import convert, parse_assignments, parse_date, parse_quantity

from tests.cli.test_shop_defects import write_run
from tests.history.conftest import weekly

FUTURE = (dt.datetime.now(dt.timezone.utc).date() + dt.timedelta(days=2)).isoformat()
MALFORMED = ["2025-2-1", "31.12.2025", "2025-13-01", "2025-02-30", "yesterday", "20250201"]

#: 1 arcsec = pi / (180 * 3600) rad; 1 deg = pi / 180 rad (in urad); 1 um/m = 1e-6 = 1 urad
ARCSEC_URAD = math.pi / 648000 * 1e6
DEG_URAD = math.pi / 180 * 1e6


def one_line(capsys, code, *fragments):
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in err, err
    for f in fragments:
        assert f in lines[0], lines[0]
    return lines[0]


def only(folder, *names):
    assert sorted(p.name for p in folder.iterdir()) == sorted(names)


# ------------------------------------------------------------------------ the parsers
@pytest.mark.parametrize("text, value, unit", [
    ("22 um", 22.0, "um"), ("22um", 22.0, "um"), ("22 µm", 22.0, "um"), (" 0.5 mm ", 0.5, "mm"),
    ("5 urad", 5.0, "urad"), ("5 μrad", 5.0, "urad"), ("1e1 arcsec", 10.0, "arcsec"),
    ("3 um/m", 3.0, "um/m"), (".25 mrad", 0.25, "mrad")])
def test_a_number_and_its_unit(text, value, unit):
    assert parse_quantity(text, "--x") == (value, unit)


@pytest.mark.parametrize("given, unit, to, expected", [
    (0.015, "mm", "um", 15.0), (250.0, "nm", "um", 0.25), (2.0, "arcsec", "urad", 2 * ARCSEC_URAD),
    (0.01, "mrad", "urad", 10.0), (1.0, "deg", "urad", DEG_URAD), (7.0, "um/m", "urad", 7.0),
    (0.002, "mm/m", "urad", 2.0), (1.0, "m", "mm", 1000.0)])
def test_conversions_are_the_units_definitions(given, unit, to, expected):
    assert convert(given, unit, to) == pytest.approx(expected, rel=1e-12)


@pytest.mark.parametrize("text, fragment", [
    ("22", "the value needs its unit, e.g. 22 um or 5 urad"), ("22 furlong", "'furlong'"),
    ("1e999 um", "not a finite number"), ("nan um", "a number and its unit"),
    ("-3 um", "positive"), ("0 um", "positive"), ("", "a number and its unit"),
    ("22 u m", "a number and its unit")])
def test_quantities_refused_in_one_line(text, fragment):
    with pytest.raises(InputError) as exc:
        parse_quantity(text, f"--tolerance EX0C={text}")
    msg = str(exc.value)
    assert msg.startswith(f"--tolerance EX0C={text}") and fragment in msg and "\n" not in msg


def test_an_option_that_states_its_unit_keeps_bare_numbers():
    assert parse_quantity("12", "--t", default_unit="um") == (12.0, "um")
    with pytest.raises(InputError, match="urad is a unit of angle, not of length"):
        parse_quantity("12 urad", "--t", default_unit="um", kinds=("length",))
    with pytest.raises(InputError, match="not a unit of urad"):
        convert(3.0, "um", "urad")
    assert parse_assignments("EX0C=20 um; EA0C = 5 urad|map=0.03 mm", "--tolerance") == [
        ("EX0C", (20.0, "um")), ("EA0C", (5.0, "urad")), ("map", (0.03, "mm"))]
    for text, word in (("EX0C=1 um,EX0C=2 um", "given twice"), ("EX0C", "NAME=VALUE UNIT"),
                       (" , ", "no value")):
        with pytest.raises(InputError, match=word):
            parse_assignments(text, "--tolerance")


def test_dates():
    assert parse_date("2024-02-29") == "2024-02-29"
    today = dt.datetime.now(dt.timezone.utc).date().isoformat()
    assert parse_date(today) == today
    with pytest.raises(InputError, match=f"^--date {FUTURE} is in the future"):
        parse_date(FUTURE)
    for bad in MALFORMED:
        with pytest.raises(InputError, match="YYYY-MM-DD"):
            parse_date(bad)


# ------------------------------------------------------------------------ history show
@pytest.fixture(scope="module")
def history(tmp_path_factory):
    """A history of 8 weekly calibrations of machine M1 (made once for these tests; read
    only)."""
    from volerr.history.run import add

    d = tmp_path_factory.mktemp("history")
    db = d / "h.sqlite"
    for f, date in weekly(d, weeks=8, seed=3):
        add(str(db), "M1", [f], date)
    return db


def _show(db, tol, out=None):
    extra = ["--json", str(out)] if out else []
    return main(["history", "show", "--db", str(db), "--machine", "M1", "--tolerance", tol,
                 *extra])


@pytest.mark.parametrize("tol, fragment", [
    ("EX0C=22", "--tolerance EX0C=22: the value needs its unit, e.g. 22 um or 5 urad"),
    ("EX0C=22 um,EA0C=5", "--tolerance EA0C=5: the value needs its unit"),
    ("EX0C=22 urad", "given in urad, which is not a unit of um"),
    ("EA0C=3 mm", "given in mm, which is not a unit of urad"),
    ("EX0C=22 furlong", "given in furlong, which is not a unit of um"), ("EX0C=inf um", "--tolerance EX0C=inf um"),
    ("map=30", "map=30: the value needs its unit"), ("map=30 urad", "map=VALUE um")])
def test_history_tolerance_needs_its_unit(tmp_path, capsys, history, tol, fragment):
    capsys.readouterr()
    out = tmp_path / "s.json"
    one_line(capsys, _show(history, tol, out), fragment)
    assert not out.exists()


def test_history_tolerance_in_other_units_is_the_same_tolerance(tmp_path, capsys, history):
    capsys.readouterr()
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert _show(history, "EX0C=15 um,EA0C=12 urad", a) == 0
    assert _show(history, f"EX0C=0.015 mm,EA0C={12 / ARCSEC_URAD!r} arcsec", b) == 0
    fa, fb = (json.loads(p.read_text())["forecast"] for p in (a, b))
    for name in ("EX0C", "EA0C"):
        assert fb[name]["tolerance"] == pytest.approx(fa[name]["tolerance"], rel=1e-12)
        assert fb[name]["date"] == fa[name]["date"]
    assert fa["EX0C"]["tolerance"] == 15.0 and fa["EA0C"]["unit"] == "urad"
    # the volumetric error's tolerance, a length, in um (the map forecast itself: test_show)
    from volerr.history.run import parse_tolerances

    assert parse_tolerances("map=0.04 mm") == {"map": (pytest.approx(40.0, rel=1e-12), "um")}


def test_history_tolerance_in_a_parameters_own_unit(tmp_path, capsys):
    """A slope parameter (unit um/mm, as calibrate reports a first-order term) takes its
    tolerance in that unit; a length is not its unit."""
    import volerr
    from volerr.history.run import add

    db = tmp_path / "h.sqlite"
    for w in range(4):
        f = tmp_path / f"c{w}.json"
        f.write_text(json.dumps({"layout": "DMU50", "parameters": {"EXX@slope": {
            "value": 0.1 + 0.01 * w, "unit": "um/mm", "std": 0.002}}}))
        add(str(db), "M1", [f], (dt.date(2025, 1, 6) + dt.timedelta(weeks=w)).isoformat())
    h = volerr.history.show(str(db), "M1", "EXX@slope=0.5 um/mm")
    assert h.forecast["EXX@slope"]["tolerance"] == 0.5
    assert h.forecast["EXX@slope"]["unit"] == "um/mm"
    for tol, word in (("EXX@slope=0.5 um", "given in um, which is not a unit of um/mm"),
                      ("EXX@slope=0.5", "the value needs its unit"),
                      ("EXX@slope=0.5 um/mm!", "unknown")):
        with pytest.raises(InputError, match=word):
            volerr.history.show(str(db), "M1", tol)


# ------------------------------------------------------------------------ every --date
def _errors_dir(tmp_path):
    from volerr.tables import ErrorTable, write_error_dir

    nodes = np.linspace(0, 900, 10)
    d = tmp_path / "err"
    write_error_dir(d, {"X": ErrorTable("X", nodes, {"EXX": 1e-6 * nodes},
                                        std={"EXX": np.full(10, 0.5e-3)})})
    return d


def _commands(tmp_path, date):
    """Every command with a --date option, given ``date``, each writing a --json."""
    run = write_run(tmp_path / "run.csv")
    cal = tmp_path / "cal.json"
    cal.write_text(json.dumps({"layout": "DMU50", "parameters": {
        "EX0C": {"value": 1.0, "unit": "um", "std": 0.1}}}))
    drift = tmp_path / "drift.csv"
    drift.write_text("t_s,d_x_um\n0,0\n60,1\n")
    out = str(tmp_path / "out.json")
    return {
        "iso230-2": ["iso230-2", str(run), "--json", out, "--date", date],
        "iso10360": ["iso10360", "MB1", "--errors", str(_errors_dir(tmp_path)), "--json", out,
                     "--date", date],
        "iso230-3": ["iso230-3", str(drift), "--json", out, "--date", date],
        "check": ["check", "DMU50", "--reference", str(cal), str(run), "--json", out,
                  "--date", date],
        "history add": ["history", "add", "--db", str(tmp_path / "h.sqlite"), "--machine",
                        "M1", "--date", date, str(cal)],
    }


@pytest.mark.parametrize("command", ["iso230-2", "iso10360", "iso230-3", "check",
                                     "history add"])
@pytest.mark.parametrize("date", [FUTURE, "2025-13-01", "2025-2-1"])
def test_every_date_option_refuses_the_future_and_malformed(tmp_path, capsys, command, date):
    args = _commands(tmp_path, date)[command]
    before = sorted(p.name for p in tmp_path.iterdir())
    line = one_line(capsys, main(args), "--date")
    assert ("is in the future" in line) if date == FUTURE else ("YYYY-MM-DD" in line)
    assert sorted(p.name for p in tmp_path.iterdir()) == before     # nothing written


def test_a_past_date_is_the_certificates_date(tmp_path, capsys):
    args = _commands(tmp_path, "2024-05-06")["iso230-2"]
    assert main(args) == 0
    assert json.loads((tmp_path / "out.json").read_text())["identification"]["date"] == \
        "2024-05-06"


# ------------------------------------------------------------------------ iso230-2, check
def test_iso230_2_tolerance_bare_um_or_with_a_length_unit(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv")
    docs = []
    for k, tol in enumerate(("A=10,E=8", "A=0.01 mm,E=8 um", "A=10000 nm, E=8um")):
        out = tmp_path / f"o{k}.json"
        assert main(["iso230-2", str(run), "--tolerance", tol, "--json", str(out)]) == 0
        docs.append(json.loads(out.read_text()))
    assert docs[0]["tolerance_um"] == {"A": 10.0, "E": 8.0}
    assert docs[1]["tolerance_um"] == pytest.approx(docs[0]["tolerance_um"], rel=1e-12)
    assert docs[2]["tolerance_um"] == pytest.approx(docs[0]["tolerance_um"], rel=1e-12)
    assert docs[1]["verdicts"] == docs[0]["verdicts"]
    capsys.readouterr()
    out = tmp_path / "x.json"
    one_line(capsys, main(["iso230-2", str(run), "--tolerance", "A=10 urad", "--json",
                           str(out)]), "--tolerance A=10 urad", "not of length")
    assert not out.exists()


def test_check_tolerance_converts_to_the_parameters_unit():
    from volerr.check._tolerance import parse

    ref = SimpleNamespace(names=["EX0C", "EA0C", "EXX@slope"], units=["um", "urad", "um/m^2"])
    got = parse("EX0C=0.03 mm, EA0C=2 arcsec, EXX@slope=4 um/m^2, map=0.05 mm", ref)
    assert got == pytest.approx({"EX0C": 30.0, "EA0C": 2 * ARCSEC_URAD, "EXX@slope": 4.0,
                                 "map": 50.0}, rel=1e-12)
    # issue 43 item 5: every value needs its unit (as history show): a bare one is refused
    for bare in ("EX0C=30", "EXX@slope=4", "map=30"):
        with pytest.raises(InputError, match="needs its unit"):
            parse(bare, ref)
    for text, word in (("EX0C=3 urad", "not a unit of um"), ("EA0C=1 mm", "not a unit of urad"),
                       ("map=3 urad", "not a unit of um"), ("EX0C=1e999 um", "finite")):
        with pytest.raises(InputError, match=word):
            parse(text, ref)


def test_iso10360_mpe_bare_um_or_with_a_length_unit(tmp_path, capsys):
    from volerr.uncertainty.iso10360 import parse_spec

    assert parse_spec("E0=0.0015 mm + L/333, PFTU=2 um", "--mpe") == parse_spec(
        "E0=1.5+L/333,PFTU=2", "--mpe")
    err = _errors_dir(tmp_path)
    docs = []
    for k, mpe in enumerate(("E0=1.5+L/333", "E0=1.5 um + L/333", "E0=1500nm+L/333")):
        out = tmp_path / f"m{k}.json"
        assert main(["iso10360", "MB1", "--errors", str(err), "--mpe", mpe, "--json",
                     str(out)]) == 0
        doc = json.loads(out.read_text())
        doc.pop("identification")   # its report id and method hash the options as typed
        docs.append(doc)
    assert docs[1] == docs[0] and docs[2] == docs[0]
    capsys.readouterr()
    out = tmp_path / "x.json"
    for mpe, word in (("E0=1.5 urad+L/333", "expected"), ("E0=1e999+L/333", "finite")):
        one_line(capsys, main(["iso10360", "MB1", "--errors", str(err), "--mpe", mpe,
                               "--json", str(out)]), "--mpe", word)
        assert not out.exists()
