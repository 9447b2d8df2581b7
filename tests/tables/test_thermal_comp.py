"""Temperature compensation for SINUMERIK / ISG from an augmented layout's thermal effects:
planted effects a controller's error line carries exactly come back as its coefficients
(written in the files, evaluated here from the text); an effect through a lag leaves what
a static model cannot follow, and nothing once the sensors are lagged; bad input is one
line, exit 2."""

import json
import re

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.machine.layout import layout_text

KT_X = 5e-6       # 1/K: EXX = KT_X * X * (T_a - 20)
KT0_Z = 2e-3      # mm/K: EZZ = KT0_Z * (T_b - 20)


def _layout(tmp_path, x_basis="X*(T_a - 20)", name="MB1T_aug"):
    text, _ = layout_text("MB1")
    text = re.sub(r'(?m)^name\s*=\s*"[^"]*"', f'name = "{name}"', text, count=1)
    text += f'''
[effects.thermal_X]
kind = "thermal"
terms = [
  {{parameter = "KT_X", target = "EXX", basis = "{x_basis}"}},
]

[effects.thermal_Z]
kind = "thermal"
terms = [
  {{parameter = "KT0_Z", target = "EZZ", basis = "T_b - 20"}},
]
'''
    p = tmp_path / f"{name}.toml"
    p.write_text(text)
    return p


def _loop_json(tmp_path):
    p = tmp_path / "loop.json"
    p.write_text(json.dumps({"effects": [
        {"parameters": {"KT_X": KT_X * 1e6}, "units": {"KT_X": "um/m/K"}},
        {"parameters": {"KT0_Z": KT0_Z * 1e3}, "units": {"KT0_Z": "um/K"}}]}))
    return p


def _log(tmp_path):
    t = np.arange(0, 6 * 3600 + 1, 60.0)
    on = t < 3 * 3600                      # drives on for 3 h, then off: a step up and down
    t_a = 20 + np.where(on, 6 * (1 - np.exp(-t / 2400)),
                        6 * (1 - np.exp(-3 * 3600 / 2400)) * np.exp(-(t - 3 * 3600) / 2400))
    t_b = 20.5 + 1.5 * np.sin(t / 4000)
    p = tmp_path / "log.csv"
    p.write_text("t_s,T_a,T_b,T_room\n" + "".join(
        f"{a:g},{b:.4f},{c:.4f},20.1\n" for a, b, c in zip(t, t_a, t_b)))
    return p


def _export(tmp_path, layout, fmt, out, *extra):
    return main(["controller", "export", str(layout), "--format", fmt, "--loop-json",
                 str(_loop_json(tmp_path)), "--temperatures", str(_log(tmp_path)), "--out",
                 str(out), "--grid", "4", *extra])


def _evaluate(expr: str, temps: dict) -> float:
    """A written line ``c0+c1*(R1-20)`` evaluated at the temperatures (R1 ... or names)."""
    for k, v in temps.items():
        expr = re.sub(rf"\b{k}\b", repr(v), expr)
    assert re.fullmatch(r"[0-9.eE+\-*() ]+", expr), expr
    return eval(expr)


def test_static_effects_come_back_as_the_error_lines(tmp_path):
    lay = _layout(tmp_path)
    js = tmp_path / "s.json"
    assert _export(tmp_path, lay, "sinumerik-temp", tmp_path / "st", "--json", str(js)) == 0
    s = json.loads(js.read_text())
    assert s["worse_than_none"] is False and s["sensors"] == ["T_a", "T_b"]
    assert s["left_um"]["max"] < 0.01 * s["before_um"]["max"]          # carried exactly
    text = (tmp_path / "st" / "temp_comp.spf").read_text()
    lines = dict(re.findall(r"^\$(SA_TEMP_COMP_\w+\[\w+\])=(.+)$", text, re.M))
    m = volerr.load("MB1")
    p0x = 0.5 * sum(m.travel["X"])
    assert float(lines["SA_TEMP_COMP_REF_POSITION[X1]"]) == pytest.approx(p0x)
    for ta, tb in ((20.0, 20.0), (26.0, 21.5), (23.0, 19.0)):
        temps = {"R1": ta, "R2": tb}
        # EXX = KT_X X (T_a - 20) = K0 + tan(beta) (X - P0): tan(beta) = KT_X (T_a - 20)
        slope = _evaluate(lines["SA_TEMP_COMP_SLOPE[X1]"], temps)
        k0 = _evaluate(lines["SA_TEMP_COMP_ABS_VALUE[X1]"], temps)
        assert slope == pytest.approx(KT_X * (ta - 20), abs=2e-10)
        assert k0 == pytest.approx(KT_X * p0x * (ta - 20), abs=2e-6)
        assert _evaluate(lines["SA_TEMP_COMP_ABS_VALUE[Z1]"], temps) == \
            pytest.approx(KT0_Z * (tb - 20), abs=2e-6)
    assert "SA_TEMP_COMP_ABS_VALUE[Y1]" not in lines           # nothing moves Y
    # ISG: integers at 20 degC (0.1 um, um/m) and the PLC's formulas in comments
    assert _export(tmp_path, lay, "isg-temp", tmp_path / "it") == 0
    isg = (tmp_path / "it" / "temp_comp.lis").read_text()
    assert f"lr_param.temp_comp_position_0 {round(p0x * 1e4)}" in isg
    form = re.search(r"# axis X: coefficient = (.+)", isg).group(1)
    assert _evaluate(form, {"T_a": 24.0, "T_b": 20.0}) == pytest.approx(KT_X * 4, abs=2e-10)


def test_an_effect_through_a_lag_leaves_what_a_static_model_cannot_follow(tmp_path, capsys):
    lay = _layout(tmp_path, "X*(lag(T_a, 1800.0) - 20)", "MB1L_aug")
    js = tmp_path / "l.json"
    assert _export(tmp_path, lay, "sinumerik-temp", tmp_path / "st", "--json", str(js)) == 0
    out = capsys.readouterr().out
    assert "lags the controller's model does not compute" in out and "T_a: 1800 s" in out
    s = json.loads(js.read_text())
    b, left, lagged = s["before_um"], s["left_um"], s["left_with_lagged_sensors_um"]
    # the lag of a step: the raw sensor leads the structure by up to ~ the step itself
    assert 0.05 * b["max"] < left["max"] < b["max"] and left["rms"] < b["rms"]
    assert lagged["max"] < 1e-6
    assert s["lags"] == [{"covariate": "T_a", "lag_s": 1800.0}]


@pytest.mark.parametrize("edit, words", [
    ("no-json", "--loop-json"),
    ("no-time", "no time column"),
    ("time-back", "must increase"),
    ("no-sensor", "no column T_b"),
    ("not-aug", "no thermal effect"),
    ("no-value", "no value of KT0_Z"),
    ("errors", "--errors is not for"),
])
def test_bad_input_one_line_exit_2(tmp_path, capsys, edit, words):
    lay = _layout(tmp_path)
    log, js = _log(tmp_path), _loop_json(tmp_path)
    argv = ["controller", "export", str(lay), "--format", "isg-temp", "--loop-json", str(js),
            "--temperatures", str(log), "--out", str(tmp_path / "o")]
    text = log.read_text().splitlines()
    if edit == "no-json":
        argv = argv[:5] + argv[7:]
    elif edit == "no-time":
        log.write_text("\n".join(["time,T_a,T_b,T_room"] + text[1:]) + "\n")
    elif edit == "time-back":
        log.write_text("\n".join(text[:3] + [text[2]] + text[3:]) + "\n")
    elif edit == "no-sensor":
        log.write_text("\n".join(",".join(r.split(",")[:2]) for r in text) + "\n")
    elif edit == "not-aug":
        argv[2] = "MB1"
    elif edit == "no-value":
        js.write_text(json.dumps({"effects": [{"parameters": {"KT_X": 5.0},
                                               "units": {"KT_X": "um/m/K"}}]}))
    elif edit == "errors":
        argv += ["--errors", str(tmp_path)]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and words in err, err
    assert not (tmp_path / "o").exists()
