"""The Python API (issue 38): every command one call, its result equal to what the command
writes and prints; the callable packages whatever was imported first; InputError one line;
the README's and the manual's Python blocks run."""

from __future__ import annotations

import json
import math
import re
import subprocess
import sys
from pathlib import Path

import pytest

import volerr
from helpers import plan_designs
from volerr.cli import main
from volerr.example_files import shipped_path

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("api_examples")

ROOT = Path(__file__).resolve().parents[2]
SPHERE = str(shipped_path("sphere_example_DMU50.csv"))


def _cli_json(tmp_path, argv, capsys) -> tuple[dict, str]:
    out = tmp_path / "cli.json"
    capsys.readouterr()
    assert main([*argv, "--json", str(out)]) == 0
    doc = json.loads(out.read_text())
    doc.pop("identification", None)   # the report's identification: the command's options and
    return doc, capsys.readouterr().out   # file (issue 45), not the API's keywords


def test_calibrate_equals_the_command(tmp_path, capsys):
    doc, printed = _cli_json(tmp_path, ["calibrate", "DMU50", SPHERE], capsys)
    cal = volerr.calibrate("DMU50", [SPHERE])
    assert cal.to_dict()["parameters"] == doc["parameters"]
    timeless = {k for k in doc if k != "seconds"}
    assert {k: cal.to_dict()[k] for k in timeless} == {k: doc[k] for k in timeless}
    assert cal.summary() == printed.rstrip("\n")
    assert len(repr(cal).splitlines()) == 1 and len(repr(cal)) < 160
    rows = cal.table()
    rows = rows.to_dict("records") if hasattr(rows, "to_dict") else [r._asdict() for r in rows]
    assert {r["name"]: (r["value"], r["std"], r["unit"], r["k"]) for r in rows} == {
        n: (v["value"], v["std"], v["unit"], 1.0) for n, v in doc["parameters"].items()}
    cal.write_json(tmp_path / "api.json")
    assert json.loads((tmp_path / "api.json").read_text()) == cal.to_dict()


def test_every_plus_minus_printed_says_its_k(capsys):
    assert main(["calibrate", "DMU50", SPHERE]) == 0
    lines = [ln for ln in capsys.readouterr().out.splitlines() if "+-" in ln]
    assert lines and all("k = 1" in ln for ln in lines), lines


def test_a_variance_factor_below_one_keeps_the_stated_uncertainties(tmp_path):
    """The DMU50 example scatters less than stated (u = 1 um per coordinate by default;
    variance factor s0^2 = 0.28): its stds are the a-priori ones.  The same readings stated
    at u = 0.5 um have s0^2 = 4 x 0.28 > 1, so their stds are the a-priori ones (half) widened
    by s0: std(0.5) / std(1) = sqrt(4 s0^2) / 2 = s0.  Scaling by s0 below 1 too (the former
    rule) would give the same stds for both files (ratio 1)."""
    lines = Path(SPHERE).read_text().splitlines()
    half = tmp_path / "sphere_u05.csv"
    half.write_text("\n".join([lines[0] + ",u_um"] + [ln + ",0.5" for ln in lines[1:]]) + "\n")
    a = volerr.calibrate("DMU50", [SPHERE])
    b = volerr.calibrate("DMU50", [str(half)])
    vf = a["variance_factor"]
    assert vf < 1 and not a["uncertainty_scaled"]
    assert b["variance_factor"] == pytest.approx(4 * vf, rel=1e-3) and b["uncertainty_scaled"]
    for name, pa in a["parameters"].items():
        pb = b["parameters"][name]
        assert pb["value"] == pytest.approx(pa["value"], rel=1e-9)   # the same weights' ratio
        assert pb["std"] / pa["std"] == pytest.approx(math.sqrt(vf), rel=2e-3), name
    assert "are kept, not shrunk" in a.summary()
    assert "are kept, not shrunk" not in b.summary()


def test_combination_by_names_equals_the_reported_combination():
    cal = volerr.calibrate("DMU50", [SPHERE])
    combo = cal["combinations"][0]
    assert combo["expression"] == "EY0B + EY0C"
    value, std = cal.combination({"EY0B": 1, "EY0C": 1})
    assert 1e3 * value == pytest.approx(combo["value"], rel=1e-9)   # mm -> um
    assert 1e3 * std == pytest.approx(combo["std"], rel=1e-9)
    labels = {n: cal.labels[j] for n, j in cal._label_names().items()}
    assert cal.combination({labels["EY0B"]: 1, labels["EY0C"]: 1}) == (value, std)
    assert cal.combination({"EY0B": 1}) is None          # not determined alone
    assert cal.combination({"NOPE": 1}) is None


@pytest.mark.slow
def test_plan_equals_the_command(tmp_path, capsys):
    """The command's design is kept for tests/cli/test_readme_commands.py's shortest plan
    (the same request, one xdist group: ``helpers.plan_designs``); the API call below designs
    its own."""
    with plan_designs.designed_once():
        doc, printed = _cli_json(tmp_path, ["plan", "MB1", "--instrument", "ballbar",
                                            "--readings", "200", "--out", str(tmp_path / "p")],
                                 capsys)
    p = volerr.plan("MB1", "ballbar", readings=200)
    d = p.to_dict()
    assert d["parameters"] == doc["parameters"]
    timeless = {k for k in doc if k not in ("seconds", "files")}
    assert {k: d[k] for k in timeless} == {k: doc[k] for k in timeless}
    assert p.summary() == printed.rstrip("\n")


@pytest.mark.slow
def test_loop_equals_the_command(tmp_path, capsys):
    from volerr.example_files import write_examples

    write_examples(tmp_path)
    data = str(tmp_path / "deviations_MB1.csv")
    doc, printed = _cli_json(tmp_path, ["loop", "MB1", data, "--out-dir", str(tmp_path / "o")],
                             capsys)
    r = volerr.loop("MB1", data)
    d = r.to_dict()
    assert d["effects"] == doc["effects"]
    same = {k for k in doc if k not in ("augmented_layout", "generated_module") and
            k != "seconds"}
    assert {k: d[k] for k in same} == {k: doc[k] for k in same}
    assert r.summary().splitlines()[:3] == printed.splitlines()[:3]


def test_input_error_is_the_commands_one_line(capsys):
    with pytest.raises(volerr.InputError) as exc:
        volerr.calibrate("NOPE", [SPHERE])
    assert main(["calibrate", "NOPE", SPHERE]) == 2
    err = capsys.readouterr().err
    assert err == f"volerr calibrate: error: {exc.value}\n"
    assert "\n" not in str(exc.value)


def test_packages_are_callable_whatever_was_imported_first():
    code = ("import sys\nimport volerr\nassert 'volerr.calibrate' not in sys.modules\n"
            "assert 'sympy' not in sys.modules\n"
            "import volerr.calibrate.run, volerr.plan._run, volerr.loop.run, "
            "volerr.identify.solve\n"
            "from volerr.calibrate import terms\n"
            "assert all(callable(getattr(volerr, n)) for n in "
            "('calibrate', 'plan', 'loop', 'identify', 'uncertainty', 'compensate', 'ballbar_evaluate', "
            "'iso230_2', 'error_map', 'probe_cal', 'diagonals'))\n"
            "assert volerr.calibrate.run.calibrate is volerr.calibrate.__api__\n"
            "print('ok')\n")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                       timeout=120)
    assert r.returncode == 0 and r.stdout.strip() == "ok", r.stderr


def _python_blocks(path: Path) -> list:
    return re.findall(r"```python\n(.*?)```", path.read_text(encoding="utf-8"), re.S)


@pytest.mark.parametrize("page", ["README.md", "docs/getting_started.md"])
def test_the_python_blocks_run(page, tmp_path, monkeypatch):
    import shutil

    blocks = _python_blocks(ROOT / page)
    assert blocks
    monkeypatch.chdir(tmp_path)
    shutil.copy(SPHERE, tmp_path / "sphere_example_DMU50.csv")
    for code in blocks:
        exec(compile(code, page, "exec"), {"__name__": "__main__"})


def test_uncertainty_equals_the_command(tmp_path, capsys):
    from volerr.example_files import write_examples

    write_examples(tmp_path)
    task = str(tmp_path / "task_distance.csv")
    argv = ["uncertainty", "MH2", "--task", task, "--evaluate", "distance", "--spec",
            "E0=2+L/300", "--samples", "200"]
    doc, printed = _cli_json(tmp_path, argv, capsys)
    r = volerr.uncertainty("MH2", task, "distance", spec="E0=2+L/300", samples=200)
    assert r.to_dict() == doc
    assert r.summary() == printed.rstrip("\n")
    assert "u 1." in printed and "(k = 1)" in printed and "(k = 2)" in printed


@pytest.fixture(scope="module")
def example_dir(tmp_path_factory):
    from volerr.example_files import write_examples

    d = tmp_path_factory.mktemp("api_examples")
    write_examples(d)
    return d


@pytest.mark.parametrize("argv,call", [
    (["ballbar", "evaluate", "ballbar_example_XY.csv"],
     lambda: volerr.ballbar_evaluate("ballbar_example_XY.csv")),
    (["iso230-2", "iso230_2_run_X.csv"], lambda: volerr.iso230_2("iso230_2_run_X.csv")),
    (["map", "MB1", "--errors", "errors_MB1", "--grid", "5"],
     lambda: volerr.error_map("MB1", "errors_MB1", grid=5)),
    (["diagonals", "MB1", "--errors", "errors_MB1"],
     lambda: volerr.diagonals("MB1", "errors_MB1")),
    (["probe-cal", "probe_sphere.csv", "--sphere-radius", "25.006", "--out", "pm.csv"],
     lambda: volerr.probe_cal("probe_sphere.csv", 25.006)),
])
def test_evaluations_equal_the_commands(argv, call, example_dir, monkeypatch, capsys):
    monkeypatch.chdir(example_dir)
    doc, printed = _cli_json(example_dir, argv, capsys)
    r = call()
    doc.pop("identification", None)   # the command's --instrument/--machine/--operator (none)
    assert r.to_dict() == doc
    assert printed.startswith(r.summary())
    assert all(("k = " in ln) for ln in printed.splitlines() if "+-" in ln or "(U " in ln)


def test_identify_equals_the_command(example_dir, monkeypatch, capsys):
    monkeypatch.chdir(example_dir)
    capsys.readouterr()
    assert main(["identify", "MB1", "--axis", "X", "tracker_example_X.csv", "--out",
                 "X_api.csv", "--json", "id.json"]) == 0
    printed = capsys.readouterr().out
    r = volerr.identify("MB1", "X", "tracker_example_X.csv")
    doc = json.loads(Path("id.json").read_text())
    doc.pop("identification", None)    # the report's identification (issue 45), when stated
    assert r.to_dict() == doc
    assert r.error_table_csv() == Path("X_api.csv").read_text()
    assert r.summary().split(" -> ")[0] == printed.split(" -> ")[0]


def test_the_readme_fits_on_a_screen():
    """At most 15 KB (issue 38): the rest is in the manual (docs/), each capability linked."""
    text = (ROOT / "README.md").read_text(encoding="utf-8")
    assert len(text.encode("utf-8")) <= 15 * 1024
    for link in re.findall(r"\]\(((?:docs/)[^)#]+)\)", text):
        assert (ROOT / link).exists(), link


def test_check_and_history_are_reachable_from_the_top():
    """``volerr.check(...)`` is the check command's function whatever was imported first;
    ``volerr.history.add`` / ``show`` are the history commands'."""
    import subprocess
    import sys

    code = ("import volerr.check._run, volerr; from volerr.check import check; "
            "assert callable(volerr.check) and volerr.check.__api__ is check; "
            "assert volerr.history.add.__module__ == 'volerr.history.run'; "
            "import sys; assert 'sympy' not in sys.modules")
    subprocess.run([sys.executable, "-c", code], check=True)
