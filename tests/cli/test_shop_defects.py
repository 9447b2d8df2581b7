"""Defects a new user hit (issue 32): each test failed before its fix.

Every bad input ends in exit 2 and ONE line on stderr (no traceback, no warning before it),
nothing written or replaced; every output option is optional."""

from __future__ import annotations

import numpy as np
import pytest

from volerr.cli import main
from tests.helpers.full_disk import full_disk


def one_line_error(capsys, code, fragment=""):
    """Exit 2 and exactly one stderr line containing ``fragment``."""
    err = capsys.readouterr().err
    assert code == 2, err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert len(lines) == 1, err
    assert "Traceback" not in err
    assert fragment.lower() in lines[0].lower(), lines[0]
    return lines[0]


def write_run(path, header="deviation_um", scale=1.0, targets=np.linspace(0, 800, 9)):
    """An ISO 230-2 long-format run: 3 cycles, both directions, deviations in um (x scale)."""
    rng = np.random.default_rng(5)
    lines = [f"target_mm,cycle,direction,{header}"]
    for t in targets:
        for c in (1, 2, 3):
            for word, half in (("+1", 1.2), ("-1", -1.2)):
                dev = 4.0 * np.sin(t / 200.0) + half + rng.normal(0, 0.3)
                lines.append(f"{t:g},{c},{word},{dev * scale:.4f}")
    path.write_text("\n".join(lines) + "\n")
    return path


# ---------------------------------------------------------------------------------------------
# every output optional
def test_iso230_2_without_outputs_prints_the_result(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv")
    assert main(["iso230-2", str(run)]) == 0
    out = capsys.readouterr().out
    assert "A " in out and " um" in out
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_iso230_2_html_alone(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv")
    assert main(["iso230-2", str(run), "--html", str(tmp_path / "c.html")]) == 0
    assert (tmp_path / "c.html").read_text().lstrip().lower().startswith("<!doctype html")


# ---------------------------------------------------------------------------------------------
# empty or malformed option text
@pytest.mark.parametrize("text, fragment", [("", "--tolerance"), (" ", "--tolerance"),
                                            ("A=", "--tolerance"), ("A10", "--tolerance"),
                                            ("Q=3", "--tolerance")])
def test_iso230_2_tolerance_refused(tmp_path, capsys, text, fragment):
    run = write_run(tmp_path / "run.csv")
    one_line_error(capsys, main(["iso230-2", str(run), "--tolerance", text]), fragment)


@pytest.mark.parametrize("text", ["", " ", "E0=", "E0=1.5+L/", "banana"])
def test_iso10360_mpe_refused(tmp_path, capsys, text):
    from volerr.cmm.examples import write_example_errors

    write_example_errors(tmp_path / "errors", "MB1")
    one_line_error(capsys, main(["iso10360", "MB1", "--errors", str(tmp_path / "errors"),
                                 "--mpe", text]), "--mpe")


# ---------------------------------------------------------------------------------------------
# a unit header contradicted by the magnitudes
def test_iso230_2_um_values_under_mm_header_refused(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv", header="deviation_mm")
    one_line_error(capsys, main(["iso230-2", str(run), "--json", str(tmp_path / "r.json")]),
                   "_mm header")
    assert not (tmp_path / "r.json").exists()


def test_iso230_2_deviation_beyond_half_the_target_spacing_refused(tmp_path, capsys):
    # targets 1 mm apart, deviations near 0.7 mm: the machine would stand at the next target
    run = write_run(tmp_path / "run.csv", header="deviation_mm", scale=0.5,
                    targets=np.arange(0.0, 9.0))
    one_line_error(capsys, main(["iso230-2", str(run)]), "half the smallest target spacing")


def test_iso230_2_mm_header_with_mm_values_accepted(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv", header="deviation_mm", scale=1e-3)
    assert main(["iso230-2", str(run)]) == 0


# ---------------------------------------------------------------------------------------------
# demo: the folder is checked before any computing
def test_demo_refuses_a_used_folder_before_computing(tmp_path, capsys, monkeypatch):
    import volerr.demo.cmm_sections as demo

    def never(*a, **k):
        raise AssertionError("the demo computed before refusing its folder")

    monkeypatch.setattr(demo, "cmm", never)
    (tmp_path / "D").mkdir()
    (tmp_path / "D" / "index.html").write_text("earlier run")
    one_line_error(capsys, main(["demo", "--out", str(tmp_path / "D"), "--only", "cmm_a"]),
                   "--force")
    assert (tmp_path / "D" / "index.html").read_text() == "earlier run"


# ---------------------------------------------------------------------------------------------
# a full disk at write time
@pytest.fixture(scope="module")
def dmu50_example(tmp_path_factory):
    from volerr.fiveaxis.example import write_example

    d = tmp_path_factory.mktemp("dmu50")
    ex = write_example(d, "DMU50")
    # a short program: the first 40 lines of the hemisphere
    short = d / "short.nc"
    short.write_text("".join(ex["program"].read_text().splitlines(True)[:40]))
    return {"errors": ex["errors"], "program": short}


@pytest.mark.parametrize("room", [0, 2000])
def test_compensate_on_a_full_disk_is_one_line(tmp_path, capsys, monkeypatch, dmu50_example,
                                               room):
    out = tmp_path / "F.nc"
    argv = ["compensate", "DMU50", "--errors", str(dmu50_example["errors"]),
            str(dmu50_example["program"]), "--out", str(out), "--report",
            str(tmp_path / "r.csv")]
    with full_disk(monkeypatch, room):
        code = main(argv)
    one_line_error(capsys, code, "no space left")
    assert sorted(p.name for p in tmp_path.iterdir()) == []   # nothing staged left, nothing


@pytest.mark.parametrize("option", ["--json", "--html", "--plot"])
def test_iso230_2_on_a_full_disk_is_one_line(tmp_path, capsys, monkeypatch, option):
    run = write_run(tmp_path / "run.csv")
    name = {"--json": "r.json", "--html": "r.html", "--plot": "r.png"}[option]
    with full_disk(monkeypatch):
        code = main(["iso230-2", str(run), option, str(tmp_path / name)])
    one_line_error(capsys, code, "no space left")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run.csv"]


def test_a_replaced_file_survives_a_full_disk(tmp_path, capsys, monkeypatch):
    run = write_run(tmp_path / "run.csv")
    (tmp_path / "r.json").write_text("before")
    with full_disk(monkeypatch):
        code = main(["iso230-2", str(run), "--json", str(tmp_path / "r.json")])
    one_line_error(capsys, code, "no space left")
    assert (tmp_path / "r.json").read_text() == "before"


# ---------------------------------------------------------------------------------------------
# controller tables
@pytest.fixture(scope="module")
def mb1_errors(tmp_path_factory):
    from volerr.cmm.examples import write_example_errors

    d = tmp_path_factory.mktemp("mb1") / "errors"
    write_example_errors(d, "MB1")
    return d


def test_heidenhain_export_never_replaces_a_com_beside_it(tmp_path, capsys, dmu50_example):
    argv = ["controller", "export", "DMU50", "--errors", str(dmu50_example["errors"]),
            "--format", "heidenhain", "--out", str(tmp_path / "c.cma")]
    (tmp_path / "c_X.com").write_text("the user's table\n")
    one_line_error(capsys, main(argv), "--force")
    assert (tmp_path / "c_X.com").read_text() == "the user's table\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["c_X.com"]
    assert main(argv + ["--force"]) == 0
    assert (tmp_path / "c_X.com").read_text().startswith("BEGIN c_X.com")
    capsys.readouterr()
    # a second export without --force: the .cma and its .com files are there now
    one_line_error(capsys, main(argv), "--force")


@pytest.mark.parametrize("fmt, good, bad", [("sinumerik-lec", ",X1]", ",X9]"),
                                            ("sinumerik-lec", ",X1]", ",X2]"),
                                            ("sinumerik-cec", "(AX1)", "(X9)")])
def test_sinumerik_unknown_machine_axis_refused(tmp_path, capsys, mb1_errors, fmt, good, bad):
    f = tmp_path / "t.spf"
    # --force: MB1's CEC tables leave more than none (refused without it); axis names here
    assert main(["controller", "export", "MB1", "--errors", str(mb1_errors), "--format", fmt,
                 "--out", str(f), "--force"]) == 0
    text = f.read_text()
    assert good in text
    f.write_text(text.replace(good, bad))
    capsys.readouterr()
    one_line_error(capsys, main(["controller", "import", "MB1", str(f), "--format", fmt,
                                 "--errors-out", str(tmp_path / "imp")]), "unknown axis")
    assert not (tmp_path / "imp").exists()


# ---------------------------------------------------------------------------------------------
# bad data refused: artifacts, multilateration
@pytest.fixture(scope="module")
def ballplate(tmp_path_factory):
    from volerr.calibrate.examples import write_ballplate_example

    d = tmp_path_factory.mktemp("plate")
    return write_ballplate_example(d / "plate.csv", "MB1")["path"]


def _calibrate(*argv):
    return main(["calibrate", *map(str, argv)])


def test_artifact_every_row_twice_refused(tmp_path, capsys, ballplate):
    head, *rows = ballplate.read_text().splitlines()
    f = tmp_path / "twice.csv"
    f.write_text("\n".join([head, *rows, *rows]) + "\n")
    one_line_error(capsys, _calibrate("MB1", f, "--json", tmp_path / "r.json"),
                   "a row given twice")
    assert not (tmp_path / "r.json").exists()


def test_artifact_placement_copied_under_a_new_label_refused(tmp_path, capsys, ballplate):
    head, *rows = ballplate.read_text().splitlines()
    first = rows[0].split(",")[0]
    copy = [r.replace(first + ",", "copy,", 1) for r in rows if r.startswith(first + ",")]
    f = tmp_path / "copied.csv"
    f.write_text("\n".join([head, *rows, *copy]) + "\n")
    one_line_error(capsys, _calibrate("MB1", f), "copied under a new label")


def test_artifact_ball_twice_with_different_coordinates_refused(tmp_path, capsys, ballplate):
    head, *rows = ballplate.read_text().splitlines()
    cells = rows[1].split(",")
    cells[1] = rows[0].split(",")[1]           # the second ball gets the first one's label
    f = tmp_path / "label.csv"
    f.write_text("\n".join([head, rows[0], ",".join(cells), *rows[2:]]) + "\n")
    one_line_error(capsys, _calibrate("MB1", f), "different calibrated coordinates")


def test_artifact_repeated_probing_of_a_ball_accepted(tmp_path, capsys, ballplate):
    """The same ball probed twice (same calibrated coordinates, its own reading) is data."""
    head, *rows = ballplate.read_text().splitlines()
    cells = rows[0].split(",")
    cells[6] = f"{float(cells[6]) + 0.0003:.6f}"
    f = tmp_path / "repeat.csv"
    f.write_text("\n".join([head, *rows, ",".join(cells)]) + "\n")
    assert _calibrate("MB1", f, "--parameters", "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z",
                      "--degree", "1") == 0


@pytest.fixture(scope="module")
def multilateration(tmp_path_factory):
    from volerr.calibrate.examples import write_multilateration_example

    d = tmp_path_factory.mktemp("ml")
    return write_multilateration_example(d / "ml.csv", "DMU50", n=200)["path"]


@pytest.mark.parametrize("command", ["calibrate", "loop"])
@pytest.mark.parametrize("keep", [("S1",), ("S1", "S2")])
def test_distances_from_too_few_stations_refused(tmp_path, capsys, multilateration, command,
                                                 keep):
    head, *rows = multilateration.read_text().splitlines()
    j = head.split(",").index("station")
    f = tmp_path / "few.csv"
    f.write_text("\n".join([head, *[r for r in rows if r.split(",")[j] in keep]]) + "\n")
    one_line_error(capsys, main([command, "DMU50", str(f), "--json", str(tmp_path / "r.json")]),
                   "at least 3")
    assert not (tmp_path / "r.json").exists()


# ---------------------------------------------------------------------------------------------
# found by the hostile sweep
@pytest.fixture(scope="module")
def sphere_file(tmp_path_factory):
    from volerr.calibrate.examples import write_sphere_example

    d = tmp_path_factory.mktemp("sphere")
    return write_sphere_example(d / "s.csv", "DMU50")["path"]


def _replace_cell(src, dst, row, column, value):
    head, *rows = src.read_text().splitlines()
    j = head.split(",").index(column)
    cells = rows[row].split(",")
    cells[j] = value
    rows[row] = ",".join(cells)
    dst.write_text("\n".join([head, *rows]) + "\n")
    return dst


@pytest.mark.parametrize("column", ["X", "sphere_x", "dx_um", "Zp"])
def test_sphere_implausibly_large_number_refused(tmp_path, capsys, sphere_file, column):
    f = _replace_cell(sphere_file, tmp_path / "big.csv", 3, column, "1e300")
    one_line_error(capsys, _calibrate("DMU50", f), "implausibly large")


@pytest.mark.parametrize("value, fragment", [("", "empty placement label"),
                                             ("typo", "has 1 row")])
def test_sphere_placement_label_of_one_row_refused(tmp_path, capsys, sphere_file, value,
                                                   fragment):
    f = _replace_cell(sphere_file, tmp_path / "label.csv", 5, "placement", value)
    one_line_error(capsys, _calibrate("DMU50", f), fragment)


@pytest.mark.parametrize("column, value, fragment", [
    ("placement", "typo", "has 1 row"), ("placement", "", "empty placement label"),
    ("ball", "", "empty ball label"), ("x_mm", "1e300", "implausibly large")])
def test_artifact_bad_label_or_number_refused(tmp_path, capsys, ballplate, column, value,
                                              fragment):
    f = _replace_cell(ballplate, tmp_path / "bad.csv", 7, column, value)
    one_line_error(capsys, _calibrate("MB1", f), fragment)


@pytest.mark.parametrize("argv, fragment", [
    (["probe-cal", "p.csv", "--sphere-radius", "nan", "--out", "m.csv"], "--sphere-radius"),
    (["probe-cal", "p.csv", "--sphere-radius", "25", "--ball-radius", "inf", "--out", "m.csv"],
     "--ball-radius"),
    (["calibrate", "MB1", "f.csv", "--seed", "-1"], "--seed"),
    (["ballbar", "simulate", "MB1", "--errors", "e", "--plane", "XY", "--radius", "1e9",
      "--centre", "0,0,0", "--out", "t.csv"], "--radius"),
])
def test_nonfinite_or_out_of_range_option_refused(tmp_path, capsys, monkeypatch, argv,
                                                  fragment, mb1_errors):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "e").symlink_to(mb1_errors)
    one_line_error(capsys, main(argv), fragment)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["e"]


@pytest.mark.parametrize("argv, fragment", [
    (["iso230-2", "RUN", "--json="], "--json: empty value"),
    (["iso230-2", ""], "empty argument"),
    (["map", "MB1", "--errors", " "], "--errors: empty value"),
    (["calibrate", "MB1", "RUN", "--parameters", ""], "--parameters: empty value"),
])
def test_empty_argument_refused(tmp_path, capsys, argv, fragment):
    run = write_run(tmp_path / "run.csv")
    argv = [str(run) if a == "RUN" else a for a in argv]
    one_line_error(capsys, main(argv), fragment)


def _twice(src, dst, block=slice(None)):
    """The file with a block of its rows given a second time at the end."""
    head, *rows = [ln for ln in src.read_text().splitlines() if not ln.startswith("#")]
    dst.write_text("\n".join([head, *rows, *rows[block]]) + "\n")
    return dst


@pytest.mark.parametrize("kind", ["sphere", "distances", "deviations"])
def test_rows_pasted_twice_refused(tmp_path, capsys, sphere_file, multilateration, kind):
    if kind == "sphere":
        f, layout = _twice(sphere_file, tmp_path / "s.csv", slice(3, 9)), "DMU50"
    elif kind == "distances":
        f, layout = _twice(multilateration, tmp_path / "d.csv"), "DMU50"
    else:
        src = tmp_path / "dev.csv"
        assert main(["simulate", "MB1", "--points", "60", "--out", str(src)]) == 0
        f, layout = _twice(src, tmp_path / "twice.csv", slice(0, 1)), "MB1"
    capsys.readouterr()
    one_line_error(capsys, _calibrate(layout, f), "pasted twice")


def test_distances_one_station_per_file_counted_over_the_campaign(tmp_path, capsys,
                                                                   multilateration):
    """A tracking interferometer moved from station to station is often saved one file per
    station: three such files make a campaign of three stations (accepted), two do not."""
    head, *rows = multilateration.read_text().splitlines()
    j = head.split(",").index("station")
    files = []
    for name in ("S1", "S2", "S3"):
        f = tmp_path / f"{name}.csv"
        f.write_text("\n".join([head, *[r for r in rows if r.split(",")[j] == name]]) + "\n")
        files.append(str(f))
    one_line_error(capsys, main(["calibrate", "DMU50", *files[:2], "--json",
                                 str(tmp_path / "r2.json")]), "at least 3")
    assert main(["calibrate", "DMU50", *files, "--json", str(tmp_path / "r3.json")]) == 0
