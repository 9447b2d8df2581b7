"""``volerr calibrate`` on laser-interferometer runs (issue 20): an ISO 230-2 positioning run of
MB1's X axis with the moving optic 100 mm off the tool point (an Abbe arm along the tool) and a
planted pitch error, simulated with the independent exact chain
(tests/helpers/metrology_sim.py).

* The run alone (written in the ISO 230-2 wide format with the line in ``#`` header lines --
  the same file ``volerr iso230-2`` evaluates): it sees ``EXX`` plus the pitch times the arms,
  so the report must call ``EXX`` and ``EBX`` undetermined and confounded with each other (as
  the rank analysis of the finite-difference design says) and suggest a plan that separates
  them.
* With an angular run of the same axis about Y (pitch optics): ``EXX`` and ``EBX`` are
  identified within 3 standard uncertainties, the identifiability agrees with the rank
  analysis, each file's held-out residual is at the floor of the true model on the same
  split (in its own unit: um and urad), and nothing is flagged inconsistent.  A straightness
  run (vertical, about an unknown beam line) in the same campaign gives ``EZX``'s curvature.

A straightness run would not do instead of the angular one: it reads the lateral motion of
the optic, to which the pitch contributes only through an arm along the axis itself, which a
straightness function of the same axis absorbs."""

import numpy as np

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from instruments._common import FLOOR_FACTOR, K_SIGMA, in_process, run_json, series_terms

VALUES = {"EXX@slope": 0.010, "EXX@P2": 1.5, "EBX@slope": 0.015, "EBX@P2": 4.0,
          "EZX@P2": -1.2}
SETUP = {"pos.csv:zero": 0.8, "pitch.csv:zero": 12.0, "straight.csv:zero": -3.0,
         "straight.csv:slope": 25.0}
FOUR = ("EXX@slope", "EXX@P2", "EBX@slope", "EBX@P2")


def _write_wide(path, blk, values_um):
    """The ISO 230-2 wide format (one row per target, fwd_<cycle>_um / bwd_<cycle>_um) with
    the line's header lines."""
    table = {}
    for t, c, d, v in zip(blk.targets, blk.cycle, blk.direction, values_um):
        table[(float(t), f"{'fwd' if d > 0 else 'bwd'}_{c}_um")] = float(v)
    cols = sorted({k[1] for k in table}, key=lambda s: (s.split("_")[1], s[0] != "f"))
    lines = [f"# axis: {blk.axis}", f"# mode: {blk.mode}",
             "# at: " + ", ".join(f"{a}={v!r}" for a, v in blk.at.items()),
             "# optics: " + ", ".join(repr(float(v)) for v in blk.optics),
             f"# u_um: {blk.u!r}", "target_mm," + ",".join(cols)]
    for t in sorted({k[0] for k in table}):
        lines.append(f"{t!r}," + ",".join(repr(table[(t, c)]) for c in cols))
    path.write_text("\n".join(lines) + "\n")
    return path


def test_abbe_offset_and_pitch(tmp_path):
    m = S.Machine("MB1")
    rng = np.random.default_rng(41)
    targets = np.linspace(0.0, 900.0, 11)
    at = {"Y": 300.0, "Z": 200.0}
    pos = M.line_block(m, "pos.csv", "positioning", "X", at, (0, 0, 100.0), targets, cycles=3)
    ang = M.line_block(m, "pitch.csv", "angular", "X", at, (0, 0, 100.0), targets, cycles=2,
                       sense=(0, 1.0, 0))
    straight = M.line_block(m, "straight.csv", "straightness", "X", at, (0, 0, 100.0),
                            targets, cycles=2, sense=(0, 0, 1.0))
    blocks = [pos, ang, straight]
    terms = series_terms(blocks, ["EXX", "EBX"], 2, with_offset=("EBX",))
    terms += series_terms(blocks, ["EZX"], 2, skip=("EZX@slope",))     # its slope: the gauge
    y = {b.name: M.simulate(m, b, terms, VALUES, SETUP, rng)[0] for b in blocks}
    opts = ["--parameters", "EXX,EBX,EZX", "--degree", "2", "--seed", "3"]

    # the positioning run alone, ISO 230-2 wide format: EXX and the pitch confounded
    wide = _write_wide(tmp_path / "pos.csv", pos, y["pos.csv"])
    iso = in_process("iso230-2", wide, "--axis", "X", "--json", tmp_path / "iso.json")
    assert iso.returncode == 0, iso.stderr          # the same file volerr iso230-2 reads
    r, doc = run_json(["calibrate", "MB1", wide, *opts], tmp_path / "alone.json")
    assert r.returncode == 0, r.stderr[-3000:]
    ok_a, _ = S.identifiability(M.design(m, [pos], [t for t in terms if t.target != "EZX"]))
    for p in FOUR:
        assert not ok_a[p] and not doc["identifiability"][p]["identifiable"], p
        assert p in doc["unidentifiable"]
    assert "EBX@P2" in doc["identifiability"]["EXX@P2"]["confounded_with"]
    assert "EXX@slope" in doc["identifiability"]["EBX@slope"]["confounded_with"]
    helps = [e for e in doc["plan"] if set(FOUR) <= set(e["makes_identifiable"])]
    assert helps, doc["plan"]
    assert doc["instruments"][0]["n"] == len(targets)          # data rows of the wide file

    # with the angular run: both identified
    folder = tmp_path / "both"
    folder.mkdir()
    M.write_run(folder / "pos.csv", pos, y["pos.csv"])          # the long format this time
    M.write_run(folder / "pitch.csv", ang, y["pitch.csv"])
    M.write_run(folder / "straight.csv", straight, y["straight.csv"])
    r, doc = run_json(["calibrate", "MB1", *(folder / b.name for b in blocks), *opts],
                      tmp_path / "both.json")
    assert r.returncode == 0, r.stderr[-3000:]
    d = M.design(m, blocks, terms)
    ok, rel = S.identifiability(d)
    assert all(ok[p] for p in FOUR + ("EZX@P2",)), rel
    assert not ok["EBX@offset"]                  # a constant pitch: no relative reading sees it
    for p, ident in ok.items():
        assert doc["identifiability"][p]["identifiable"] == ident, p
    bad = [(p, doc["parameters"][p]["value"], VALUES[p], doc["parameters"][p]["std"])
           for p in FOUR + ("EZX@P2",) if abs(doc["parameters"][p]["value"] - VALUES[p])
           > K_SIGMA * doc["parameters"][p]["std"]]
    assert not bad, bad
    units = {i["file"]: i["unit"] for i in doc["instruments"]}
    assert units == {"pos.csv": "um", "pitch.csv": "urad", "straight.csv": "um"}
    yy = np.concatenate([y[b.name] for b in blocks])
    test = np.zeros(len(yy), bool)
    for bi, b in enumerate(blocks):
        (inst,) = [i for i in doc["instruments"] if i["file"] == b.name]
        test |= (d.rows[:, 0] == bi) & np.isin(d.rows[:, 1], inst["test_rows"])
    true_cols = [j for j, c in enumerate(d.columns) if j >= d.n_params or VALUES.get(c)]
    sub = S.Design(d.J[:, true_cols], [d.columns[j] for j in true_cols], 5, d.rows, d.weights)
    _, _, res = S.wls(sub, yy, ~test)
    for bi, b in enumerate(blocks):
        (inst,) = [i for i in doc["instruments"] if i["file"] == b.name]
        sel = test & (d.rows[:, 0] == bi)
        floor = float(np.sqrt(np.mean(res[sel] ** 2)))
        assert floor / FLOOR_FACTOR <= inst["heldout_rms"] <= FLOOR_FACTOR * floor, (
            b.name, inst["heldout_rms"], floor)
    assert doc["consistency"]["inconsistent"] == []
