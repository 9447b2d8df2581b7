"""Outputs never lose data: every command checks every output before computing (exit 2, one
line, no traceback), never writes over an input or a file of the installed package, refuses two
outputs on one file, and writes all of its outputs or none of them."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from volerr.cli import main
from volerr.fileio import Outputs, is_package_file, write_text
from volerr.errors import InputError

PACKAGE = Path(__import__("volerr").__file__).parent
#: a folder nobody can create files in, root included
NOWHERE = "/proc/volerr-nowhere"


def run(capsys, *argv):
    """(exit code, stdout, stderr) of ``volerr argv`` run in-process."""
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, err):
    assert code == 2, err
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err


def files_in(d: Path) -> set:
    return {str(p.relative_to(d)) for p in d.rglob("*")}


# ---------------------------------------------------------------------------------------------
# 1. an unwritable output path: exit 2 and one line, for every command and every output option
def _cases(i, bad, tmp):
    e, dmu = i["errors"], i["dmu_errors"]
    png = bad + ".png"
    return {
        "map --out": ["map", "MB1", "--errors", e, "--out", bad],
        "map --plot": ["map", "MB1", "--errors", e, "--plot", png],
        "map --json": ["map", "MB1", "--errors", e, "--json", bad],
        "diagonals --plot": ["diagonals", "MB1", "--errors", e, "--plot", png],
        "identify --out": ["identify", "MB1", "--axis", "X", i["tracker"], "--out", bad],
        "identify --plot": ["identify", "MB1", "--axis", "X", i["tracker"], "--out",
                            tmp / "X.csv", "--plot", png],
        "squareness --out": ["squareness", "MB1", e, "--out", bad],
        "probe-cal --plot": ["probe-cal", i["sphere"], "--sphere-radius", i["sphere_r"],
                             "--out", tmp / "m.csv", "--plot", png],
        "probe-cal --plots": ["probe-cal", i["sphere"], "--sphere-radius", i["sphere_r"],
                              "--out", tmp / "m.csv", "--plots", bad],
        "probe-cal --plan": ["probe-cal", "--plan", bad, "--sphere-radius", 10,
                             "--ball-radius", 1],
        "compensate --plot": ["compensate", "DMU50", i["program"], "--errors", dmu, "--out",
                              tmp / "c.nc", "--plot", png],
        "compensate --report": ["compensate", "DMU50", i["program"], "--errors", dmu, "--out",
                                tmp / "c.nc", "--report", bad],
        "tcpmap --out": ["tcpmap", "DMU50", "--errors", dmu, "--point", "30,20,60", "--out", png],
        "tcpmap --csv": ["tcpmap", "DMU50", "--errors", dmu, "--point", 30, 20, 60, "--out",
                         tmp / "t.png", "--csv", bad],
        "controller export": ["controller", "export", "MB1", "--errors", e, "--format", "isg",
                              "--out", bad],
        "simulate --out": ["simulate", "MB1", "--out", bad],
        "loop --json": ["loop", "MB1", i["task"], "--json", bad],
        "iso230-2 --json": ["iso230-2", i["run"], "--json", bad],
        "iso230-2 --table-out": ["iso230-2", i["run"], "--json", tmp / "r.json",
                                 "--table-out", bad],
        "uncertainty --json": ["uncertainty", "MB1", "--task", i["task"], "--evaluate",
                               "distance", "--noise-um", 1, "--json", bad],
        "iso10360 --json": ["iso10360", "MB1", "--errors", e, "--json", bad],
        "audit --json": ["audit", "MB1", "--json", bad],
        "derive --out": ["derive", "MB1", "--out", bad],
        "demo --out": ["demo", "--out", bad],
        "calibrate --json": ["calibrate", "DMU50", i["sphere_probing"], "--json", bad],
        "calibrate --html": ["calibrate", "DMU50", i["sphere_probing"], "--html", bad],
        "calibrate --errors-out": ["calibrate", "DMU50", i["sphere_probing"], "--json",
                                   tmp / "c.json", "--errors-out", bad],
        "ballbar simulate --out": ["ballbar", "simulate", "MB1", "--errors", e, "--plane", "XY",
                                   "--radius", 100, "--centre", "450,287,200", "--out", bad],
        "ballbar evaluate --json": ["ballbar", "evaluate", i["ballbar"], "--json", bad],
        "ballbar evaluate --plot": ["ballbar", "evaluate", i["ballbar"], "--json",
                                    tmp / "b.json", "--plot", png],
        "ballbar evaluate --html": ["ballbar", "evaluate", i["ballbar"], "--html", bad],
    }


CASES = sorted(_cases({k: Path("x") for k in ("errors", "dmu_errors", "program", "tracker",
                                               "sphere", "run", "task", "ballbar",
                                               "sphere_probing")} | {"sphere_r": 1},
                      "b", Path("t")))


@pytest.mark.parametrize("case", CASES)
@pytest.mark.parametrize("bad", [NOWHERE + "/x", "FILE/x"], ids=["no-permission", "below-a-file"])
def test_unwritable_output_is_one_line_and_writes_nothing(case, bad, inputs, tmp_path, capsys):
    if bad.startswith("FILE"):
        (tmp_path / "FILE").write_text("a file, not a folder")
        bad = str(tmp_path / bad)
    out = tmp_path / "out"
    out.mkdir()
    code, _, err = run(capsys, *_cases(inputs, bad, out)[case])
    one_line_error(code, err)
    assert files_in(out) == set(), f"{case}: wrote {files_in(out)} although it failed"


def test_read_only_demo_folder_is_refused_before_any_work(tmp_path, capsys):
    if os.geteuid() == 0:
        pytest.skip("root writes into read-only folders; /proc covers the unwritable case")
    ro = tmp_path / "ro"
    ro.mkdir()
    ro.chmod(0o555)
    try:
        code, _, err = run(capsys, "demo", "--out", ro)
    finally:
        ro.chmod(0o755)
    one_line_error(code, err)


# ---------------------------------------------------------------------------------------------
# 2. inputs and package files are never overwritten
@pytest.mark.parametrize("argv", [
    ["audit", "MB1", "--json", PACKAGE / "layouts" / "MB1.toml"],
    ["map", "MB1", "--errors", "{errors}", "--out", PACKAGE / "layouts" / "MB1.toml"],
    ["map", "MB1", "--errors", "{errors}", "--json", PACKAGE / "data" / "formats.md"],
    ["map", "MB1", "--errors", "{errors}", "--out", "{errors}/X.csv"],
    ["identify", "MB1", "--axis", "X", "{tracker_copy}", "--out", "{tracker_copy}"],
    ["squareness", "MB1", "{errors}", "--out", "{errors}"],
    ["simulate", "{layout_copy}", "--out", "{layout_copy}", "--points", 10],
])
def test_inputs_and_package_files_are_never_overwritten(argv, inputs, tmp_path, capsys):
    import shutil

    tracker_copy = tmp_path / "t.csv"
    shutil.copy(inputs["tracker"], tracker_copy)
    layout_copy = tmp_path / "lay.toml"
    shutil.copy(PACKAGE / "layouts" / "MB1.toml", layout_copy)
    subst = {"errors": inputs["errors"], "tracker_copy": tracker_copy, "layout_copy": layout_copy}
    argv = [str(a).format(**subst) for a in argv]
    watched = [Path(a) for a in argv if Path(a).is_file()]
    watched += list(Path(inputs["errors"]).glob("*.csv"))
    before = {p: p.read_bytes() for p in watched}
    code, _, err = run(capsys, *argv)
    one_line_error(code, err)
    assert "refusing" in err or "input" in err
    for p, data in before.items():
        assert p.read_bytes() == data, f"{p} was modified"


def test_every_shipped_file_is_protected():
    shipped = [p for p in PACKAGE.rglob("*") if p.is_file()]
    assert len(shipped) > 40
    for p in shipped:
        assert is_package_file(p)
        with pytest.raises(InputError, match="installed volerr package"):
            Outputs().file("--out", p).check()
        with pytest.raises(InputError):
            write_text(p, "x")
    assert not is_package_file(PACKAGE.parent / "README.md")


# ---------------------------------------------------------------------------------------------
# 3. two outputs of one run on the same file
@pytest.mark.parametrize("argv", [
    ["compensate", "DMU50", "{program}", "--errors", "{dmu}", "--out", "{t}/c.nc",
     "--json", "{t}/c.nc"],
    ["compensate", "DMU50", "{program}", "--errors", "{dmu}", "--out", "{t}/c.nc",
     "--report", "{t}/r.png", "--plot", "{t}/r.png"],
    ["tcpmap", "DMU50", "--errors", "{dmu}", "--point", "30,20,60", "--out", "{t}/t.png",
     "--csv", "{t}/t.png"],
    ["squareness", "MB1", "{errors}", "--out", "{t}/sq", "--json", "{t}/sq/constants.csv"],
    ["map", "MB1", "--errors", "{errors}", "--out", "{t}/m", "--json", "{t}/./m"],
    ["probe-cal", "{sphere}", "--sphere-radius", "{r}", "--out", "{t}/p/probe_map_3d.png",
     "--plots", "{t}/p"],
    ["loop", "MB1", "{task}", "--json", "{t}/l.json", "--html", "{t}/l.json"],
])
def test_two_outputs_on_one_file_are_refused(argv, inputs, tmp_path, capsys):
    t = tmp_path / "o"
    t.mkdir()
    subst = {"program": inputs["program"], "dmu": inputs["dmu_errors"], "t": t,
             "errors": inputs["errors"], "sphere": inputs["sphere"], "r": inputs["sphere_r"],
             "task": inputs["task"]}
    code, _, err = run(capsys, *[str(a).format(**subst) for a in argv])
    one_line_error(code, err)
    assert "same" in err
    assert files_in(t) == set()


# ---------------------------------------------------------------------------------------------
# 4. all or nothing
def test_failing_last_output_leaves_nothing(inputs, tmp_path, capsys, monkeypatch):
    """map --out --json --plot: the plot (written after the CSV) fails -> no file at all."""
    from volerr.cmm import volmap

    def broken(*a, **k):
        raise InputError("simulated failure of the plot")

    monkeypatch.setattr(volmap, "plot_map", broken)
    code, _, err = run(capsys, "map", "MB1", "--errors", inputs["errors"], "--out",
                       tmp_path / "m.csv", "--json", tmp_path / "s.json", "--plot",
                       tmp_path / "new" / "m.png")
    one_line_error(code, err)
    assert files_in(tmp_path) == set()


@pytest.mark.parametrize("command", ["identify", "compensate", "squareness", "probe-cal"])
def test_failed_rename_restores_previous_outputs(command, inputs, tmp_path, capsys,
                                                 monkeypatch):
    """The last rename fails: earlier outputs of the run are rolled back to what was there."""
    import volerr.fileio as fio

    t = tmp_path
    argv = {
        "identify": ["identify", "MB1", "--axis", "X", inputs["tracker"], "--out", t / "a",
                     "--json", t / "b"],
        "compensate": ["compensate", "DMU50", inputs["program"], "--errors",
                       inputs["dmu_errors"], "--out", t / "a", "--report", t / "b"],
        "squareness": ["squareness", "MB1", inputs["errors"], "--out", t, "--json", t / "b"],
        "probe-cal": ["probe-cal", inputs["sphere"], "--sphere-radius", inputs["sphere_r"],
                      "--out", t / "a", "--json", t / "b"],
    }[command]
    (t / "a").write_text("old a")
    (t / "b").write_text("old b")
    real = os.replace

    def replace(src, dst):
        if Path(dst).name == "b" and ".volerr-staging-" in str(src):
            raise PermissionError(1, "Operation not permitted")
        return real(src, dst)

    monkeypatch.setattr(fio.os, "replace", replace)
    code, _, err = run(capsys, *argv)
    one_line_error(code, err)
    assert (t / "a").read_text() == "old a" and (t / "b").read_text() == "old b"
    assert sorted(p.name for p in t.iterdir()) == ["a", "b"], "staging or backup files left"


def test_outputs_plan_folder_files_and_cleanup(tmp_path):
    inp = tmp_path / "in.csv"
    inp.write_text("1")
    plan = Outputs([inp]).folder("--dir", tmp_path / "D", files=["X.csv"]) \
        .file("--json", tmp_path / "s.json").check()
    with plan:
        write_text(plan.path("--dir") / "X.csv", "x")
        write_text(plan.path("--json"), "{}")
        assert not (tmp_path / "s.json").exists()  # nothing final before the end
    assert (tmp_path / "D" / "X.csv").read_text() == "x"
    assert files_in(tmp_path) == {"in.csv", "D", "D/X.csv", "s.json"}
    # a folder's future file may not be an input or another output
    with pytest.raises(InputError, match="input"):
        Outputs([inp]).folder("--dir", tmp_path, files=["in.csv"]).check()
    with pytest.raises(InputError, match="same file"):
        Outputs().folder("--dir", tmp_path / "D", files=["X.csv"]) \
            .file("--out", tmp_path / "D" / "X.csv").check()
    # an undeclared name written into a folder is checked at commit: nothing moves
    plan = Outputs([inp]).folder("--dir", tmp_path)
    with pytest.raises(InputError, match="input"):
        with plan:
            write_text(plan.path("--dir") / "new.csv", "n")
            write_text(plan.path("--dir") / "in.csv", "overwrite!")
    assert inp.read_text() == "1" and not (tmp_path / "new.csv").exists()
    assert not [p for p in tmp_path.rglob(".volerr-*")]


# ---------------------------------------------------------------------------------------------
# 5. derive writes into ./generated of the working directory, never into the package
def test_derive_default_location_is_the_working_directory(tmp_path, monkeypatch, capsys):
    import volerr.generated

    pkg_file = Path(volerr.generated.__file__).parent / "mb1.py"
    before = pkg_file.stat().st_mtime_ns, pkg_file.read_bytes()
    lay = tmp_path / "copy.toml"
    lay.write_text((PACKAGE / "layouts" / "MB1.toml").read_text())  # keeps name = "MB1"
    monkeypatch.chdir(tmp_path)
    code, out, err = run(capsys, "derive", "copy.toml")
    assert code == 0, err
    text = (tmp_path / "generated" / "mb1.py").read_text()
    assert "copy.toml" in text and "LAYOUT = 'MB1'" in text
    assert (pkg_file.stat().st_mtime_ns, pkg_file.read_bytes()) == before
    # naming the package folder explicitly is refused for a single layout
    code, _, err = run(capsys, "derive", "copy.toml", "--out", pkg_file.parent)
    one_line_error(code, err)
    assert (pkg_file.stat().st_mtime_ns, pkg_file.read_bytes()) == before
