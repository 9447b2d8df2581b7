"""Bad instrument files get exit 2 and one clear stderr line, no traceback, nothing written
(issue 19, sixth "Done when" item); the files of before -- the loop's 3-D deviations and the
laser-tracker files of ``identify`` -- keep working (smoke runs with existing-format files)."""

import json

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers.in_process import volerr as volerr_command
from helpers.tracker_sim import simulate as tracker_simulate
from helpers.tracker_sim import smooth_errors, to_csv
from instruments._common import Campaign, check_one_line_error, in_process, random_setup

# module-scoped simulated data: keep the module on one xdist worker
pytestmark = pytest.mark.xdist_group("test_instrument_files")


@pytest.fixture(scope="module")
def good(tmp_path_factory):
    """A good MB1 ballbar file and a good TT_AC sphere file (columns dict each)."""
    m = S.Machine("MB1")
    bb = S.concat([S.ballbar_circle(m, "bb.csv", "XY", (450.0, 290.0, 200.0), 100.0, 72, d,
                                    "P1") for d in (1, -1)])
    cb = Campaign(m, [bb], [S.constant("EC0Y")], {"EC0Y": 20.0}, {}, seed=1)
    t = S.Machine("TT_AC")
    sp = S.sphere_block(t, "sp.csv", {"P1": (80, 0, 30), "P2": (-60, 60, 90)},
                        [{"A": a, "C": c} for a in (0, 30) for c in range(0, 360, 60)])
    cs = Campaign(t, [sp], [S.constant("EX0C")], {"EX0C": 10.0},
                  random_setup([sp], np.random.default_rng(2)), seed=3)
    return {"ballbar": S.columns(m, bb, cb.y[0]), "sphere": S.columns(t, sp, cs.y[0])}


def _variant(cols, drop=(), change=None):
    out = {k: np.array(v, dtype=object) for k, v in cols.items() if k not in drop}
    if change:
        change(out)
    return out


def _nan(cols):
    cols["dr_um"][7] = float("nan")


def _longer(cols):
    cols["length_mm"] = np.array(cols["length_mm"], float) + 1.0     # radius != positions


CASES = {
    "ballbar without pivot": ("ballbar", "MB1", dict(drop=("pivot_x", "pivot_y", "pivot_z")),
                              "ballbar:", ("pivot",)),
    "ballbar without pivot, kind detected": (
        "ballbar", "MB1", dict(drop=("pivot_x", "pivot_y", "pivot_z")), "", ()),
    "ballbar length differs from positions": ("ballbar", "MB1", dict(change=_longer), "",
                                              ("length", "radius")),
    "ballbar NaN": ("ballbar", "MB1", dict(change=_nan), "", ()),
    "sphere without placement": ("sphere", "TT_AC", dict(drop=("placement",)), "",
                                 ("placement",)),
}


# every case through calibrate; the loop (same readers) on two of them
RUNS = [("calibrate", c) for c in sorted(CASES)] + [
    ("loop", "ballbar length differs from positions"), ("loop", "sphere without placement")]


@pytest.mark.parametrize("command,case", RUNS)
def test_bad_file_exit_2_one_line(tmp_path, good, case, command):
    kind, layout, how, prefix, keywords = CASES[case]
    cols = _variant(good[kind], **how)
    path = S.write_csv(tmp_path / "bad.csv", cols)
    before = open(path).read()
    out = tmp_path / "out.json"
    r = volerr_command(command, layout, prefix + path, "--json", out)   # python -m volerr
    check_one_line_error(r, *keywords)
    assert not out.exists()
    assert open(path).read() == before


def test_ballbar_evaluate_refuses_inconsistent_length(tmp_path, good):
    cols = _variant(good["ballbar"], change=_longer)
    path = S.write_csv(tmp_path / "bad.csv", cols)
    out = tmp_path / "ev.json"
    r = volerr_command("ballbar", "evaluate", path, "--json", out)
    check_one_line_error(r, "length", "radius")
    assert not out.exists()


def test_loop_deviations_file_still_works(tmp_path):
    """The loop on a 3-D deviations file of the existing format (MB1, exact chain, static
    squareness and scale errors, 0.5 um noise): runs and finds nothing on this clean data."""
    m = S.Machine("MB1")
    rng = np.random.default_rng(8)
    n = 300
    pos = {a: rng.uniform(*m.travel[a], n) for a in m.axes}
    probe = np.zeros((n, 3))
    b = S.Block("deviations", "dev.csv", pos, probe, np.full(n, "P1", dtype=object), 0.5)
    terms = [S.constant("EC0Y"), S.constant("EB0Z"), S.series("EXX", 1, 0.0, 900.0)]
    camp = Campaign(m, [b], terms, {"EC0Y": 15.0, "EB0Z": -10.0, "EXX@slope": 0.01}, {},
                    seed=9)
    path = S.write_csv(tmp_path / "dev.csv", S.columns(m, b, camp.y[0]))
    r = in_process("loop", "MB1", path, "--json", tmp_path / "l.json", "--degree", "2")
    assert r.returncode == 0, r.stderr[-3000:]
    doc = json.loads((tmp_path / "l.json").read_text())
    assert doc["effects"] == [], doc["effects"]
    assert doc["n_points"] == n
    noise3 = float(np.sqrt(np.mean(np.sum(camp.noise[0] ** 2, axis=1))))
    # the declared model holds the truth: the held-out residual is of the size of the noise,
    # far below the planted errors (tens of um)
    assert doc["rms_after_um"] < 2 * noise3, (doc["rms_after_um"], noise3)


def test_identify_tracker_file_still_works(tmp_path):
    """``identify`` on a three-point laser-tracker file (exact rigid-body simulation, no
    noise): the positioning error of X is returned exactly."""
    ref = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -100.0], [10.0, -60.0, -200.0]])
    pos = np.linspace(0, 500, 6)
    e = smooth_errors(pos, seed=1)
    f = tmp_path / "tracker.csv"
    f.write_text(to_csv([tracker_simulate("linear", ref, pos, e)], pos, ("P", "Q", "K")))
    out = tmp_path / "X.csv"
    r = in_process("identify", "MB1", "--axis", "X", f, "--out", out)
    assert r.returncode == 0, r.stderr[-3000:]
    vals = np.loadtxt(out, delimiter=",", skiprows=1)
    assert np.allclose(vals[:, 1] * 1e-3, e[:, 0], atol=1e-6)
