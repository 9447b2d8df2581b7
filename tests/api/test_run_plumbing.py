"""issue 42 item 4: what a command did beyond argparse now lives in the API -- the
identification from a plain dict (``certificate.from_options``), the outputs declared from
the options (``fileio.planned_outputs``), the checks before the outputs (``check`` forms,
``plan`` folders, ``identify --origin``), ``simulate``'s file -- and the API refuses or
writes exactly what the command does."""

import pytest

import volerr
from volerr.cli import main
from helpers.refusals import api_error, command_error


# --- the identification of a run from its options as a plain dict ----------------------------
def _parsed(argv):
    from volerr.cli import build_parser

    return build_parser(argv[0]).parse_args(argv)


def test_identification_from_the_options_dict(tmp_path):
    from volerr.certificate import from_options

    args = _parsed(["iso230-2", "run.csv", "--axis", "Y", "--machine", "DMU50-2", "--operator",
                    "A. Person", "--date", "2026-01-15", "--json", str(tmp_path / "r.json")])
    ident = from_options(vars(args), ["run.csv"])
    assert (ident.machine, ident.operator, ident.date) == ("DMU50-2", "A. Person", "2026-01-15")
    assert ident.stated
    method = ident.method
    assert method["command"] == "volerr iso230-2" and method["version"] == volerr.__version__
    # the method: the options that shape the result, not the outputs, not the identification's
    # own fields, not the input files (hashed into the report id instead), not private keys
    assert method["options"]["axis"] == "Y"
    for not_method in ("json", "machine", "operator", "date", "runs", "func", "_ident_prog"):
        assert not_method not in method["options"], not_method
    # the same options and files: the same report id; another option value: another id
    assert from_options(vars(args), ["run.csv"]).report_id == ident.report_id
    args.axis = "Z"
    assert from_options(vars(args), ["run.csv"]).report_id != ident.report_id


def test_identification_date_refused_alike(capsys, tmp_path):
    from volerr.certificate import from_options

    said = command_error(["iso230-2", tmp_path / "run.csv", "--date", "2026-13-40"], capsys)
    assert "--date" in said
    assert api_error(lambda: from_options({"date": "2026-13-40"})) == said


# --- outputs declared from the options, in the order of the refusals ---------------------------
def test_planned_outputs_refuses_in_declaration_order(tmp_path):
    from volerr.fileio import planned_outputs

    missing = tmp_path / "no-such-folder"
    options = {"json": str(missing / "r.json"), "html": None, "force": False}
    said = api_error(lambda: planned_outputs(options, [], first={"--out": str(missing / "o")}))
    assert said.startswith("--out"), said             # first: before the report outputs
    said = api_error(lambda: planned_outputs(options, [], **{"--out": str(missing / "o")}))
    assert said.startswith("--json"), said            # more: after them


def test_planned_outputs_never_over_an_input(tmp_path):
    from volerr.fileio import planned_outputs

    data = tmp_path / "data.csv"
    data.write_text("x\n1\n")
    said = api_error(lambda: planned_outputs({"json": str(data)}, [data]))
    assert "--json" in said and "input" in said
    assert data.read_text() == "x\n1\n"


# --- volerr check: its two forms -----------------------------------------------------------------
def test_check_form_split_and_refused_alike(capsys, tmp_path):
    from volerr.check._run import command_form

    # the files after --reference CAL.json join the words
    assert command_form(["DMU50", "a.csv"], ["ref.json", "b.csv"], {}) == (
        False, ["DMU50", "a.csv", "b.csv"], "ref.json")
    assert command_form(["plan", "DMU50"], ["ref.json"], {"tolerance": None}) == (
        True, ["plan", "DMU50"], "ref.json")
    ref = tmp_path / "ref.json"
    said = command_error(["check", "plan", "DMU50", "--reference", ref, "--tolerance", "1"],
                          capsys)
    assert said == "--tolerance belongs to 'volerr check LAYOUT FILE...'"
    assert api_error(lambda: command_form(["plan", "DMU50"], [str(ref)],
                                           {"tolerance": "1"})) == said
    said = command_error(["check", "DMU50", "a.csv", "--reference", ref, "--minutes", "5"],
                          capsys)
    assert said == "--minutes belongs to 'volerr check plan'"
    said = command_error(["check", "plan", "DMU50", "MB1", "--reference", ref], capsys)
    assert said.startswith("check plan: give one LAYOUT (usage: volerr check plan LAYOUT")


# --- plan / check plan: the output folder checked before anything is computed -------------------
def test_plan_folder_refused_alike(capsys, tmp_path):
    from volerr.plan.api import check_options

    taken = tmp_path / "plan-here"
    taken.write_text("a file, not a folder\n")
    said = command_error(["plan", "MB1", "--instrument", "sphere", "--readings", "100",
                           "--out", taken], capsys)
    assert said == f"--out {taken}: a file, not a folder"
    assert api_error(lambda: check_options(100, out=taken)) == said
    check_options(100)          # no folder given: nothing to check


def test_check_plan_without_out_refused_alike(capsys, tmp_path):
    from volerr.check._plan import check_plan_options

    said = command_error(["check", "plan", "DMU50", "--reference", tmp_path / "ref.json",
                           "--instrument", "sphere"], capsys)
    assert said == "check plan: give --out DIR"
    assert api_error(lambda: check_plan_options(["sphere"], out=None)) == said
    check_plan_options(["sphere"])     # the API's own call: no folder to check


# --- identify --origin: parsed and refused by identify() --------------------------------------
@pytest.mark.parametrize("origin", [["1", "2"], ["1", "2", "x"], ["1e9", "0", "0"]])
def test_identify_origin_refused_alike(origin, capsys, tmp_path):
    from volerr.identify.api import identify

    data = tmp_path / "tracker.csv"          # never read: the origin is refused first
    said = command_error(["identify", "MB1", data, "--axis", "X", "--out",
                           tmp_path / "X.csv", "--origin", *origin], capsys)
    assert said.startswith("--origin: ")
    assert api_error(lambda: identify("MB1", "X", data, origin=origin)) == said
    assert not (tmp_path / "X.csv").exists()


def test_identify_origin_forms():
    from volerr.identify.api import _origin

    assert _origin(None) is None
    assert _origin("layout") == "layout" and _origin(["layout"]) == "layout"
    assert _origin(["1", "2", "3"]) == [1.0, 2.0, 3.0]
    assert _origin("1,2,3") == [1.0, 2.0, 3.0]
    assert _origin((0.5, -2, 1e3)) == [0.5, -2.0, 1000.0]


# --- volerr simulate: the file the command writes is simulated_file's text ---------------------
@pytest.mark.parametrize("layout, instrument, extra, kw", [
    ("MB1", "deviations", ["--points", "40"], {"points": 40}),
    ("DMU50", "sphere", [], {})])
def test_simulate_file_as_the_command_writes_it(layout, instrument, extra, kw, capsys, tmp_path):
    from volerr.loop.simulate import simulated_file

    out = tmp_path / "sim.csv"
    assert main(["simulate", layout, "--out", str(out), "--instrument", instrument,
                 "--seed", "3", *extra]) == 0
    printed = capsys.readouterr().out
    text, line = simulated_file(layout, instrument, seed=3, **kw)
    assert out.read_text(encoding="utf-8") == text
    assert printed == f"{line} -> {out}\n"
    if instrument == "deviations":      # 40 points, one line each and the header
        assert line == "40 points of MB1" and len(text.splitlines()) == 41


# --- a result's outputs: its own first, then the report's ---------------------------------------
def test_write_outputs_writes_only_what_the_options_give(tmp_path):
    from volerr.fileio import planned_outputs
    from volerr.results import ResultMixin

    class Tiny(ResultMixin):
        data = {"parameters": {"a": {"value": 1.5, "std": 0.1, "unit": "um"}}}
        lines = ("one line",)

        def __init__(self):
            self.calls = []

        def write_json(self, path, inputs=()):
            self.calls.append("json")
            return super().write_json(path, inputs)

        def write_html(self, path, inputs=()):
            self.calls.append("html")
            return super().write_html(path, inputs)

        def _write_own(self, outs, options, inputs):
            self.calls.append("own")

    from volerr.certificate import Identification

    options = {"json": str(tmp_path / "t.json"), "html": None, "plot": None}
    res = Tiny()
    with planned_outputs(options, []) as outs:
        res.write_outputs(outs, options, Identification(), [])
    assert res.calls == ["own", "json"]         # no --html, no --plot given
    assert (tmp_path / "t.json").is_file() and not (tmp_path / "t.html").exists()
    assert (tmp_path / "t.json").read_text().startswith("{")
