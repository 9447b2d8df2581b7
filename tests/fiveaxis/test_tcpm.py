"""TCPM programs (tool tip in the workpiece frame): a TCPM program and its machine-axis
equivalent give the same actual tool tips after compensation, on an independent controller
(tests/helpers/nc_sim with an inverse from the independent exact chain) and chain
(helpers.fiveaxis_chain.tool2work); with --orientation the tool-axis error shrinks (tool-vector
programs); Heidenhain plain language gives the same numbers as ISO; bad programs get exit 2
naming the line."""

import re

import numpy as np
import pytest
from helpers import nc_sim
from helpers.error_dirs import write_errors
from test_compensate import cli
from helpers.fiveaxis_chain import tool2work

import volerr
from volerr.errors import InputError
from volerr.fiveaxis.compensate import ErrorModel
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

L = 120.0                       # tool length, mm
TOOL = np.array([0.0, 0.0, -L])  # the tip against the tool axis


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=21)
    return m, ErrorFunctions.from_dir(d, m), d


def _htm(m, q, errors=None):
    return tool2work(m.name, dict(zip(m.axes, q)), errors or {})


def _tip(m, q, errors=None):
    return (_htm(m, q, errors) @ np.r_[TOOL, 1.0])[:3]


def _inverse_linear(m, tip, rot):
    """Independent nominal inverse for fixed rotary positions: the chain is affine in X Y Z."""
    base = np.r_[0.0, 0.0, 0.0, rot]
    t0 = _tip(m, base)
    a = np.column_stack([_tip(m, base + np.r_[np.eye(3)[k], 0, 0]) - t0 for k in range(3)])
    return np.linalg.solve(a, tip - t0)


def _positions(rng, n):
    return np.column_stack([rng.uniform(-150, 150, n), rng.uniform(-150, 150, n),
                            rng.uniform(150, 300, n), rng.uniform(5, 80, n),
                            rng.uniform(0, 300, n)])


def _errors_at(m, funcs, q):
    e = funcs(ErrorModel(m, funcs).lookup(np.atleast_2d(q)))
    return [{k: float(v[r]) for k, v in e.items()} for r in range(len(np.atleast_2d(q)))]


def _programs(m, rng, n=25):
    q = _positions(rng, n)
    tips = np.array([_tip(m, row) for row in q])
    tcpm = ["%", "N10 G90 G17 T1 M6", "G0 X0 Y0 Z250 B0 C0 (axis positions)",
            "N20 G43.4 H1 (TCPM on)"]
    iso_axes = ["%", "N10 G90 G17"]
    for k, (t, row) in enumerate(zip(tips, q)):
        tcpm.append(f"N{30 + 10 * k} G1 X{t[0]:.4f} Y{t[1]:.4f} Z{t[2]:.4f} B{row[3]:.3f} "
                    f"C{row[4]:.3f} F1000")
        # the axis positions the controller takes from these words (independent inverse)
        tr = np.round(t, 4)
        rot = np.round(row[3:], 3)
        lin = _inverse_linear(m, tr, rot)
        iso_axes.append(f"G1 X{lin[0]:.6f} Y{lin[1]:.6f} Z{lin[2]:.6f} B{rot[0]:.3f} "
                        f"C{rot[1]:.3f}")
    tcpm += ["G49", "G0 X0 Y0 Z250 B0 C0", "M30", "%"]
    iso_axes += ["M30", "%"]
    return "\n".join(tcpm) + "\n", "\n".join(iso_axes) + "\n", tips


def _run_tcpm(m, text):
    inv = lambda tip, rot: _inverse_linear(m, tip, rot)  # noqa: E731
    return [mv for mv in nc_sim.moves(text, m.axes, tcpm_inverse=inv)]


def _actual(m, funcs, q):
    errs = _errors_at(m, funcs, q)
    return np.array([_tip(m, row, e) for row, e in zip(q, errs)])


def test_tcpm_program_and_its_axis_equivalent_land_on_the_same_tips(setup):
    m, funcs, _ = setup
    tcpm_text, axis_text, tips = _programs(m, np.random.default_rng(3))
    out_t = compensate_program(m, funcs, tcpm_text, tool_table={1: L})
    out_a = compensate_program(m, funcs, axis_text, tool=tuple(TOOL), decimals=6)
    assert out_t.summary()["tcpm_blocks"] == len(tips)
    # the controller: TCPM words through its nominal inverse; axis words as they are
    tc = lambda text: [mv for mv in _run_tcpm(m, text) if mv.tcpm][1:]  # noqa: E731
    q_t = np.array([[mv.end[a] for a in m.axes] for mv in tc(out_t.text)])
    q_a = np.array([[mv.end[a] for a in m.axes] for mv in nc_sim.moves(out_a.text, m.axes)])
    q_before = np.array([[mv.end[a] for a in m.axes] for mv in tc(tcpm_text)])
    assert len(q_t) == len(tips) - 1 and len(q_a) == len(tips) - 1   # moves: from block 2 on
    # the axis-position blocks around the TCPM section are compensated as in an axis program
    axes_rep = [r for r in out_t.reports if "TCPM" not in r.status]
    assert len(axes_rep) == 2 and all(r.status == "compensated" for r in axes_rep)
    want = np.round(tips[1:], 4)
    act_t, act_a = _actual(m, funcs, q_t), _actual(m, funcs, q_a)
    before = _actual(m, funcs, q_before)
    assert np.linalg.norm(before - want, axis=1).max() > 5e-3
    assert np.linalg.norm(act_t - act_a, axis=1).max() < 0.2e-3
    assert np.linalg.norm(act_t - want, axis=1).max() < 0.15e-3
    # the rotary words are the programmed ones (orientation not compensated)
    assert re.findall(r"B[\d.]+ C[\d.]+", out_t.text) == re.findall(r"B[\d.]+ C[\d.]+",
                                                                    tcpm_text)


def _axis(m, q, errors=None):
    return _htm(m, q, errors)[:3, 2]


def test_tool_vector_program_with_orientation_corrects_the_tool_axis(setup):
    """G43.5 with I J K: the controller's inverse gives the rotary axes from the vector;
    --orientation writes a corrected vector so that the actual tool axis is the programmed
    one, and the tip still lands."""
    m, funcs, _ = setup
    rng = np.random.default_rng(5)
    q = _positions(rng, 12)
    lines = ["G90", "G43.5 H1"]
    for row in q:
        t, k = _tip(m, row), _axis(m, row)
        lines.append(f"G1 X{t[0]:.4f} Y{t[1]:.4f} Z{t[2]:.4f} I{k[0]:.7f} J{k[1]:.7f} "
                     f"K{k[2]:.7f}")
    text = "\n".join(lines + ["G49"]) + "\n"
    plain = compensate_program(m, funcs, text, tool_length=L)
    ori = compensate_program(m, funcs, text, tool_length=L, orientation=True)
    s0, s1 = plain.summary(), ori.summary()
    assert s0["max_orientation_after_urad"] > 20
    assert s1["max_orientation_after_urad"] < 0.25 * s0["max_orientation_after_urad"]
    # independently: words -> axis positions by Newton on the exact chain, then actual axis
    words = re.findall(r"X(\S+) Y(\S+) Z(\S+) I(\S+) J(\S+) K(\S+)", ori.text)
    words0 = re.findall(r"X(\S+) Y(\S+) Z(\S+) I(\S+) J(\S+) K(\S+)", text)
    for (w, w0, row) in zip(words, words0, q):
        w = np.array(w, float)
        w0 = np.array(w0, float)
        rot = _rotary_from_vector(m, w[3:], row[3:])
        lin = _inverse_linear(m, w[:3], rot)
        qq = np.r_[lin, rot]
        e = _errors_at(m, funcs, qq)[0]
        k_act = _axis(m, qq, e)
        assert np.linalg.norm(k_act - w0[3:] / np.linalg.norm(w0[3:])) < 5e-6
        assert np.linalg.norm(_tip(m, qq, e) - w0[:3]) < 0.2e-3


def _rotary_from_vector(m, k, near):
    """Nominal rotary positions for the tool vector ``k``, by Gauss-Newton from ``near``."""
    k = k / np.linalg.norm(k)
    r = np.array(near, float)
    for _ in range(20):
        f = _axis(m, np.r_[0, 0, 0, r])
        jac = np.column_stack([(_axis(m, np.r_[0, 0, 0, r + 1e-6 * np.eye(2)[j]]) - f) / 1e-6
                               for j in range(2)])
        step = np.linalg.lstsq(jac, k - f, rcond=None)[0]
        r = r + step
        if np.abs(step).max() < 1e-12:
            break
    return r


def _heidenhain(tcpm_text):
    out = ["0 BEGIN PGM TCPMTEST MM", "1 BLK FORM 0.1 Z X-200 Y-200 Z-50",
           "2 BLK FORM 0.2 X+200 Y+200 Z+50", "3 TOOL CALL 1 Z S12000", "4 M128 ; TCPM on"]
    n = 5
    for line in tcpm_text.splitlines():
        mm = re.search(r"X(\S+) Y(\S+) Z(\S+) B(\S+) C(\S+)", line)
        if mm and line.startswith("N"):         # the TCPM blocks
            vals = [float(v) for v in mm.groups()]
            words = " ".join(f"{a}{v:+.4f}" if a in "XYZ" else f"{a}{v:+.3f}"
                             for a, v in zip("XYZBC", vals))
            out.append(f"{n} L {words} R0 F1000")
            n += 1
    out += [f"{n} M129", f"{n + 1} END PGM TCPMTEST MM"]
    return "\r\n".join(out) + "\r\n"


def test_heidenhain_plain_language_gives_the_numbers_of_the_iso_program(setup):
    m, funcs, _ = setup
    tcpm_text, _, _ = _programs(m, np.random.default_rng(3), n=8)
    hh = _heidenhain(tcpm_text)
    iso = compensate_program(m, funcs, tcpm_text, tool_table={1: L})
    out = compensate_program(m, funcs, hh, tool_table={1: L})
    assert out.summary()["tcpm_blocks"] == 8
    num = r"([+-]?[\d.]+)"
    got = [[float(v) for v in g] for g in re.findall(
        rf"X{num} Y{num} Z{num} B{num} C{num}", out.text)]
    want = [[float(v) for v in g] for g in re.findall(
        rf"(?m)^N.*X{num} Y{num} Z{num} B{num} C{num}", iso.text)]
    assert got == want and got != [[float(v) for v in g] for g in re.findall(
        rf"X{num} Y{num} Z{num} B{num} C{num}", hh)]
    # every other byte kept; the signs written as the TNC does
    strip = lambda s: re.sub(r"[XYZBC][+-][\d.]+", "W", s)  # noqa: E731
    assert strip(out.text) == strip(hh)
    # a machine-axis plain-language program (no M128) works too
    axes_prog = hh.replace("4 M128 ; TCPM on", "4 ; no TCPM").replace("M129", "M5")
    res = compensate_program(m, funcs, axes_prog)
    assert res.summary()["tcpm_blocks"] == 0 and res.summary()["compensated"] == 8


@pytest.mark.parametrize("text,kw,msg", [
    ("G90\nG43.4 H7\nG1 X1 Y2 Z3 B10 C10\n", {"tool_table": {1: 120.0}},
     "line 2: tool H7 is not in the tool table"),
    ("; a program\nGOTO/10,20,30\n", {}, "line 2: unknown program dialect"),
    ("0 BEGIN PGM X MM\n1 CC X+0 Y+0\n", {}, "line 2: CC"),
    ("0 BEGIN PGM X MM\n1 L X+1 Y+2 Z+3 B+0 C+0 RL F100\n", {}, "line 2: radius compensation"),
    ("G90 G1 X0 Y0 Z200 B0 C0\nTRAORI\nG1 X1 Y2 Z3 A3=0 B3=0 C3=1 B5\n", {"tool_length": 99.0},
     "line 3: rotary axis B and a tool vector"),
])
def test_bad_programs_are_refused_naming_the_line(setup, text, kw, msg):
    m, funcs, _ = setup
    with pytest.raises(InputError, match=msg):
        compensate_program(m, funcs, text, **kw)


def test_cli_tcpm_without_tool_length_exit_2_one_line(setup, tmp_path):
    _, _, d = setup
    prog = tmp_path / "p.nc"
    prog.write_text("G90 G1 X0 Y0 Z200 B0 C0\nN20 G43.4 H1\nG1 X1 Y2 Z3 B10 C10\n")
    (tmp_path / "tools.csv").write_text("tool,length_mm\n2,120\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o")
    assert rc == 2 and "line 2: a TCPM program needs the tool length" in se and \
        len(se.strip().splitlines()) == 1, se
    assert not (tmp_path / "o").exists()
    rc, so, se = cli("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o",
                     "--tool-table", tmp_path / "tools.csv")
    assert rc == 2 and "line 2: tool H1 is not in the tool table" in se, se


def test_tool_length_rule():
    from volerr.nc.tcpm import length_rule

    assert length_rule(None, None) is None
    rule = length_rule(None, {1: 100.0, 2: 80.5})
    assert rule({"T": 2.0}, "line 1") == 80.5
    assert rule({"T": 2.0, "H": 1.0}, "line 1") == 100.0        # Fanuc: H wins
    assert rule({"T": 1.0, "DL": 0.25}, "line 1") == 100.25     # Heidenhain delta length
    assert length_rule(55.0, None)({"T": 1.0}, "x") == 55.0
    # both given: the table's tools must agree with --tool-length; others take it
    assert length_rule(55.0, {1: 55.0})({"T": 1.0}, "x") == 55.0
    assert length_rule(55.0, {1: 100.0})({"T": 2.0}, "x") == 55.0
    with pytest.raises(InputError, match="line 4: --tool-length 55 mm and the tool table's "
                                         "100 mm for tool T1 disagree"):
        length_rule(55.0, {1: 100.0})({"T": 1.0}, "line 4")
    with pytest.raises(InputError, match="line 9: TCPM with no T"):
        rule({}, "line 9")


@pytest.mark.parametrize("body", ["TRAORI\nG1 X1 Y2 Z3 A3=0 B3=0 C3=0\n",
                                  "G43.5 H1\nG1 X1 Y2 Z3 I0 J0 K0\n",
                                  "G43.5 H1\nG1 X1 Y2 Z3 I0 J0 K1\nG1 X2 K0\n"])
def test_cli_zero_tool_vector_one_error_line(setup, tmp_path, body):
    """A zero tool vector has no direction: one error line naming it (no numpy warning
    before it), exit 2, nothing written."""
    _, _, d = setup
    prog = tmp_path / "p.nc"
    prog.write_text("G90 G1 X0 Y0 Z200 B0 C0\n" + body)
    rc, so, se = cli("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o",
                     "--tool-length", "100")
    line = len(body.splitlines()) + 1
    assert rc == 2 and se.strip() == (f"volerr compensate: error: line {line}: the tool vector "
                                      "is zero (I J K or A3 B3 C3 all 0): it gives no tool "
                                      "direction"), se
    assert not (tmp_path / "o").exists()


def test_cli_tool_length_and_table_disagreeing_refused(setup, tmp_path):
    _, _, d = setup
    prog = tmp_path / "p.nc"
    prog.write_text("G90 G1 X0 Y0 Z200 B0 C0\nT1 M6\nN30 G43.4\nG1 X1 Y2 Z3 B10 C10\n")
    (tmp_path / "tools.csv").write_text("tool,length_mm\n1,100\n")
    args = ("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o",
            "--tool-table", tmp_path / "tools.csv", "--tool-length")
    rc, so, se = cli(*args, "50")
    assert rc == 2 and len(se.strip().splitlines()) == 1 and \
        "line 3: --tool-length 50 mm and the tool table's 100 mm for tool T1 disagree" in se, se
    assert not (tmp_path / "o").exists()
    rc, so, se = cli(*args, "100")
    assert rc == 0, se


def test_tool_vector_program_has_no_note_of_rotary_axes_at_zero(setup, tmp_path):
    """The vectors of a G43.5 / TRAORI program set the rotary axes: no note that they are
    never programmed (the program never writes a B or C word)."""
    m, funcs, d = setup
    text = "G90 G43.5 H1\nG1 X10 Y20 Z30 I0.1 J0.2 K0.97\nG1 X11 I0.12 J0.2 K0.97\n"
    res = compensate_program(m, funcs, text, tool_length=L)
    assert res.assumed_zero == () and res.summary()["compensated"] == 2
    prog = tmp_path / "p.nc"
    prog.write_text(text)
    rc, so, se = cli("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o",
                     "--tool-length", str(L))
    assert rc == 0 and "never programmed" not in se, se
    # an axis-position program that never writes C still gets the note
    prog.write_text("G90 G1 X0 Y0 Z200 B10\nG1 X1\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", d, prog, "--out", tmp_path / "o2")
    assert rc == 0 and "note: axes C are never programmed: taken at 0 deg" in se, se


def _controller_rule(m, vectors, previous):
    """The controller's rule for tool vectors, block by block, written here from the
    documented rule (volerr formats gcode, TCPM): both solutions of the generated inverse,
    an axis that does not turn the tool there stays, each value turned to the one nearest
    the previous block's, then by 360 deg into the travel; the solution inside the travel
    with the smaller move, the first on a tie."""
    rot = m.rotary_axes
    lo = [m.travel[a][0] - 1e-9 for a in rot]
    hi = [m.travel[a][1] + 1e-9 for a in rot]
    prev, out = [float(v) for v in previous], []
    for k in vectors / np.linalg.norm(vectors, axis=1, keepdims=True):
        sols = []
        for branch in (1.0, -1.0):
            r = [float(np.rad2deg(v)) for v in m.module.inverse_rotary(*k, branch)]
            q = np.r_[0.0, 0.0, 0.0, r]
            at_q = _axis(m, q)
            turns = [np.linalg.norm((_axis(m, q + 1e-7 * np.eye(5)[3 + j]) - at_q)
                                    / np.deg2rad(1e-7)) for j in range(2)]
            sols.append([x if t > 1e-6 else None for x, t in zip(r, turns)])
        best = None
        for sol in sols:
            vals, inside, move = [], True, 0.0
            for j, x in enumerate(sol):
                x = prev[j] if x is None else x
                x = prev[j] + (x - prev[j] + 180.0) % 360.0 - 180.0
                for turn in (0.0, 360.0, -360.0):
                    if lo[j] <= x + turn <= hi[j]:
                        x += turn
                        break
                else:
                    inside = False
                vals.append(x)
                move += abs(x - prev[j])
            score = move + (0.0 if inside else 1e6)
            if best is None or score < best[0]:
                best = (score, vals)
        prev = best[1]
        out.append(prev)
    return np.array(out)


@pytest.mark.parametrize("layout", ["DMU50", "HH_BC", "TT_AC"])
def test_rotary_positions_of_tool_vectors_follow_the_controller_rule(layout):
    """All rows at once (rotary_from_vector) = the rule block by block, written
    independently: random and smooth tool paths, vertical stretches (an undetermined axis
    stays), paths turning the endless axis beyond its travel (turned back by 360 deg)."""
    from volerr.fiveaxis.tcpm_kinematics import rotary_from_vector

    m = volerr.load(layout)
    rng = np.random.default_rng(7)
    n = 450
    t = np.linspace(0, 60, n)
    tilt = np.r_[np.deg2rad(rng.uniform(3, 60, n // 3)),
                 np.deg2rad(np.maximum(0, 40 * np.sin(t[:n // 3] / 2))),
                 np.deg2rad(30 + 25 * np.sin(t[:n - 2 * (n // 3)] / 7))]
    az = np.r_[np.deg2rad(rng.uniform(0, 360, n // 3)), t[:n // 3] * 1.3,
               t[:n - 2 * (n // 3)] * 2.0]
    vec = np.column_stack([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)])
    want = _controller_rule(m, vec, [0.0, 10.0])
    got = rotary_from_vector(m, vec, np.array([0.0, 10.0]))
    assert np.ptp(want[:, 1]) > 360                      # the endless axis turns more than once
    assert np.abs(got - want).max() < 1e-9


@pytest.mark.parametrize("layout", ["DMU50", "HH_BC", "TT_AC"])
def test_rotary_solve_with_a_guess_is_the_rule_bit_for_bit(layout):
    """A guess (round_tcpm passes the corrected axes' rotary positions) only speeds the
    solve up: with a guess a few ulps off, one from another start, one on the other branch
    or turned by 360 deg, and one of noise, the result is that of the block-by-block rule to
    the last bit (block_by_block, the reference the guess-free solve is tested against
    above)."""
    from volerr.fiveaxis.tcpm_kinematics import (_candidates, _limits, block_by_block,
                                                 rotary_from_vector)

    m = volerr.load(layout)
    rng = np.random.default_rng(11)
    n = 400
    tilt = np.deg2rad(np.r_[rng.uniform(3, 60, n - 40), np.zeros(20), rng.uniform(3, 60, 20)])
    az = np.r_[np.deg2rad(rng.uniform(0, 360, n - 40)), np.zeros(20), np.linspace(0, 20, 20)]
    vec = np.column_stack([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)])
    start = np.array([0.0, 10.0])
    lo, hi = _limits(m)
    want = block_by_block(_candidates(m, vec), start, lo, hi)
    near = rotary_from_vector(m, vec, start + [1e-9, -1e-9])
    flipped = want.copy()
    flipped[::7, 1] += 360.0
    flipped[3::11] = -flipped[3::11]
    for guess in (near, want * (1 + 1e-15), flipped, rng.uniform(-400, 400, (n, 2))):
        got = rotary_from_vector(m, vec, start, guess)
        assert np.array_equal(got, want)


def test_closed_form_pseudo_inverse_step_matches_numpy_pinv():
    """The batched 2x2 closed form of the Newton step (pinv_apply_3x2) against numpy's SVD
    pinv with the same cutoff: well conditioned, nearly and exactly rank deficient, zero."""
    from volerr.machine.kinematics import pinv_apply_3x2

    rng = np.random.default_rng(5)
    j = rng.normal(size=(4000, 3, 2))
    r = rng.normal(size=(4000, 3))
    j[:100, :, 1] = 2 * j[:100, :, 0]                   # rank 1
    j[100:200, :, 1] *= 1e-8                             # below the cutoff: dropped
    j[200:300, :, 1] *= 1e-4                             # above it: kept
    j[300:310] = 0.0
    want = np.einsum("nij,nj->ni", np.linalg.pinv(j, rcond=1e-6), r)
    got = pinv_apply_3x2(j, r, rcond=1e-6)
    scale = np.abs(want).max(axis=1, keepdims=True) + 1e-300
    assert np.abs(got - want).max(axis=1).max() < 1e-6          # the 1e-4 rows: cond 1e4
    assert np.all(np.abs(got - want)[300:] / scale[300:] < 1e-12)
    assert np.all(got[300:310] == 0.0)
