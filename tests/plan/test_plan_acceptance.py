"""Acceptance of ``volerr plan`` (issue 29; contract: INTERFACE.md "Planning" and the lead's
contracts note "Plan"), by a tester who never read nor called the planner's code: only its
command line, its files and its JSON.

Each case plans a campaign, EXECUTES it on an independent exact simulator
(tests/helpers/plan_exec.py on the chain of tests/helpers/instrument_sim.py: planted
parameters of realistic size, planted set-up errors, Gaussian noise of the file's declared
``u_um``, fixed seeds), feeds the filled files to ``volerr calibrate LAYOUT FILES --json F``
with NO options and checks

* every requested parameter within 3 standard uncertainties of the planted value, and the
  realised standard uncertainty within 0.7-1.4 x the plan's ``predicted_std``;
* every position of every plan file and every end point of its NC program inside the
  layout's travel (read from the layout by ``read_layout``);
* the NC program, parsed back by the test's own parser, moves through the file's rows in
  order as end points of motion blocks, with a ``G4`` dwell after each where the instrument
  reads at a stop;
* the predicted map uncertainty against the conventional plan at the same number of readings
  (the JSON's ``baseline``): no worse for the ballbar, at least 20 % better for the R-test;
* the mixed campaign (DMU50 sphere + distances) holds a parameter that only the combination
  determines (``determined_alone_by`` empty, ``predicted_std`` finite), and calibrate on each
  kind's files alone indeed does not determine it;
* one case planned with ``--parameters`` (MB1 ballbar, squareness): the plan writes the
  request into the files' header (``# parameters: ...``) and calibrate with no options fits
  exactly it;
* bad input: one error line, exit 2, nothing written.

The map comparison uses ``map_u_um.rms`` (the I-optimal criterion: the mean predicted variance
over the working volume); the ``max`` is reported in the assertion messages.
"""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from helpers import in_process, plan_designs
from helpers import instrument_sim as S
from helpers import plan_exec as P

#: the chance that an unbiased calibration fails the value check of one case: the bound per
#: parameter is Bonferroni's over the parameters checked together (a 3-std bound on each of
#: 12 parameters fails 3 % of unbiased runs: which cases passed depended on the seed)
FAMILY_ALPHA = 1e-3


def k_sigma(n_checked: int) -> float:
    """|value - truth| / std bound for ``n_checked`` estimates checked together."""
    from scipy.stats import norm

    return float(norm.isf(FAMILY_ALPHA / (2 * max(n_checked, 1))))


STD_RATIO = (0.7, 1.4)
UNITS = {"um", "urad", "um/mm", "urad/mm", "um/deg", "urad/deg"}
KINDS = {"ballbar", "sphere", "distances", "interferometer", "artifact"}

#: case -> layout, instrument specs, readings, how the map must compare with the baseline
#: (None: not checked; 1.0: no worse; 0.8: at least 20 % better), seed of the simulator
CASES = {
    "MB1-ballbar": ("MB1", ["ballbar:lengths=100,150,250"], 360, 1.0, 2901),
    "TT_AC-rtest": ("TT_AC", ["sphere:tool_u_um=0.5"], 240, 0.8, 2902),
    "DMU50-rtest": ("DMU50", ["sphere:tool_u_um=0.5"], 240, 0.8, 2903),
    "DMU50-mixed": ("DMU50", ["sphere:tool_u_um=0.5", "distances"], 480, None, 2904),
    "MB1-ballbar-squareness": ("MB1", ["ballbar:lengths=100,150,250"], 200, None, 2905),
}
#: cases planned with --parameters (the others: the instruments' defaults)
REQUEST = {"MB1-ballbar-squareness": "EC0Y,EB0Z,EA0Z"}


def _case(name):
    return pytest.param(name, id=name, marks=pytest.mark.xdist_group(f"plan_{name}"))


ALL = [_case(c) for c in CASES]
MIXED = [_case(c) for c in CASES if len(CASES[c][1]) > 1]


def run(*args):
    """``volerr ARGS`` through ``volerr.cli.main`` in this process with one BLAS thread: the
    command's parser, files, exit code and stderr as ``python -m volerr`` gives them, without
    starting an interpreter (``helpers.in_process``: a stray warning still counts as a line of
    stderr; the exit-2 paths too, their one line is ``main``'s)."""
    return in_process.volerr(*args)


def determined(entry) -> bool:
    v = entry.get("predicted_std")
    return isinstance(v, (int, float)) and math.isfinite(v) and v > 0


class Plan:
    """One ``volerr plan`` run: its JSON, its folder and its files read back."""

    def __init__(self, name, root: Path):
        layout, specs, n, _, _ = CASES[name]
        self.name, self.layout, self.specs, self.readings = name, layout, specs, n
        self.kinds = {s.split(":")[0] for s in specs}
        self.dir, self.json = root / "plan", root / "plan.json"
        args = ["plan", layout]
        for s in specs:
            args += ["--instrument", s]
        self.option = REQUEST.get(name)
        if self.option:
            args += ["--parameters", self.option]
        with plan_designs.designed_once():   # kept for test_output_folder_with_files_needs_force
            self.proc = run(*args, "--readings", n, "--out", self.dir, "--json", self.json,
                            "--seed", 1)
        assert self.proc.returncode == 0, self.proc.stderr[-3000:]
        self.doc = json.loads(self.json.read_text())
        self.machine = S.Machine(layout)
        self.files = [P.read_plan_file(self.dir / e["file"], e["kind"])
                      for e in self.doc["files"]]

    @property
    def requested(self) -> dict:
        """The parameters the plan determines (finite predicted_std)."""
        return {k: v for k, v in self.doc["parameters"].items() if determined(v)}

    @property
    def request(self) -> list:
        """Every parameter of the plan's request: the determined ones and those it leaves
        undetermined (scales without a calibrated bar ...), which calibrate fits too (their
        determined combinations)."""
        return sorted(set(self.doc["parameters"]) | set(self.doc.get("unidentifiable", []))
                      | set(self.doc.get("requested", [])))

    @property
    def planted(self) -> list:
        """What the simulated machine has: the whole request."""
        return [n for n in self.request if P.known_to_machine(self.machine, n)]


class Executed:
    """A plan filled by the simulator and fed to ``volerr calibrate`` with no options."""

    def __init__(self, plan: Plan, root: Path):
        seed = CASES[plan.name][4]
        rng = np.random.default_rng(seed)
        self.truth = {k: P.planted_value(plan.machine, k, rng) for k in plan.planted}
        self.filled = root / "filled"
        self.paths, self.setup = P.execute(plan.machine, plan.files, self.truth, self.filled,
                                           rng, plan.dir)
        self.json = root / "calibrate.json"
        self.proc = run("calibrate", plan.layout, *self.paths, "--json", self.json)
        assert self.proc.returncode == 0, self.proc.stderr[-3000:]
        self.doc = json.loads(self.json.read_text())


class Runs:
    """Plans and executions computed once per case (and per xdist worker)."""

    def __init__(self, factory):
        self.factory, self.plans, self.runs = factory, {}, {}

    def plan(self, name) -> Plan:
        if name not in self.plans:
            self.plans[name] = Plan(name, self.factory.mktemp(name))
        return self.plans[name]

    def executed(self, name) -> Executed:
        if name not in self.runs:
            p = self.plan(name)
            self.runs[name] = Executed(p, p.dir.parent)
        return self.runs[name]


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    return Runs(tmp_path_factory)


# ---- the report ------------------------------------------------------------------------------
@pytest.mark.parametrize("case", ALL)
def test_report_states_the_plan(runs, case):
    p = runs.plan(case)
    doc = p.doc
    assert doc["layout"] == p.layout and doc["readings"] == p.readings, (doc["layout"],
                                                                           doc["readings"])
    assert p.requested, doc["parameters"]
    for name, e in doc["parameters"].items():
        assert e["unit"] in UNITS, (name, e)
        assert set(e["determined_alone_by"]) <= p.kinds, (name, e)
        if len(p.kinds) == 1 and determined(e):
            # one instrument: whatever the plan determines, that instrument determines alone
            assert e["determined_alone_by"] == sorted(p.kinds), (name, e)
    assert {f["kind"] for f in doc["files"]} == p.kinds <= KINDS, doc["files"]
    for e, f in zip(doc["files"], p.files):
        assert e["readings"] == f.n, (e, f.n)
        assert isinstance(e["minutes"], (int, float)) and e["minutes"] > 0, e
        assert (p.dir / e["nc"]).is_file(), e
    assert sum(f.n for f in p.files) == p.readings, [(f.path.name, f.n) for f in p.files]
    for key in ("max", "rms"):
        assert doc["map_u_um"][key] > 0 and doc["baseline"]["map_u_um"][key] > 0, doc
    assert doc["baseline"]["readings"] == doc["readings"], doc["baseline"]
    assert doc["baseline"]["name"] and isinstance(doc["baseline"]["parameters"], dict)
    assert isinstance(doc["unidentifiable"], list)
    for e in doc["files"]:
        assert not Path(e["file"]).is_absolute() and not Path(e["nc"]).is_absolute(), e
    sheet = p.dir / "plan.html"
    assert sheet.is_file(), sorted(q.name for q in p.dir.iterdir())
    text = sheet.read_text()
    assert "<svg" in text or "<img" in text, "the set-up sheet has no figure"
    if p.option:
        # the request is the plan's, written into the files so that calibrate uses it
        assert set(doc["parameters"]) == set(p.option.split(",")), sorted(doc["parameters"])
        for f in p.files:
            assert "parameters" in f.meta, (f.path.name, f.meta)


@pytest.mark.parametrize("case", ALL)
def test_files_are_instrument_files_with_empty_readings(runs, case):
    p = runs.plan(case)
    m = p.machine
    for f in p.files:
        where = f"{case}: {f.path.name}"
        for c in P.READING_COLUMNS[f.kind]:
            assert f.has(c), (where, c, f.columns)
            assert all(v == "" for v in f.text(c)), (where, c, "not empty")
        for a in m.axes:
            assert f.has(a), (where, a, f.columns)
        label = "station" if f.kind == "distances" else "placement"
        assert f.has(label) and all(f.text(label)), (where, label)
        u = f.number("u_um") if (f.has("u_um") or "u_um" in f.meta) else None
        assert u is not None and np.all(u > 0), (where, "u_um not declared", f.meta)
        pos, probe = f.positions(m.axes), f.probe()
        t = m.tool_point(pos, None, probe)
        if f.kind == "ballbar":
            pivot = np.column_stack([f.number(c) for c in ("pivot_x", "pivot_y", "pivot_z")])
            length = f.number("length_mm")
            assert set(np.round(length, 6)) <= {100.0, 150.0, 250.0}, (where, set(length))
            gap = np.abs(np.linalg.norm(t - pivot, axis=1) - length)
            assert gap.max() < 5e-3, (where, "tool ball off the bar length", gap.max())
        if f.kind == "sphere":
            assert f.declared("tool_u_um") == pytest.approx(0.5), (where, f.meta)
            centre = np.column_stack([f.number(c) for c in ("sphere_x", "sphere_y",
                                                            "sphere_z")])
            gap = np.linalg.norm(t - centre, axis=1)
            assert gap.max() < 5e-3, (where, "tool point off the sphere centre", gap.max())


@pytest.mark.parametrize("case", ALL)
def test_every_position_inside_the_travel(runs, case):
    p = runs.plan(case)
    travel = p.machine.travel
    for f, e in zip(p.files, p.doc["files"]):
        for a in p.machine.axes:
            lo, hi = travel[a]
            q = f.number(a)
            assert np.all((q >= lo - 1e-9) & (q <= hi + 1e-9)), (
                case, f.path.name, a, (lo, hi), q.min(), q.max())
        blocks = P.nc_blocks((p.dir / e["nc"]).read_text(), p.machine.axes)
        ends = [b.end for b in blocks if b.end is not None]
        assert ends, (case, e["nc"], "no motion block")
        for end in ends:
            for a, v in end.items():
                lo, hi = travel[a]
                assert lo - 1e-9 <= v <= hi + 1e-9, (case, e["nc"], a, v, (lo, hi))


@pytest.mark.parametrize("case", ALL)
def test_nc_program_moves_through_the_rows_in_order(runs, case):
    p = runs.plan(case)
    for f, e in zip(p.files, p.doc["files"]):
        blocks = P.nc_blocks((p.dir / e["nc"]).read_text(), p.machine.axes)
        bad = [(b.line, b.errors) for b in blocks if b.errors]
        assert not bad, (case, e["nc"], "motion not absolute mm", bad[:3])
        pos = f.positions(p.machine.axes)
        rows = [{a: float(pos[a][i]) for a in p.machine.axes} for i in range(f.n)]
        hits = P.match_rows(blocks, rows)
        missing = [i for i, h in enumerate(hits) if h is None]
        assert not missing, (case, e["nc"], "row not an end point in order", missing[0],
                             rows[missing[0]] if missing[0] < len(rows) else None)
        if f.kind not in P.READS_AT_A_STOP:
            continue
        for i, h in enumerate(hits):
            # the blocks after the reading's move, up to the next move: one is a dwell
            after = []
            for b in blocks[h + 1:]:
                if b.end is not None:
                    break
                after.append(b)
            assert any(b.dwell is not None and b.dwell > 0 for b in after), (
                case, e["nc"], "no G4 dwell after the reading of row", i, blocks[h].line)


# ---- executed: calibrate finds what was planted, with the predicted uncertainty -------------
@pytest.mark.parametrize("case", ALL)
def test_calibrate_recovers_the_planted_parameters(runs, case):
    p, x = runs.plan(case), runs.executed(case)
    got = x.doc["parameters"]
    missing = sorted(set(p.requested) - set(got))
    assert not missing, (case, "requested but not determined", missing,
                         x.doc.get("unidentifiable"))
    bad = []
    k = k_sigma(len(got))
    for name, e in got.items():
        truth = x.truth.get(name, 0.0)
        if name in p.requested:
            assert e["unit"] == p.requested[name]["unit"], (name, e, p.requested[name])
        if not abs(e["value"] - truth) <= k * e["std"]:
            bad.append((name, e["value"], truth, e["std"]))
    assert not bad, (case, f"outside {k:.2f} std of the planted value", bad)


@pytest.mark.parametrize("case", ALL)
def test_calibrate_fits_what_the_plan_requested(runs, case):
    """No option: calibrate determines exactly the parameters the plan predicts for (the
    instruments' defaults, or the plan's --parameters read from the files' header)."""
    p, x = runs.plan(case), runs.executed(case)
    got = set(x.doc["parameters"])
    assert got == set(p.requested), (case, "calibrate only", sorted(got - set(p.requested)),
                                     "plan only", sorted(set(p.requested) - got))


@pytest.mark.parametrize("case", ALL)
def test_realised_uncertainty_as_predicted(runs, case):
    p, x = runs.plan(case), runs.executed(case)
    got = x.doc["parameters"]
    ratios = {n: got[n]["std"] / e["predicted_std"] for n, e in p.requested.items() if n in got}
    assert set(ratios) == set(p.requested), sorted(set(p.requested) - set(ratios))
    bad = {n: round(r, 3) for n, r in ratios.items() if not STD_RATIO[0] <= r <= STD_RATIO[1]}
    assert not bad, (case, "realised std / predicted_std outside 0.7-1.4", bad,
                     x.doc.get("variance_factor"))


# ---- what the design gains over the conventional plan ------------------------------------
@pytest.mark.parametrize("case", [c for c in ALL if CASES[c.values[0]][3] is not None])
def test_map_uncertainty_against_the_baseline(runs, case):
    p = runs.plan(case)
    factor = CASES[case][3]
    mine, base = p.doc["map_u_um"], p.doc["baseline"]["map_u_um"]
    assert p.doc["baseline"]["readings"] == p.doc["readings"] == p.readings
    assert mine["rms"] <= factor * base["rms"] * (1 + 1e-9), (
        case, p.doc["baseline"].get("name"), mine, base, factor)


def _setups(files) -> int:
    """Set-ups of a plan: distinct placements (sphere, ballbar) and stations per file."""
    return sum(len(set(f.text("station" if f.kind == "distances" else "placement")))
               for f in files)


@pytest.mark.parametrize("case", [_case("DMU50-rtest")])
def test_time_budget_is_kept(runs, case, tmp_path):
    """--minutes M just under the unconstrained plan's time, same readings budget N: a plan of
    N readings within M minutes with fewer set-ups (set-up changes cost the most), or -- when
    the unconstrained plan has a single set-up, so that nothing can go -- one error line."""
    p = runs.plan(case)
    full = sum(e["minutes"] for e in p.doc["files"])
    budget = round(full - 0.5, 1)
    js, out = tmp_path / "p.json", tmp_path / "out"
    args = ["plan", p.layout, *sum((["--instrument", s] for s in p.specs), []),
            "--readings", p.readings, "--minutes", budget, "--out", out, "--json", js,
            "--seed", 1]
    r = run(*args)
    if _setups(p.files) == 1:
        _refused(r, "minutes")
        return
    assert r.returncode == 0, r.stderr[-2000:]
    doc = json.loads(js.read_text())
    spent = sum(e["minutes"] for e in doc["files"])
    assert 0 < spent <= budget + 1e-9, (spent, budget, full)
    assert sum(e["readings"] for e in doc["files"]) == p.readings == doc["readings"]
    files = [P.read_plan_file(out / e["file"], e["kind"]) for e in doc["files"]]
    assert _setups(files) < _setups(p.files), (_setups(files), _setups(p.files))


# ---- a mixed campaign: determined by the combination only ----------------------------------
@pytest.mark.parametrize("case", MIXED)
def test_mixed_campaign_determines_what_no_instrument_does_alone(runs, case):
    p, x = runs.plan(case), runs.executed(case)
    joint = sorted(n for n, e in p.requested.items() if e["determined_alone_by"] == [])
    assert joint, (case, "no parameter determined by the combination only",
                   {n: e["determined_alone_by"] for n, e in p.doc["parameters"].items()})
    for n in joint:
        e = x.doc["parameters"].get(n)
        assert e is not None, (n, "not determined by calibrate", x.doc.get("unidentifiable"))
        assert abs(e["value"] - x.truth[n]) <= k_sigma(len(joint)) * e["std"], (n, e, x.truth[n])
    # the claim checked: each kind's files alone, asked for the same parameters (the plan's
    # whole request), leave every "joint" parameter undetermined and determine those the
    # plan says they determine
    request = ",".join(p.request)
    for kind in sorted(p.kinds):
        paths = [path for path, f in zip(x.paths, p.files) if f.kind == kind]
        out = x.json.parent / f"alone_{kind}.json"
        r = run("calibrate", p.layout, *paths, "--parameters", request, "--json", out)
        assert r.returncode == 0, (kind, r.stderr[-2000:])
        alone = json.loads(out.read_text())["parameters"]
        wrong = sorted(set(joint) & set(alone))
        assert not wrong, (kind, "determines alone what the plan says only the combination "
                           "determines", wrong)
        said = sorted(n for n, e in p.requested.items() if kind in e["determined_alone_by"])
        assert set(said) <= set(alone), (kind, sorted(set(said) - set(alone)))


# ---- bad input -------------------------------------------------------------------------------
@pytest.fixture(scope="module")
def plan_exists():
    r = run("plan", "--help")
    assert r.returncode == 0, r.stderr[-2000:]
    return r.stdout


def _refused(r, *keywords):
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert "Traceback" not in r.stderr and len(lines) == 1, r.stderr[-2000:]
    assert any(k.lower() in lines[0].lower() for k in keywords), (keywords, lines[0])


BAD = {
    "unknown kind": (["--instrument", "lasertracer9:u_um=1"], ["lasertracer9"]),
    "malformed spec": (["--instrument", "ballbar:lengths=abc"], ["abc", "lengths"]),
    "no value": (["--instrument", "sphere:tool_u_um="], ["tool_u_um"]),
    "zero readings": (["--instrument", "ballbar:lengths=100", "--readings", "0"], ["readings"]),
}


@pytest.mark.parametrize("what", list(BAD))
def test_bad_input_one_line_nothing_written(plan_exists, tmp_path, what):
    extra, words = BAD[what]
    if "--readings" not in extra:
        extra = extra + ["--readings", "100"]
    out, js, html = tmp_path / "out", tmp_path / "p.json", tmp_path / "p.html"
    r = run("plan", "MB1", *extra, "--out", out, "--json", js, "--html", html)
    _refused(r, *words)
    assert not out.exists() and not js.exists() and not html.exists(), sorted(
        q.name for q in tmp_path.iterdir())


@pytest.mark.xdist_group("plan_MB1-ballbar")
def test_output_folder_with_files_needs_force(plan_exists, tmp_path):
    """A second plan into a folder holding the first one's files: refused without --force
    (one line, nothing changed, no JSON), done with it.  The three runs ask for one design,
    made once (``helpers.plan_designs``): what is checked is the command's output folder.
    The request is the MB1-ballbar case's, in its xdist group: its design, made there."""
    out = tmp_path / "out"
    layout, specs, n, _, _ = CASES["MB1-ballbar"]
    args = ["plan", layout, "--instrument", *specs, "--readings", n, "--seed", 1, "--out", out]
    with plan_designs.designed_once():
        r = run(*args, "--json", tmp_path / "first.json")
    assert r.returncode == 0, r.stderr[-2000:]
    (out / "notes.txt").write_text("mine\n")
    before = {q.name: q.read_bytes() for q in out.rglob("*") if q.is_file()}
    with plan_designs.designed_once():
        r = run(*args, "--json", tmp_path / "second.json")
    _refused(r, "force", "exist")
    after = {q.name: q.read_bytes() for q in out.rglob("*") if q.is_file()}
    assert after == before and not (tmp_path / "second.json").exists()
    with plan_designs.designed_once():
        r = run(*args, "--json", tmp_path / "third.json", "--force")
    assert r.returncode == 0 and (tmp_path / "third.json").is_file(), r.stderr[-2000:]
    assert (out / "notes.txt").read_text() == "mine\n"
