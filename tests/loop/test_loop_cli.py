"""``volerr loop`` on the command line: success, units, and bad input (exit 2, one line, no
traceback, inputs untouched, nothing written)."""

import hashlib
import json

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.loop.simulate import demo_probes, simulate

from helpers import in_process


def _cli(*args, cwd=None):
    """``volerr ARGS`` in this process (``helpers.in_process``: ``main``'s exit code and
    lines; a warning a process would print is appended to stderr), without starting an
    interpreter; the entry point's own process is tests/cli/test_cli_core.py's."""
    return in_process.volerr(*args, cwd=cwd)


@pytest.fixture(scope="module")
def campaign():
    return simulate("MB1", n_points=240, seed=4, probes=demo_probes(volerr.load("MB1")),
                    effects=[{"kind": "reversal", "axis": "X", "um": 4.0}])


def _write(path, cols: dict):
    names = list(cols)
    rows = [",".join(names)]
    for i in range(len(next(iter(cols.values())))):
        rows.append(",".join(str(cols[n][i]) for n in names))
    path.write_text("\n".join(rows) + "\n")
    return path


def test_cli_loop_success_and_mm_units(tmp_path, campaign, capsys, monkeypatch):
    cols = campaign.columns()
    um = _write(tmp_path / "um.csv", cols)
    mm_cols = {(k.replace("_um", "_mm") if k.startswith("d") and k.endswith("_um") else k):
               (np.asarray(v) * 1e-3 if k.endswith("_um") else v) for k, v in cols.items()}
    mm = _write(tmp_path / "mm.csv", mm_cols)
    # relative paths, as a user types them: the report names the files where they end up
    r1 = _cli("loop", "MB1", um, "--json", "a.json", "--degree", "4",
              "--out-dir", "aug", "--errors-out", "errors", cwd=tmp_path)
    # the same data in mm, with --html and no --json nor --out-dir: the augmented layout is
    # not written (issue 38: only what was asked); the page holds the residual sources as
    # tables, no raw JSON dump, no absolute paths
    # (this one and the third through ``volerr.cli.main`` in this process, the same parser
    # and exit codes; r1 is the ``python -m volerr`` entry point)
    html = tmp_path / "page" / "r.html"
    html.parent.mkdir()
    capsys.readouterr()
    rc2 = main(["loop", "MB1", str(mm), "--html", str(html), "--degree", "4"])
    r2 = capsys.readouterr()
    assert r1.returncode == 0 and rc2 == 0, r1.stderr + r2.err
    a = json.loads((tmp_path / "a.json").read_text())
    assert f"held-out RMS {a['rms_before_um']:.3f} -> {a['rms_after_um']:.3f} um" in r2.out
    text = html.read_text()
    assert "Where the residual lives" in text and "parameter P" in text
    assert str(tmp_path) not in text and '"rms_before_um"' not in text
    assert sorted(p.name for p in html.parent.iterdir()) == ["r.html"]
    assert [e["name"] for e in a["effects"]] == ["reversal_X"]
    assert (tmp_path / "aug" / "MB1_aug.toml").is_file()
    assert a["augmented_layout"] == "aug/MB1_aug.toml" and a["generated_module"] == \
        "aug/mb1_aug.py" and (tmp_path / a["generated_module"]).is_file()
    assert sorted(p.name for p in (tmp_path / "errors").iterdir()) == [
        "X.csv", "Y.csv", "Z.csv", "constants.csv"]
    assert "reversal" in r1.stdout
    # a second run is never refused for a file the first wrote itself
    monkeypatch.chdir(tmp_path)
    rc3 = main(["loop", "MB1", str(um), "--json", "a.json", "--degree", "4"])
    assert rc3 == 0, capsys.readouterr().err


def _bad_cases(campaign):
    c = campaign.columns()
    drop = lambda k: {n: v for n, v in c.items() if n != k}  # noqa: E731
    nan = dict(c)
    nan["dy_um"] = np.where(np.arange(len(c["X"])) == 5, np.nan, c["dy_um"])
    nounit = {("dx" if k == "dx_um" else k): v for k, v in c.items()}
    nm = {("dz_nm" if k == "dz_um" else k): v for k, v in c.items()}
    mm_as_um = dict(c)  # deviations given in um but labelled mm: 1000x too big
    for k in ("dx_um", "dy_um", "dz_um"):
        mm_as_um[k.replace("_um", "_mm")] = mm_as_um.pop(k) * 1e3 + 5000.0
    extra_axis = dict(c)
    extra_axis["C"] = np.zeros(len(c["X"]))
    far = dict(c)
    far["X"] = np.asarray(c["X"]) + 5000.0
    few = {k: np.asarray(v)[:8] for k, v in c.items()}
    return {"missing axis": drop("Y"), "missing deviation": drop("dz_um"), "NaN": nan,
            "no unit": nounit, "nm unit": nm, "implausible mm": mm_as_um,
            "extra axis": extra_axis, "outside travel": far, "too few": few}


@pytest.mark.parametrize("case", ["missing axis", "missing deviation", "NaN", "no unit",
                                  "nm unit", "implausible mm", "extra axis", "outside travel",
                                  "too few"])
def test_cli_loop_bad_input(tmp_path, campaign, case):
    path = _write(tmp_path / "d.csv", _bad_cases(campaign)[case])
    before = hashlib.sha256(path.read_bytes()).hexdigest()
    r = _cli("loop", "MB1", path, "--json", tmp_path / "r.json", "--html", tmp_path / "r.html")
    assert r.returncode == 2, (case, r.stdout, r.stderr)
    assert r.stderr.startswith("volerr loop: error:") and r.stderr.count("\n") == 1, r.stderr
    assert "Traceback" not in r.stderr
    assert hashlib.sha256(path.read_bytes()).hexdigest() == before
    assert not (tmp_path / "r.json").exists() and not (tmp_path / "r.html").exists()


@pytest.mark.parametrize("args", [["--json", "{data}"], ["--families", "thermal,magic"],
                                  ["--degree", "40"], ["--test-fraction", "0.9"]])
def test_cli_loop_bad_options(tmp_path, campaign, args):
    path = _write(tmp_path / "d.csv", campaign.columns())
    before = path.read_bytes()
    args = [a.replace("{data}", str(path)) for a in args]
    if "--json" not in args:
        args += ["--json", str(tmp_path / "r.json")]
    r = _cli("loop", "MB1", path, *args)
    assert r.returncode == 2 and "Traceback" not in r.stderr and r.stderr.count("\n") == 1
    assert path.read_bytes() == before


def test_cli_loop_unknown_layout_and_missing_file(tmp_path):
    r = _cli("loop", "NOPE", tmp_path / "x.csv", "--json", tmp_path / "r.json")
    assert r.returncode == 2 and "unknown layout" in r.stderr
    r = _cli("loop", "MB1", tmp_path / "x.csv", "--json", tmp_path / "r.json")
    assert r.returncode == 2 and "not found" in r.stderr


def test_layout_effect_table_errors(tmp_path):
    """Defective [effects.*] tables in a layout file are refused with one clear line."""
    from volerr.errors import InputError
    from volerr.machine.layout import layout_text, parse_layout

    text, _ = layout_text("MB1")
    bad = {
        "target": '[effects.e]\nkind = "thermal"\nterms = [{parameter = "K", target = "EQX", basis = "X"}]\n',
        "clash": '[effects.e]\nkind = "thermal"\nterms = [{parameter = "EXX", target = "EXX", basis = "X"}]\n',
        "basis": '[effects.e]\nkind = "thermal"\nterms = [{parameter = "K", target = "EXX", basis = "__import__(1)"}]\n',
        "terms": '[effects.e]\nkind = "thermal"\n',
    }
    for why, table in bad.items():
        with pytest.raises(InputError):
            parse_layout(text + "\n" + table, f"{why}.toml")


def test_cli_loop_refuses_drift_options_on_deviations(tmp_path, campaign):
    """``--predictions-out`` and ``--holdout-files`` are the drift loop's: on measured
    deviations one line, exit 2, nothing written (the refusals are ``volerr.loop``'s and its
    result's, not the command's)."""
    um = _write(tmp_path / "um.csv", campaign.columns())
    r = _cli("loop", "MB1", um, "--json", tmp_path / "r.json", "--degree", "2",
             "--predictions-out", tmp_path / "p.csv")
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "--predictions-out" in r.stderr and "drift" in r.stderr
    assert not (tmp_path / "r.json").exists() and not (tmp_path / "p.csv").exists()
    r = _cli("loop", "MB1", um, "--json", tmp_path / "r.json", "--holdout-files", um)
    assert r.returncode == 2 and "--holdout-files" in r.stderr
    assert not (tmp_path / "r.json").exists()
