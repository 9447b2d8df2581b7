"""``volerr plan --instrument interferometer``: laser beam lines along each linear axis through a
grid of Abbe offsets, for each optic asked.  The plan's files are filled by the exact simulator
of tests/helpers/metrology_sim.py (never volerr's model: its own chain, tests/helpers/
instrument_sim.py), with set-up unknowns (zero, scale, beam slope) and noise of the files'
declared ``u``, and calibrated with no options: every determined parameter within 3 std of the
planted value and the realised std within 0.7-1.4 x the plan's ``predicted_std``; every target
inside the travel; the NC program passes through the rows, in order, each followed by a dwell."""

from __future__ import annotations

import json
import re

import numpy as np
import pytest

from helpers import instrument_sim as S
from helpers import metrology_sim as M
from helpers import plan_designs, plan_fill
from volerr.calibrate.run import calibrate
from volerr.cli import main
from volerr.machine.layout import read_layout

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("planning_interferometer")

PLAN = ["MB1", "--instrument", "interferometer", "--readings", "1200"]
#: planted errors (JSON units: um, urad; slopes per mm, Legendre coefficients over the range)
PLANTED = {"EXX@slope": 0.010, "EYY@slope": -0.008, "EZZ@slope": 0.005, "EYX@P2": -1.0,
           "EZX@P2": 1.5, "EBX@slope": 0.02, "ECY@slope": -0.015, "EXZ@P2": 0.8}


@pytest.fixture(scope="module")
def plan(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("interferometer")
    out, js = tmp / "plan", tmp / "plan.json"
    with plan_designs.designed_once():    # the design shared with the Heidenhain plan below
        assert main(["plan", *PLAN, "--out", str(out), "--json", str(js)]) == 0
    return out, json.loads(js.read_text())


def _header(comments) -> dict:
    out = {}
    for c in comments:
        m = re.match(r"#\s*(axis|mode|at|optics|sense|separation|u_um|u_urad):\s*(.*)$", c)
        if m:
            out[m.group(1)] = m.group(2)
    return out


def _line(machine, path):
    """The file as a metrology_sim line (its header lines and rows)."""
    comments, cols = plan_fill.read(path)
    h = _header(comments)
    at = {a.split("=")[0].strip(): float(a.split("=")[1]) for a in h["at"].split(",")}
    vec = lambda t: np.array([float(v) for v in t.split(",")])  # noqa: E731
    blk = M.line_block(machine, path.stem, h["mode"], h["axis"], at, vec(h["optics"]),
                       np.array([0.0, 1.0]), cycles=1,
                       sense=vec(h["sense"]) if "sense" in h else None,
                       separation=float(h.get("separation", 30.0)),
                       u=float(h.get("u_um", h.get("u_urad"))))
    blk.targets = np.array(cols["target_mm"], float)
    blk.direction = np.array(cols["direction"], float)
    blk.cycle = np.array(cols["cycle"], dtype=object)
    blk.pos = {a: (blk.targets.copy() if a == blk.axis else np.full(blk.n, at[a]))
               for a in machine.axes}
    return blk, comments, cols


def _ranges(blocks, machine) -> dict:
    return {a: (min(float(b.pos[a].min()) for b in blocks),
                max(float(b.pos[a].max()) for b in blocks)) for a in machine.axes}


def _terms(ranges) -> list:
    out = []
    for name in PLANTED:
        comp, key = name.split("@")
        k = 1 if key == "slope" else int(key[1:])
        out.append(S.series(comp, k, *ranges[comp[2]]))
    return out


@pytest.fixture(scope="module")
def executed(plan, tmp_path_factory):
    folder, doc = plan
    machine = S.Machine(doc["layout"])
    run = tmp_path_factory.mktemp("filled")
    lines = [(_line(machine, folder / f["file"]), f["file"]) for f in doc["files"]]
    terms = _terms(_ranges([b for (b, _, _), _ in lines], machine))
    rng = np.random.default_rng(11)
    paths = []
    for (blk, comments, cols), name in lines:
        setup = {f"{blk.name}:zero": rng.normal(0, 5.0),
                 f"{blk.name}:scale": rng.normal(0, 0.25),
                 f"{blk.name}:slope": rng.normal(0, 20.0)}
        values = M.line_readings(machine, blk, terms, PLANTED, setup)
        values = values + rng.normal(0, blk.u, blk.n)
        key = "deviation_urad" if blk.mode == "angular" else "deviation_um"
        cols[key] = [repr(float(v)) for v in values]
        plan_fill.write(run / name, comments, cols)
        paths.append(str(run / name))
    return calibrate(doc["layout"], paths, plan=False).data


def test_executed_plan_gives_the_planted_errors_and_the_predicted_std(plan, executed):
    _, doc = plan
    cal = executed
    assert set(cal["parameters"]) == set(doc["parameters"])
    assert len(doc["parameters"]) >= 20
    ratios = []
    for n, pred in doc["parameters"].items():
        got = cal["parameters"][n]
        assert got["unit"] == pred["unit"]
        assert pred["determined_alone_by"] == ["interferometer"]
        assert abs(got["value"] - PLANTED.get(n, 0.0)) < 3 * got["std"], (n, got)
        ratios.append(got["std"] / pred["predicted_std"])
        assert 0.7 <= ratios[-1] <= 1.4, (n, got, pred)
    print(f"realised / predicted std: {min(ratios):.3f} .. {max(ratios):.3f}")


def test_every_optic_and_axis_is_used_and_targets_stay_inside_the_travel(plan):
    folder, doc = plan
    layout = read_layout(doc["layout"])
    seen = set()
    for f in doc["files"]:
        comments, cols = plan_fill.read(folder / f["file"])
        h = _header(comments)
        seen.add((h["axis"], h["mode"]))
        assert f["kind"] == "interferometer"
        assert list(cols) == ["target_mm", "cycle", "direction",
                              "deviation_urad" if h["mode"] == "angular" else "deviation_um"]
        assert all(c == "" for c in cols[list(cols)[-1]])
        t = np.array(cols["target_mm"], float)
        lo, hi = layout.axes[h["axis"]].travel
        assert np.all((t >= lo) & (t <= hi))
        for part in h["at"].split(","):
            a, v = part.split("=")
            lo, hi = layout.axes[a.strip()].travel
            assert lo <= float(v) <= hi
        # ISO 230-2: equally spaced targets, both directions, whole cycles
        targets = np.unique(t)
        assert np.allclose(np.diff(targets), np.diff(targets)[0])
        cycles = len(t) // (2 * len(targets))
        assert cycles >= 2 and len(t) == 2 * cycles * len(targets)
        assert sorted(set(cols["direction"])) == ["+1", "-1"]
    assert sum(f["readings"] for f in doc["files"]) == doc["readings"] <= 1200
    modes = {m for _, m in seen}
    assert modes == {"positioning", "straightness", "angular"}
    assert {a for a, _ in seen} == {"X", "Y", "Z"}


def test_nc_program_passes_through_the_rows_with_a_dwell(plan):
    folder, doc = plan
    axes = read_layout(doc["layout"]).axis_names
    for f in doc["files"]:
        comments, cols = plan_fill.read(folder / f["file"])
        h = _header(comments)
        at = {a.split("=")[0].strip(): float(a.split("=")[1]) for a in h["at"].split(",")}
        rows = [{a: (float(t) if a == h["axis"] else at[a]) for a in axes}
                for t in cols["target_mm"]]
        lines = [ln.strip() for ln in (folder / f["nc"]).read_text().splitlines()]
        where, k = {}, 0
        for i, ln in enumerate(lines):
            code = re.sub(r"\(.*?\)", "", ln).split()
            if not code or code[0] not in ("G0", "G1"):
                continue
            where = {**where, **{w[0]: float(w[1:]) for w in code[1:] if w[0] != "F"}}
            if k < len(rows) and all(abs(where.get(a, np.nan) - rows[k][a]) < 1e-9
                                     for a in axes):
                assert lines[i + 1].startswith("G4 P")
                k += 1
        assert k == len(rows), f["file"]


def test_dialect_option_writes_that_dialect(plan, tmp_path):
    """``--dialect heidenhain``: the module's plan (its design made once: ``plan`` asks for it
    first, ``helpers.plan_designs``; the dialect is applied when the command writes the plan)
    written as Heidenhain programs.  Moved here from tests/plan/test_plan_nc.py (the suite's
    time, session 9), where it designed the same plan again."""
    out, js = tmp_path / "plan", tmp_path / "plan.json"
    with plan_designs.designed_once():
        assert main(["plan", *PLAN, "--dialect", "heidenhain", "--out", str(out), "--json",
                     str(js)]) == 0
    doc = json.loads(js.read_text())
    assert doc["nc_dialect"] == "heidenhain"
    for f in doc["files"]:
        assert f["nc"].endswith(".h")
        text = (out / f["nc"]).read_text()
        assert text.startswith("0 BEGIN PGM ") and "CYCL DEF 9.1 DWELL 3" in text
        assert max(map(len, text.splitlines())) < 254
    assert not list(out.glob("*.nc"))
