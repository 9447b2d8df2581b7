"""The commands of branch cli-a are argparse + one API call (issue 42 item 4): what a command
checked or wrote itself is now the API's, so a Python user gets the same refusal (the same
one line) and the same files.  Each case runs the command in-process and the API function on
the same input; expected values are stated from the rules (Pahk's plan: 5 circles x 20
azimuths + the pole; the drift file's run labels), not read back from the code."""

from __future__ import annotations

from pathlib import Path

import pytest

import volerr
from volerr.cli import main
from volerr.errors import InputError


def _refusal(capsys, argv) -> str:
    """The one stderr line of a refused command, without the ``volerr CMD: error:`` prefix."""
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "Traceback" not in err
    return err.split(": error: ", 1)[1]


def _positioning_run(path: Path) -> Path:
    """A long-format ISO 230-2 run: 4 targets x 2 cycles x both directions (um)."""
    rows = ["target_mm,cycle,direction,deviation_um"]
    for i, target in enumerate((0, 100, 200, 300)):
        for cycle in (1, 2):
            rows += [f"{target},{cycle},+1,{0.5 * i + 0.1 * cycle}",
                     f"{target},{cycle},-1,{0.5 * i + 1.0 - 0.1 * cycle}"]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_iso230_2_budget_options_refused_alike(tmp_path, capsys):
    run = _positioning_run(tmp_path / "run.csv")
    said = _refusal(capsys, ["iso230-2", str(run), "--alignment-mm", "2000"])
    assert said == "--alignment-mm must be a number between 0 and 1000, got 2000"
    with pytest.raises(InputError) as exc:
        volerr.iso230_2(str(run), alignment_mm=2000.0)
    assert str(exc.value) == said


def test_iso230_2_correction_conditions():
    from volerr.positioning.api import correction_conditions

    assert correction_conditions() == {}
    assert correction_conditions(11.5, 21.25) == {
        "expansion coefficient": "11.5 ppm/K (corrected to 20 \u00b0C)",
        "material temperature": "21.25 \u00b0C"}


def test_uncertainty_temperature_refused_alike(tmp_path, capsys):
    task = tmp_path / "task.csv"           # the options are refused before the task is read
    said = _refusal(capsys, ["uncertainty", "MB1", "--task", str(task), "--evaluate",
                             "distance", "--part-cte", "11.5", "0"])
    assert said.startswith("--part-cte = 11.5 1/K is 1.15e+07 ppm/K")
    with pytest.raises(InputError) as exc:
        volerr.uncertainty("MB1", task, "distance", temperature={"part_cte": (11.5, 0.0)})
    assert str(exc.value) == said
    said = _refusal(capsys, ["uncertainty", "MB1", "--task", str(task), "--evaluate",
                             "distance", "--scale-dt", "1", "-0.2"])
    assert said == "--scale-dt: value and a non-negative u"


def test_temperature_model_pairs():
    from volerr.uncertainty.api import temperature_model

    assert temperature_model() is None
    assert temperature_model(compensated=True) is None      # nothing uncertain to draw
    t = temperature_model(part_cte=(11.5e-6, 1e-6), scale_dt=(0.5, 0.1), compensated=True)
    assert (t.part_cte, t.u_part_cte, t.part_dt, t.u_part_dt) == (11.5e-6, 1e-6, 0.0, 0.0)
    assert (t.scale_cte, t.scale_dt, t.u_scale_dt, t.compensated) == (0.0, 0.5, 0.1, True)


def test_probe_plan_is_the_commands_plan(tmp_path, capsys):
    from volerr.probe.api import probe_plan

    out = tmp_path / "plan.csv"
    assert main(["probe-cal", "--plan", str(out), "--sphere-radius", "12.5", "--ball-radius",
                 "1.5", "--center", "10,20,30"]) == 0
    assert capsys.readouterr().out == f"plan: 101 points -> {out}\n"
    res = probe_plan(12.5, 1.5, center=(10.0, 20.0, 30.0))
    assert res.csv_text() == out.read_text(encoding="utf-8")
    lines = res.csv_text().splitlines()
    assert len(lines) == 1 + 5 * 20 + 1            # header, Pahk's 5 circles x 20, the pole
    x, y, z = (float(v) for v in lines[1].split(",")[:3])
    assert (x, y, z) == pytest.approx((10.0, 20.0, 30.0 + 12.5 + 1.5))   # the pole: +z
    custom = probe_plan(12.5, 1.5, phis="30, 60", per_circle=4, pole=False)
    assert custom.csv_text() == probe_plan(12.5, 1.5, phis=[30, 60], per_circle=4,
                                           pole=False).csv_text()
    assert custom.summary() == "plan: 8 points"


def test_probe_plan_and_cal_refused_alike(tmp_path, capsys):
    from volerr.probe.api import probe_plan

    said = _refusal(capsys, ["probe-cal", "--plan", str(tmp_path / "p.csv"),
                             "--sphere-radius", "12.5"])
    with pytest.raises(InputError, match="^--plan needs --ball-radius") as exc:
        probe_plan(12.5, None)
    assert str(exc.value) == said
    said = _refusal(capsys, ["probe-cal", str(tmp_path / "data.csv"), "--sphere-radius", "12.5",
                             "--ball-radius", "-1", "--out", str(tmp_path / "map.csv")])
    assert said == "--ball-radius must be a positive length in mm, got -1.0"
    with pytest.raises(InputError) as exc:
        volerr.probe_cal(tmp_path / "data.csv", 12.5, ball_radius=-1.0)
    assert str(exc.value) == said
    assert not (tmp_path / "map.csv").exists()


def _two_run_drift(path: Path) -> Path:
    rows = ["# channel d_a: X", "run,t_s,d_a_um,T_room"]
    for run, k in (("A", 1.0), ("B", 2.0)):
        rows += [f"{run},{60 * i},{k * i * i},{20 + 0.1 * i}" for i in range(6)]
    path.write_text("\n".join(rows) + "\n", encoding="utf-8")
    return path


def test_iso230_3_one_plot_per_run(tmp_path, capsys):
    f = _two_run_drift(tmp_path / "drift.csv")
    res = volerr.iso230_3(f)
    assert res.plot_paths(None) == []
    assert res.plot_paths(tmp_path / "p.png") == [tmp_path / "p_A.png", tmp_path / "p_B.png"]
    with pytest.raises(InputError, match="plot file must end in .png, got .*p.jpg"):
        res.plot_paths(tmp_path / "p.jpg")
    assert main(["iso230-3", str(f), "--plot", str(tmp_path / "p.png")]) == 0
    assert capsys.readouterr().out == res.summary() + "\n"
    assert sorted(p.name for p in tmp_path.glob("p*.png")) == ["p_A.png", "p_B.png"]
    one = tmp_path / "one.csv"
    one.write_text("# channel d_a: X\nt_s,d_a_um,T_room\n0,0,20\n60,1,20.1\n120,3,20.3\n",
                   encoding="utf-8")
    assert volerr.iso230_3(one).plot_paths("q.png") == [Path("q.png")]


def test_drift_convert_is_the_commands_conversion(tmp_path, capsys):
    from volerr.example_files import write_drift_examples
    from volerr.instruments.drift_test import drift_convert

    write_drift_examples(tmp_path)
    raw, out = tmp_path / "drift_logger_raw.csv", tmp_path / "drift.csv"
    assert main(["drift", "convert", str(raw), "--out", str(out), "--channel", "ch1=X at z=20",
                 "--channel", "ch2=Z"]) == 0
    printed = capsys.readouterr().out
    res = drift_convert(raw, channels=["ch1=X at z=20", "ch2=Z"])
    assert res.text == out.read_text(encoding="utf-8")
    assert printed == res.summary(str(out)) + "\n"
    assert drift_convert(raw, channels={"ch1": "X at z=20", "ch2": "Z"}).text == res.text
    assert res.to_dict()["runs"][0]["channels"]["ch1"] == "X"
    said = _refusal(capsys, ["drift", "convert", str(raw), "--out", str(tmp_path / "x.csv"),
                             "--map", "nonsense"])
    with pytest.raises(InputError) as exc:
        drift_convert(raw, mapping="nonsense")
    assert str(exc.value) == said


def test_history_wait_refused_alike(tmp_path, capsys):
    db = tmp_path / "h.sqlite"
    said = _refusal(capsys, ["history", "show", "--db", str(db), "--machine", "M1", "--wait",
                             "5000"])
    assert said == "--wait 5000: 0 to 3600 s"
    for call in (lambda: volerr.history.show(str(db), "M1", wait_s=5000),
                 lambda: volerr.history.add(str(db), "M1", ["r.json"], wait_s=5000)):
        with pytest.raises(InputError) as exc:
            call()
        assert str(exc.value) == said
    assert not db.exists()


def test_uncertainty_plot_is_the_results_png(tmp_path, capsys):
    task = tmp_path / "task.csv"
    task.write_text("X,Y,Z\n100,100,100\n400,100,100\n", encoding="utf-8")
    png = tmp_path / "h.png"
    argv = ["uncertainty", "MB1", "--task", str(task), "--evaluate", "distance", "--noise-um",
            "0.5", "--samples", "200", "--contributions", "0", "--quiet", "--plot", str(png)]
    assert main(argv) == 0
    assert capsys.readouterr().out == ""                       # --quiet
    res = volerr.uncertainty("MB1", task, "distance", noise_um=0.5, samples=200,
                             contributions=0)
    assert res.png() == png.read_bytes()
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
