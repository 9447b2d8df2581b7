"""Shared machinery of the instrument acceptance tests (issue 19): running the command line,
building simulated campaigns with the independent simulator (tests/helpers/instrument_sim.py),
and the independent references a result is judged against (true-model floor on the same
split, weighted least squares, rank analysis).  Nothing here calls volerr's computing code;
the layout is only parsed (``read_layout``) by the simulator."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np

from helpers import instrument_sim as S

#: z of a standard normal for "within 3 standard uncertainties"
K_SIGMA = 3.0
#: held-out residual at most this many times the floor of the true model (issue 19)
FLOOR_FACTOR = 1.15


def cli(*args, cwd=None):
    """``python -m volerr ARGS`` (one BLAS thread, as every process the tests start:
    tests/conftest.py)."""
    return subprocess.run([sys.executable, "-m", "volerr", *map(str, args)],
                          capture_output=True, text=True, cwd=cwd)


def in_process(*args):
    """``volerr ARGS`` through ``volerr.cli.main`` in this process, console captured:
    (returncode, stdout, stderr) as :func:`cli` gives them, without starting an interpreter
    (the commands expected to succeed; exit-2 paths use :func:`cli`):
    :func:`helpers.in_process.volerr`."""
    from helpers.in_process import volerr

    return volerr(*args)


def run_json(args, json_path: Path):
    """Run a command that writes --json (in this process: :func:`in_process`); return
    (completed command, parsed JSON or None)."""
    r = in_process(*args, "--json", json_path)
    doc = json.loads(Path(json_path).read_text()) if r.returncode == 0 and Path(
        json_path).is_file() else None
    return r, doc


def measured_range(blocks, axis):
    """The measured range of an axis: min / max of its commanded positions over every reading
    of the campaign (the range of the Legendre series of the contract)."""
    return (min(float(b.pos[axis].min()) for b in blocks),
            max(float(b.pos[axis].max()) for b in blocks))


def series_terms(blocks, comps, degree, with_offset=(), skip=()):
    """Terms of component series: for each component its slope and P2..Pk (its offset only
    when listed in ``with_offset``), over the measured range; ``skip``: term names left out
    (the gauge-fixed ones)."""
    out = []
    for c in comps:
        lo, hi = measured_range(blocks, c[2])
        ks = ([0] if c in with_offset else []) + list(range(1, degree + 1))
        out += [S.series(c, k, lo, hi) for k in ks]
    return [t for t in out if t.param not in skip]


class Campaign:
    """Simulated files of one calibrate / loop run: blocks, planted values and set-ups,
    noise, and the files written."""

    def __init__(self, machine, blocks, terms, values, setup, seed):
        self.machine, self.blocks, self.terms = machine, blocks, terms
        self.values, self.setup = values, setup
        rng = np.random.default_rng(seed)
        self.y, self.noise = [], []
        for b in blocks:
            y, e = S.simulate(machine, b, terms, values, setup, rng)
            self.y.append(y)
            self.noise.append(e)

    def write(self, folder: Path, prefix=""):
        paths = []
        for b, y in zip(self.blocks, self.y):
            p = folder / b.name
            S.write_csv(p, S.columns(self.machine, b, y))
            paths.append(prefix + str(p))
        return paths

    def stacked(self):
        return np.concatenate([np.ravel(y) for y in self.y])


def random_setup(blocks, rng, pivot_um=15.0, length_um=6.0, centre_um=40.0, tool_um=8.0):
    """Planted set-up offsets of every placement (um)."""
    out = {}
    for b in blocks:
        for s in b.setup_names():
            key = s.split(":")[-1]
            size = {"length": length_um, "tool_dz": tool_um}.get(
                key, pivot_um if key.startswith("pivot") else centre_um)
            out[s] = float(rng.normal(0.0, size))
    return out


def true_design(campaign: Campaign, params=None):
    """Design of the true model: the planted (nonzero, or ``params``) terms and all set-ups."""
    params = params or [p for p, v in campaign.values.items() if v]
    return S.design(campaign.machine, campaign.blocks,
                    [t for t in campaign.terms if t.param in params])


def floor_fit(campaign: Campaign, test_rows: dict, params=None, design=None,
              per: str = "point"):
    """Held-out RMS per file (um) of the TRUE model fitted by weighted least squares on the
    training readings of the split ``test_rows`` (file name -> data-row indices): the columns
    are finite differences of the exact simulator w.r.t. the planted parameters (``params``,
    default the nonzero ones) and every set-up unknown.  Rows of 3-D readings (sphere,
    deviations): ``per="point"`` RMS of the length of the residual vector (the loop's RMS,
    INTERFACE.md), ``per="reading"`` RMS per scalar reading (calibrate's, docs/formats.md
    section calibrate-json)."""
    d = design or true_design(campaign, params)
    y = campaign.stacked()
    test = np.zeros(len(y), bool)
    for bi, b in enumerate(campaign.blocks):
        rows = np.asarray(test_rows[b.name], int)
        sel = (d.rows[:, 0] == bi) & np.isin(d.rows[:, 1], rows)
        test |= sel
    _, _, res = S.wls(d, y, ~test)
    out = {}
    for bi, b in enumerate(campaign.blocks):
        m = test & (d.rows[:, 0] == bi)
        r = res[m].reshape(-1, b.rows_per_reading)
        ms = np.mean(np.sum(r ** 2, axis=1))
        out[b.name] = float(np.sqrt(ms if per == "point" else ms / b.rows_per_reading))
    return out


def expected_floor(campaign: Campaign, params=None, n_splits=40, fraction=0.25, seed=7):
    """Median over random splits (``fraction`` of each file held out) of the held-out RMS per
    file of the true model -- the floor when the program does not report its split."""
    rng = np.random.default_rng(seed)
    d = true_design(campaign, params)
    acc = {b.name: [] for b in campaign.blocks}
    for _ in range(n_splits):
        split = {b.name: np.sort(rng.permutation(b.n)[: max(1, round(fraction * b.n))])
                 for b in campaign.blocks}
        for k, v in floor_fit(campaign, split, design=d).items():
            acc[k].append(v)
    return {k: float(np.median(v)) for k, v in acc.items()}


def reference_estimate(campaign: Campaign, terms):
    """Independent WLS estimate and standard uncertainty of ``terms`` (plus set-ups) on all
    readings: (dict name -> value, dict name -> std, Design)."""
    d = S.design(campaign.machine, campaign.blocks, terms)
    theta, cov, _ = S.wls(d, campaign.stacked())
    std = np.sqrt(np.clip(np.diag(cov), 0, None))
    return ({c: float(theta[i]) for i, c in enumerate(d.columns)},
            {c: float(std[i]) for i, c in enumerate(d.columns)}, d)


def check_one_line_error(r, *keywords):
    """Exit 2, exactly one non-empty stderr line, no traceback, the line mentions one of the
    keywords (case-insensitive) when given."""
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert "Traceback" not in r.stderr, r.stderr[-2000:]
    assert len(lines) == 1, r.stderr
    if keywords:
        assert any(k.lower() in lines[0].lower() for k in keywords), (keywords, lines[0])


def setup_key(name: str):
    """Simulator set-up name -> (JSON "setup" key, KEY): ``"f.csv#P1:length"`` ->
    (``"f.csv#P1"``, ``"length"``); ``"f.csv:tool_dz"`` -> (``"f.csv"``, ``"tool_dz"``)."""
    owner, key = name.rsplit(":", 1)
    return owner, key


def check_setups(doc, campaign, design, keys=None):
    """Every set-up unknown whose column the rank analysis finds identifiable (and whose KEY
    is in ``keys``, default all) is reported within 3 standard uncertainties of the planted
    value, in um.  Returns the list of failures (name, value, planted, std)."""
    names = [c for c in design.columns[design.n_params:]
             if keys is None or setup_key(c)[1] in keys]
    ok, _ = S.identifiability(design, names=names)
    bad = []
    for c, ident in ok.items():
        if not ident:
            continue
        owner, key = setup_key(c)
        if owner not in doc["setup"] and "#" in owner:
            # the contract's "<file>#<placement>" or "<file>": a file of one placement may
            # carry its placement's set-up under the file name
            fname = owner.split("#")[0]
            (blk,) = [b for b in campaign.blocks if b.name == fname]
            if len(set(blk.placement.tolist())) == 1:
                owner = fname
        assert owner in doc["setup"], (owner, sorted(doc["setup"]))
        assert key in doc["setup"][owner], (owner, key, sorted(doc["setup"][owner]))
        e = doc["setup"][owner][key]
        assert e["unit"] == "um", (c, e)
        truth = campaign.setup.get(c, 0.0)
        if abs(e["value"] - truth) > K_SIGMA * e["std"]:
            bad.append((c, e["value"], truth, e["std"]))
    return bad


def residual_outside(design, name, others) -> float:
    """Relative norm of the part of column ``name`` outside the span of the columns
    ``others`` and of every set-up column (weighted, columns normalised)."""
    A = design.J * design.weights[:, None]
    A = A / np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    idx = [design.columns.index(o) for o in others] + list(
        range(design.n_params, len(design.columns)))
    a = A[:, design.columns.index(name)]
    if not np.any(a):
        return 0.0
    B = A[:, idx]
    coef, *_ = np.linalg.lstsq(B, a, rcond=None)
    return float(np.linalg.norm(a - B @ coef))
