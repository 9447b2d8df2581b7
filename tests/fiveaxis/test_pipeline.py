"""One compensation pipeline for ``volerr compensate`` and ``volerr.compensate`` (issue 42,
item 3): the API writes the command's bytes (a CRLF program stays CRLF), its JSON and console
text; the datum is checked and reported the same way; ``--tool-length`` is the tool offset
``(0, 0, -L)`` of axis-position blocks (checked on an independent exact chain of a head-head
machine whose B axis tilts the tool) or refused with one line where it cannot apply."""

import json

import numpy as np
import pytest
from helpers.error_dirs import write_errors
from helpers.fiveaxis_chain import tool2work
from test_compensate import cli, main_

import volerr
from volerr.errors import InputError
from volerr.fiveaxis.compensate import ErrorModel
from volerr.tables.functions import ErrorFunctions

L = 85.0        # tool length, mm


@pytest.fixture(scope="module")
def dmu(tmp_path_factory):
    """The DMU 50 example's error tables and the first 60 lines of its hemisphere program,
    also with CRLF line endings."""
    from volerr.fiveaxis.example import write_example

    d = tmp_path_factory.mktemp("dmu")
    ex = write_example(d, "DMU50")
    lines = ex["program"].read_text().splitlines()[:60]
    lf, crlf = d / "lf.nc", d / "crlf.nc"
    lf.write_bytes(("\n".join(lines) + "\n").encode())
    crlf.write_bytes(("\r\n".join(lines) + "\r\n").encode())
    return {"errors": ex["errors"], "lf": lf, "crlf": crlf, "n_lines": len(lines)}


def test_api_writes_the_commands_bytes_and_keeps_crlf(dmu, tmp_path):
    """Before: ``write_program`` wrote LF for a CRLF program the command kept as CRLF."""
    out, js = tmp_path / "cmd.nc", tmp_path / "cmd.json"
    code, so, se = main_("compensate", "DMU50", "--errors", dmu["errors"], dmu["crlf"],
                         "--out", out, "--json", js)
    assert code == 0, se
    res = volerr.compensate("DMU50", dmu["crlf"], dmu["errors"])
    api = res.write_program(tmp_path / "api.nc")
    data = api.read_bytes()
    assert data == out.read_bytes()
    # every line of the input ends CRLF in the output, none LF alone
    assert data.count(b"\r\n") == dmu["n_lines"] and data.count(b"\n") == dmu["n_lines"]
    # and the numbers were compensated (the output is not the input)
    assert data != dmu["crlf"].read_bytes()
    # the JSON byte for byte, the console text line for line
    assert res.write_json(tmp_path / "api.json").read_bytes() == js.read_bytes()
    assert res.to_dict() == json.loads(js.read_text())
    first, *rest = so.splitlines()
    # the API wrote no program: its summary says "(not written)" where the command names it
    assert first == res.summary().splitlines()[0].replace("(not written)", str(out))
    assert rest == res.summary().splitlines()[1:]


def test_api_streamed_into_a_file_is_the_same_program(dmu, tmp_path):
    mem = volerr.compensate("DMU50", dmu["lf"], dmu["errors"], tool_length=L)
    streamed = volerr.compensate("DMU50", dmu["lf"], dmu["errors"], tool_length=L,
                                 out=tmp_path / "s.nc", keep_errors=True)
    assert streamed.text is None and (tmp_path / "s.nc").read_bytes() == \
        mem.text.encode("latin-1")
    assert streamed.to_dict() == mem.to_dict()
    assert np.allclose(streamed.program_errors().after_um, mem.program_errors().after_um,
                       rtol=1e-12, atol=0)
    # the program text itself is taken as well as its file
    text = dmu["lf"].read_text()
    assert volerr.compensate("DMU50", text, dmu["errors"], tool_length=L).text == mem.text


def test_api_datum_is_checked_and_reported_as_the_command_does(dmu, tmp_path):
    """Before: the API's JSON ``datum`` had no ``error_um`` and the travel was not checked."""
    js = tmp_path / "c.json"
    code, so, se = main_("compensate", "DMU50", "--errors", dmu["errors"], dmu["lf"],
                         "--out", tmp_path / "c.nc", "--json", js, "--datum", "10,-20,150")
    assert code == 0, se
    res = volerr.compensate("DMU50", dmu["lf"], dmu["errors"], datum=(10, -20, 150))
    doc = json.loads(js.read_text())
    assert res.to_dict()["datum"] == doc["datum"] and len(doc["datum"]["error_um"]) == 3
    assert res.summary().splitlines()[1] == so.splitlines()[1]
    # the error at the datum, independently: the model's tool-tip error there (um)
    m = volerr.load("DMU50")
    em = ErrorModel(m, ErrorFunctions.from_dir(dmu["errors"], m))
    want = 1e3 * em.position_error(np.array([[10.0, -20.0, 150.0, 0.0, 0.0]]))[0]
    assert np.allclose(doc["datum"]["error_um"], want, atol=2e-6)
    with pytest.raises(InputError, match=r"--datum: X = 999 is outside the travel"):
        volerr.compensate("DMU50", dmu["lf"], dmu["errors"], datum=(999, 0, 100))
    with pytest.raises(InputError, match=r"--datum: Y = nan is outside the travel"):
        volerr.compensate("DMU50", dmu["lf"], dmu["errors"], datum=(0, float("nan"), 100))


# -- the tool length on a machine whose head tilts the tool ---------------------------------
def _tip(q, errors, length):
    """The tool tip of the independent exact chain, mm (workpiece frame)."""
    return (tool2work("HH_BC", dict(zip("XYZBC", q)), errors) @ np.r_[0, 0, -length, 1.0])[:3]


@pytest.fixture(scope="module")
def head(tmp_path_factory):
    """HH_BC with smooth random error tables, and a program of axis positions with the
    fork tilted (B up to 40 deg)."""
    m = volerr.load("HH_BC")
    d = write_errors(tmp_path_factory.mktemp("hh"), m, seed=4)
    rng = np.random.default_rng(11)
    q = np.column_stack([rng.uniform(600, 1400, 12), rng.uniform(400, 1100, 12),
                         rng.uniform(300, 600, 12), rng.uniform(-40, 40, 12),
                         rng.uniform(-90, 90, 12)])
    assert m.axes == ("X", "Y", "Z", "B", "C")
    text = "G90 G17\n" + "".join("G1 " + " ".join(f"{a}{v:.4f}" for a, v in zip(m.axes, r))
                                 + " F2000\n" for r in q) + "M30\n"
    return m, ErrorFunctions.from_dir(d, m), d, text


def _written(text, axes):
    rows = []
    for line in text.splitlines():
        words = dict((w[0], float(w[1:])) for w in line.split() if w[0] in axes)
        if len(words) == len(axes):
            rows.append([words[a] for a in axes])
    return np.array(rows)


def test_tool_length_is_the_offset_of_axis_positions(head):
    """Before: ``--tool-length`` on a program without TCPM was ignored (the same bytes).
    Now the actual tip of a tool L long lands on its nominal position (independent chain),
    which the run without it misses: the fork's tilt turns the angular errors into a
    tip error that grows with L."""
    m, funcs, d, text = head
    with_l = volerr.compensate("HH_BC", text, d, tool_length=L, decimals=6)
    without = volerr.compensate("HH_BC", text, d, decimals=6)
    assert with_l.text != without.text
    q_nom = _written(text, m.axes)
    lookup = ErrorModel(m, funcs).lookup

    def miss(out_text):
        q = _written(out_text, m.axes)
        e = funcs(lookup(q))
        errs = [{**{k: float(v[r]) for k, v in e.items()},
                 **{k: float(v) for k, v in funcs.constants.items()}} for r in range(len(q))]
        actual = np.array([_tip(r, err, L) for r, err in zip(q, errs)])
        nominal = np.array([_tip(r, {}, L) for r in q_nom])
        return np.linalg.norm(actual - nominal, axis=1).max()

    assert miss(with_l.text) < 0.1e-3
    assert miss(without.text) > 1e-3
    assert with_l.to_dict()["tool_offset_mm"] == [0.0, 0.0, -L]
    assert with_l.to_dict()["tool_length_mm"] == L
    assert f"tool: length {L:g} mm, offset (0, 0, -{L:g}) mm" in with_l.summary()
    assert "tool: offset (0, 0, 0) mm" in without.summary()
    # the same offset given as --tool is the same run
    same = volerr.compensate("HH_BC", text, d, tool=(0, 0, -L), decimals=6)
    assert same.text == with_l.text


def test_cli_tool_length_with_another_tool_offset_is_refused(head, tmp_path):
    m, funcs, d, text = head
    prog = tmp_path / "p.nc"
    prog.write_text(text)
    rc, so, se = cli("compensate", "HH_BC", "--errors", d, prog, "--out", tmp_path / "o",
                     "--tool", "0", "0", "-50", "--tool-length", str(L))
    assert rc == 2 and len(se.strip().splitlines()) == 1 and \
        "--tool 0 0 -50 and --tool-length 85 disagree" in se, se
    assert not (tmp_path / "o").exists()


def test_cli_tool_table_without_tcpm_is_refused(head, tmp_path):
    m, funcs, d, text = head
    prog = tmp_path / "p.nc"
    prog.write_text(text)
    (tmp_path / "tools.csv").write_text("tool,length_mm\n1,85\n")
    rc, so, se = cli("compensate", "HH_BC", "--errors", d, prog, "--out", tmp_path / "o",
                     "--tool-table", tmp_path / "tools.csv", "--json", tmp_path / "o.json")
    assert rc == 2 and len(se.strip().splitlines()) == 1 and \
        "--tool-table: " in se and "has no TCPM block" in se, se
    assert sorted(p.name for p in tmp_path.iterdir()) == ["p.nc", "tools.csv"]


def test_result_contract(head):
    """``table()`` rows of what the command prints, the corrections per axis computed here
    from the per-block reports; a one-line repr."""
    m, funcs, d, text = head
    res = volerr.compensate("HH_BC", text, d, tool_length=L)
    rows = {r.name: r for r in (res._rows())}
    s = res.to_dict()
    assert rows["max_before"].value == s["max_before_um"] and rows["max_before"].unit == "um"
    assert rows["rms_after"].value == s["rms_after_um"]
    assert rows["tool_offset_z"].value == -L and rows["tool_offset_z"].unit == "mm"
    done = [b for b in res.blocks if b.status.startswith("compensated")]
    for a in m.axes:
        corr = np.array([b.output[a] - b.nominal[a] for b in done])
        scale, unit = (np.pi / 180 * 1e6, "urad") if a in m.rotary_axes else (1e3, "um")
        assert rows[f"max_correction_{a}"].unit == unit
        assert rows[f"max_correction_{a}"].value == pytest.approx(np.abs(corr).max() * scale,
                                                                  rel=1e-12, abs=1e-12)
        assert rows[f"rms_correction_{a}"].value == pytest.approx(
            np.sqrt(np.mean(corr ** 2)) * scale, rel=1e-9, abs=1e-12)
    assert rows["max_correction_X"].value > 0.5      # the linear axes moved (um)
    assert all(r.k == 1.0 for r in rows.values())
    assert len(res.table()) == len(rows)
    r = repr(res)
    assert "\n" not in r and len(r) < 120 and r.startswith("<volerr Compensation: HH_BC")


def test_tcpmap_command_is_the_api(dmu, tmp_path):
    """``volerr tcpmap`` prints and writes what ``volerr.fiveaxis.api.tcpmap`` holds; the
    table's max / rms computed here from the map's errors."""
    from volerr.fiveaxis.api import tcpmap

    png, grid = tmp_path / "m.png", tmp_path / "m.csv"
    code, so, se = main_("tcpmap", "DMU50", "--errors", dmu["errors"], "--point", "30", "20",
                         "60", "--tool", "0", "0", "-40", "--steps", "9", "--plot", png,
                         "--csv", grid)
    assert code == 0, se
    res = tcpmap("DMU50", dmu["errors"], (30, 20, 60), tool=(0, 0, -40), steps=9,
                 plot_name=png)
    assert so.strip() == res.summary()
    assert grid.read_text() == res.csv_text()
    e = np.linalg.norm(res.map.err, axis=2)[res.map.valid] * 1e3
    rows = {r.name: r for r in res._rows()}
    assert rows["max_error"].value == pytest.approx(e.max(), rel=1e-12)
    assert rows["rms_error"].value == pytest.approx(np.sqrt(np.mean(e ** 2)), rel=1e-12)
    assert rows["valid_points"].value == 81 and rows["max_error"].unit == "um"
    assert res.to_dict()["tool_mm"] == [0.0, 0.0, -40.0]
    assert "\n" not in repr(res) and len(repr(res)) < 120


def test_api_tool_table_as_a_dict_or_a_file(dmu, tmp_path):
    """The tool table is available to the API, as the CSV the command reads or as a dict
    (keys as the tool numbers of the program's H / T / D words)."""
    text = "G90 G17\nT1 M6\nG43.4 H1\nG1 X10 Y20 Z60 B20 C30\nG1 X12 Y18 Z61 B25 C40\nG49\n"
    (tmp_path / "tools.csv").write_text("tool,length_mm\n1,120\n")
    a = volerr.compensate("DMU50", text, dmu["errors"], tool_table=tmp_path / "tools.csv")
    b = volerr.compensate("DMU50", text, dmu["errors"], tool_table={"1": 120})
    c = volerr.compensate("DMU50", text, dmu["errors"], tool_length=120)
    assert a.text == b.text == c.text != text
    assert a.to_dict()["tcpm_blocks"] == 2
    with pytest.raises(InputError, match="tool table: tool 1: length: 'long' is not a number"):
        volerr.compensate("DMU50", text, dmu["errors"], tool_table={1: "long"})


def test_figures_are_the_plots(dmu):
    from volerr.fiveaxis.api import tcpmap

    res = volerr.compensate("DMU50", dmu["lf"], dmu["errors"])
    fig = res.figures()["program_errors"]
    before = fig.axes[0].lines[0].get_ydata()
    want = [np.linalg.norm(b.before_um) for b in res.blocks]
    assert np.allclose(before, np.maximum(want, 1e-4), rtol=1e-12)
    m = tcpmap("DMU50", dmu["errors"], (30, 20, 60), steps=5).figures()["map"]
    assert len(m.axes) >= 5
