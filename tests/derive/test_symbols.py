"""Nominal symbols of the chain (issue 21): the generated ``symbol_sensitivity`` -- d(tool
point)/d(symbol) for the probe offset components, the axis positions, the layout parameters and
the fixed frames' offsets and angles -- against central differences of the independent exact
chain (tests/helpers/family_sim.py on instrument_sim.py: it parses the layout and never calls
generated code); effect terms that target a symbol (``param.h``, ``probe.Zp``, ``axis.C``,
``frame.F.angle`` ...) give an augmented model whose error is the exact chain's with the symbol
changed, and whose columns are the loop's candidate columns; the readings' projection applies
(a ballbar's length)."""

import re

import numpy as np
import pytest

import volerr
from helpers import family_sim as F
from helpers import instrument_sim as S
from volerr.errors import InputError
from volerr.machine.layout import parse_layout

#: a machine with a table C whose axis point holds the parameter r and a tool-side frame that
#: is rotated (30 deg about x) and translated by an expression of the parameter h
CUSTOM = """name = "SYMTEST"
kind = "machine_tool"
[parameters]
r = 40.0
h = 120.0
[axes.X]
kind = "linear"
direction = [1, 0, 0]
travel = [-200, 200]
[axes.Y]
kind = "linear"
direction = [0, 1, 0]
travel = [-200, 200]
[axes.Z]
kind = "linear"
direction = [0, 0, 1]
travel = [0, 300]
[axes.C]
kind = "rotary"
direction = [0, 0, 1]
point = ["r", 0, 0]
travel = [-360, 360]
[frames.holder]
translation = [5.0, "0.1*h", "-h"]
rotation = {axis = [1, 0, 0], angle_deg = 30}
[chain]
tool = ["X", "Y", "Z", "holder"]
workpiece = ["C"]
[squareness]
EC0Y = "X"
"""

#: effect terms on every kind of symbol (distinct parameters: one column each)
EFFECTS = """
[effects.grow]
kind = "thermal"
terms = [{parameter = "KH", target = "param.h", basis = "(T_s - 20)"},
         {parameter = "KR", target = "param.r", basis = "(T_s - 20)"},
         {parameter = "KP", target = "probe.Zp", basis = "Zp*(T_s - 20)"},
         {parameter = "KQ", target = "probe.Xp", basis = "Xp*(T_s - 20)"},
         {parameter = "KC", target = "axis.C", basis = "C*(T_s - 20)"},
         {parameter = "KZ", target = "axis.Z", basis = "(T_s - 20)"},
         {parameter = "KF", target = "frame.holder.angle", basis = "(T_s - 20)"},
         {parameter = "KY", target = "frame.holder.y", basis = "(T_s - 20)"}]
"""
#: effect parameter -> (symbol, the variable of a proportional basis)
TERMS = {"KH": ("param.h", None), "KR": ("param.r", None), "KP": ("probe.Zp", "Zp"),
         "KQ": ("probe.Xp", "Xp"), "KC": ("axis.C", "C"), "KZ": ("axis.Z", None),
         "KF": ("frame.holder.angle", None), "KY": ("frame.holder.y", None)}


@pytest.fixture(scope="module")
def custom(tmp_path_factory):
    folder = tmp_path_factory.mktemp("symtest")
    path = folder / "SYMTEST.toml"
    path.write_text(CUSTOM + EFFECTS)
    return folder, path, volerr.load(str(path))


def _state(model, rng, n):
    pos = {a: rng.uniform(*model.travel[a], n) for a in model.axes}
    probe = rng.normal(0.0, 60.0, (n, 3))
    return pos, probe


def _symbols(model, pos, probe):
    s = model.module.symbol_sensitivity(**model.positions(pos), Xp=probe[:, 0],
                                        Yp=probe[:, 1], Zp=probe[:, 2])
    return np.moveaxis(np.broadcast_to(s, (3, len(model.symbols), len(probe))), -1, 0)


def _varied_layout(folder, text, symbol, h) -> str:
    """A copy of the layout file with one parameter or frame value changed by h (mm / rad)."""
    kind, _, rest = symbol.partition(".")
    h = float(h)
    if kind == "param":
        text = re.sub(rf"(?m)^{rest} = (.*)$", lambda m: f"{rest} = {float(m[1]) + h!r}", text)
    elif symbol == "frame.holder.angle":
        text = text.replace("angle_deg = 30", f"angle_deg = {30 + float(np.rad2deg(h))!r}")
    elif symbol == "frame.holder.y":
        text = text.replace('"0.1*h"', f'"0.1*h + {h!r}"')
    p = folder / f"v{abs(hash((symbol, h)))}.toml"
    p.write_text(text)
    return str(p)


def _differences(machine_of, layout_text, folder, symbol, pos, probe, h=1e-3):
    """Central difference of the exact nominal tool point for a change of ``symbol``."""
    kind, _, rest = symbol.partition(".")
    out = []
    for s in (h, -h):
        p, q = dict(pos), probe.copy()
        m = machine_of
        if kind == "probe":
            q[:, "XYZ".index(rest[0])] += s
        elif kind == "axis":
            p[rest] = pos[rest] + (np.rad2deg(s) if rest in m.rotary else s)
        else:
            m = F.Machine(_varied_layout(folder, layout_text, symbol, s))
        out.append(m.tool_point(p, None, q))
    return (out[0] - out[1]) / (2 * h)


@pytest.mark.parametrize("layout", ["MB1", "CY", "DMU50", "TT_AC", "HH_BC", "TH_BC"])
def test_shipped_symbol_sensitivity_against_exact_chain(layout, tmp_path):
    from volerr.machine.layout import layout_text

    model = volerr.load(layout)
    assert model.symbols[:3] == ("probe.Xp", "probe.Yp", "probe.Zp")
    machine = F.Machine(layout)
    pos, probe = _state(model, np.random.default_rng(3), 6)
    got = _symbols(model, pos, probe)
    text, _ = layout_text(layout)
    for j, s in enumerate(model.symbols):
        want = _differences(machine, text, tmp_path, s, pos, probe)
        np.testing.assert_allclose(got[:, :, j], want, rtol=1e-6, atol=2e-6, err_msg=s)


def test_custom_symbols_frames_and_parameters_against_exact_chain(custom):
    folder, path, model = custom
    assert model.symbols == ("probe.Xp", "probe.Yp", "probe.Zp", "axis.X", "axis.Y", "axis.Z",
                             "axis.C", "param.h", "param.r", "frame.holder.x",
                             "frame.holder.y", "frame.holder.z", "frame.holder.angle")
    machine = F.Machine(str(path))
    pos, probe = _state(model, np.random.default_rng(4), 6)
    got = _symbols(model, pos, probe)
    text = path.read_text()
    for j, s in enumerate(model.symbols):
        if s in ("frame.holder.x", "frame.holder.z"):
            continue     # the same mechanism as frame.holder.y (checked)
        want = _differences(machine, text, folder, s, pos, probe)
        np.testing.assert_allclose(got[:, :, j], want, rtol=1e-6, atol=2e-6, err_msg=s)


def test_effect_on_a_symbol_is_the_symbol_changed(custom):
    """Each effect term's column in the augmented model is the symbol's column times its basis
    (the loop's candidate), and its first-order error is the exact chain's with the symbol
    changed by parameter x basis."""
    folder, path, model = custom
    rng = np.random.default_rng(5)
    pos, probe = _state(model, rng, 5)
    T = rng.uniform(18.0, 26.0, 5)
    sens = model.sensitivity(pos, probe, covariates={"T_s": T})
    sym = _symbols(model, pos, probe)
    rad = model.positions(pos)
    text = path.read_text()
    machine = F.Machine(str(path))
    for pn, (symbol, var) in TERMS.items():
        factor = (T - 20) * ({"Zp": probe[:, 2], "Xp": probe[:, 0]}.get(var, None)
                             if var in ("Zp", "Xp") else rad[var] if var else 1.0)
        col = sens[:, :, model.parameters.index(pn)]
        np.testing.assert_allclose(col, sym[:, :, model.symbols.index(symbol)]
                                   * factor[:, None], atol=1e-9, err_msg=pn)
        # the derivative of the exact chain for a change of the symbol by k * basis
        k = 1e-3
        got = model.volumetric_error(pos, {pn: k}, probe=probe, covariates={"T_s": T})
        for i in range(5):
            p_i = {a: pos[a][i:i + 1] for a in pos}
            d = k * factor[i]
            want = _differences(machine, text, folder, symbol, p_i, probe[i:i + 1]) * d
            np.testing.assert_allclose(got[i], want[0], rtol=1e-6, atol=1e-10, err_msg=pn)


def test_ballbar_rows_project_the_symbol(tmp_path):
    """A ballbar's reading changes with a symbol by the bar direction times the symbol's
    column: Observations.symbol_sensitivity of a ballbar file against central differences of
    the exact bar length with the trunnion height h of TT_AC changed."""
    import volerr.instruments as instruments

    machine = F.Machine("TT_AC")
    b = S.ballbar_sweep(machine, "sweep.csv", "C", 0.0, 300.0, 24, pivot=(60.0, 0.0, 40.0),
                        bar=(0.0, 100.0, 0.0), rotary={"A": 30.0})
    path = S.write_csv(tmp_path / "sweep.csv", S.columns(machine, b, np.zeros(b.n)))
    model = volerr.load("TT_AC")
    obs = instruments.read(f"ballbar:{path}", model)
    got = obs.symbol_sensitivity(model)[:, 0, model.symbols.index("param.h")]
    h = 1e-3
    lengths = []
    for s in (h, -h):
        with machine.parameters({"h": np.full(b.n, 150.0 + s)}, b.n):
            t = machine.tool_point(b.pos, None, b.probe)
        lengths.append(np.linalg.norm(t - b.pivot, axis=1))
    np.testing.assert_allclose(got, (lengths[0] - lengths[1]) / (2 * h), atol=1e-6)
    assert np.ptp(got) > 0.1          # the sweep sees h


@pytest.mark.parametrize("target,basis,message", [
    ("param.q", "(T_C - 20)", "unknown target 'param.q'"),
    ("frame.nope.x", "(T_C - 20)", "unknown target 'frame.nope.x'"),
    ("probe.Wp", "(T_C - 20)", "unknown target 'probe.Wp'"),
    ("axis.B", "(T_C - 20)", "unknown target 'axis.B'"),
    ("param.h", "(h - 20)", "basis uses 'h'"),
])
def test_symbol_targets_checked(target, basis, message):
    text = CUSTOM + ("[effects.e]\nkind = \"thermal\"\nterms = [{parameter = \"K\", "
                     f"target = \"{target}\", basis = \"{basis}\"}}]\n")
    with pytest.raises(InputError, match=re.escape(message)):
        parse_layout(text)


def test_probe_offsets_in_a_basis_are_not_covariates():
    lay = parse_layout(CUSTOM + EFFECTS)
    assert lay.covariates == ("T_s",)
    assert "KP" in lay.parameter_names and lay.parameter_kind["KP"] == "effect"
