"""``volerr plan``: the steps from the instruments named to the predicted result.

1. the request: ``--parameters`` or what ``calibrate`` fits by default for these instruments;
2. the candidate set-ups of every instrument (:mod:`volerr.plan._candidates`);
3. their information on the requested parameters (:mod:`volerr.plan._information`);
4. the set-ups and their readings (:mod:`volerr.plan._design`);
5. the files, and the prediction on calibrate's own path (:mod:`volerr.plan._predict`) for
   the plan, for each instrument alone (``determined_alone_by``) and for the instruments'
   conventional plan at the same number of readings (:mod:`volerr.plan._baseline`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..calibrate import estimability, terms
from ..calibrate.defaults import default_parameters
from ..errors import require
from ..machine.model import Model, load
from ..results import ResultMixin
from . import _baseline, _candidates, _design, _files, _information, _spec
from ._predict import predict

#: highest series term planned for a component error requested whole (``EXX``, ``all``):
#: the files declare the terms, so that calibrate fits that degree (not one it would choose
#: by cross-validation on the readings, which no plan can predict)
SERIES_DEGREE = 2


def fixed_degree(model, req) -> str | None:
    """The request ``req`` with every component error requested whole written as its series
    terms up to :data:`SERIES_DEGREE` (``EXX@offset,EXX@slope,EXX@P2``; a rotary axis that
    turns: ``@cos1``, ``@sin1``), as ``--parameters`` text; None when no series is requested
    whole."""
    axis_of = model.parameter_axis
    whole = [p for p in req.parameters if axis_of.get(p) and p not in req.only]
    if not whole:
        return None
    words = []
    for p in req.parameters:
        axis = axis_of.get(p)
        if not axis:
            words.append(p)
            continue
        ks = sorted(req.only[p]) if p in req.only else range(SERIES_DEGREE + 1)
        lo, hi = model.travel[axis]
        turns = axis in model.rotary_axes and hi - lo >= 300.0
        words += [terms.term_name((p, k), turns) for k in ks]
    return ",".join(words + [f"RV_{a}" for a in req.reversals])


def default_request(model, kinds) -> list:
    """The request ``calibrate`` fits by default for instruments of ``kinds``
    (:func:`volerr.calibrate.defaults.default_parameters`)."""
    return default_parameters(model, list(dict.fromkeys(kinds)))


@dataclass(repr=False)
class Plan(ResultMixin):
    """A designed campaign: ``files`` [PlanFile], ``prediction`` and ``baseline`` (with its
    name and files), ``alone`` {kind: Prediction}, ``minutes`` per file, the request."""

    model: Model
    instruments: list
    chosen: list
    files: list
    prediction: object
    baseline: dict
    alone: dict
    minutes: list
    criterion: str
    readings: int
    candidates: int = 0
    candidate_readings: int = 0
    parameters_text: str | None = None
    map_grid: dict = field(default_factory=dict)
    dialect: str = "iso"

    def write_outputs(self, outs, options: dict, ident, inputs=(), title=None, roles=()):
        """``volerr plan``'s outputs inside ``with outs:``: :meth:`write` into ``--out`` (and
        ``--json``, ``--html``; the options' ``dialect``), then the identification
        (:func:`volerr.report.stamp.finish`)."""
        from ..report.stamp import finish

        self.write(outs.path("--out"), outs.path("--json"), outs.path("--html"), inputs,
                   options.get("dialect"))
        finish(outs, self, ident, list(inputs))

    def write(self, folder, json_path=None, html_path=None, inputs=(), dialect=None,
              sheet=None) -> None:
        """The files, NC programs (in ``dialect``, default :attr:`dialect`: one of
        :data:`volerr.plan._dialect.NAMES`), ``plan.html`` (or ``html_path``) and the JSON.
        ``sheet``: the function that writes the page's text from the plan (default the set-up
        sheet, :func:`volerr.plan._sheet.html`; a check plan adds its power table to it)."""
        from ..fileio import json_text, write_text
        from . import _nc, _report, _sheet
        from ._files import csv_text

        self.dialect = dialect or self.dialect
        for pf in self.files:
            header = _report.file_header(self, pf)
            write_text(f"{folder}/{pf.name}", csv_text(pf, header), inputs=list(inputs))
            nc = _report.nc_name(pf, self.dialect)
            write_text(f"{folder}/{nc}", _nc.program(self.model, pf, header, self.dialect,
                                                     _nc.program_name(nc)),
                       inputs=list(inputs))
        write_text(html_path or f"{folder}/plan.html", (sheet or _sheet.html)(self),
                   inputs=list(inputs))
        if json_path:
            write_text(json_path, json_text(_report.data(self)), inputs=list(inputs))

    def write_html(self, path, inputs=()) -> None:
        """The set-up sheet (``plan.html``) alone."""
        from ..fileio import write_text
        from . import _sheet

        write_text(path, _sheet.html(self), inputs=list(inputs))

    def _rows(self) -> list:
        from ..results import Row

        return [Row(n, None, e["predicted_std"], e["unit"], 1.0)
                for n, e in self.data()["parameters"].items()]

    def data(self) -> dict:
        from ._report import data

        return data(self)

    def summary(self) -> str:
        from ._report import summary

        return summary(self)

    @property
    def total_minutes(self) -> float:
        return float(sum(self.minutes))


def plan(layout, specs, readings: int, parameters: str | None = None, minutes=None,
         criterion: str = "I", seed: int = 0) -> Plan:
    """Design a campaign for ``layout`` with the instruments ``specs`` (``--instrument``
    texts) of ``readings`` readings in all (module docstring).  ``seed``: the random starts of
    the exchange (the same seed, the same plan)."""
    model = layout if isinstance(layout, Model) else load(layout)
    insts = [_spec.parse(s) for s in specs]
    require(insts, "give at least one --instrument")
    for inst in insts:
        require(inst.kind != "sphere" or model.rotary_axes,
                f"--instrument {inst.text}: layout {model.name} has no rotary axis; a sphere / "
                f"R-test plan turns the rotary axes (plan a ballbar or distances campaign)")
    require(criterion in ("I", "D"), "--criterion must be I or D")
    union = default_request(model, [i.kind for i in insts])
    req = terms.request(parameters, model, union)
    fixed = fixed_degree(model, req)
    if fixed is not None:                    # whole series: their terms up to SERIES_DEGREE
        parameters, req = fixed, terms.request(fixed, model)
    pool = []
    for i, inst in enumerate(insts):
        found = _candidates.setups(model, inst)
        require(found, f"--instrument {inst.text}: no set-up of it fits inside the travel "
                       f"of {model.name}")
        pool += [(i, s) for s in found]
    need = sum(_floor(inst) * min(s.min_readings for j, s in pool if j == i)
               for i, inst in enumerate(insts))
    require(readings >= need, f"--readings {readings}: these instruments need at least "
                              f"{need} readings (the smallest set-ups)")
    prob = _information.problem(model, insts, pool, req)
    cand = _pool(prob, insts, pool)
    picked, counts = _choose(cand, prob, insts, pool, readings, minutes, criterion, seed)
    budget = f"--readings {readings}" + (f" and --minutes {minutes:g}" if minutes else "")
    require(picked, f"{budget}: no plan of these instruments fits that budget and determines "
                    f"every requested parameter their set-ups can determine (give more "
                    f"readings or minutes, more set-ups with places= / stations=, or a "
                    f"smaller --parameters)")
    files = _files.group(insts, [(pool[c][0], pool[c][1], int(m))
                                 for c, m in zip(picked, counts)])
    out = _finish(model, insts, (parameters, union, req), files, cand, picked, counts,
                  criterion, readings, pool)
    out.parameters_text = parameters
    return out


def _floor(inst) -> int:
    """Fewest set-ups of an instrument: 3 stations for multilateration, else 1."""
    return 3 if inst.kind == "distances" else 1


def _cap(inst) -> int:
    return {"sphere": inst.places, "distances": inst.stations,
            "artifact": inst.places}.get(inst.kind, 50)


def _pool(prob, insts, pool) -> _design.Candidates:
    """Per-reading information of every candidate, columns scaled to unit pool information."""
    info = np.array([_information.setup_information(prob, insts, i, s) / s.template
                     for i, s in pool])
    total = info.sum(axis=0) + _prior(prob)
    d = np.sqrt(np.maximum(np.diag(total), 0.0))
    prob.scale = np.where(d > 0, d, 1.0)
    est, _ = estimability.estimable(total)
    prob.free = est | (np.arange(prob.q) < prob.n_global)
    S = np.outer(1 / prob.scale, 1 / prob.scale)
    info = info * S
    setup_min, read_min = [], []
    for i, s in pool:
        extra = 0.0
        if s.kind == "ballbar":
            extra = 2 * 1.25 * 2 * math.pi * s.geometry["length"] / _spec.BALLBAR_FEED_MM_MIN
        setup_min.append(_spec.SETUP_MIN[s.kind] + extra)
        read_min.append(_spec.READING_S[s.kind] / 60.0)
    f = prob.free
    info = info[:, f][:, :, f]
    return _design.Candidates(info, _design.factors(info), np.array([i for i, _ in pool]),
                              np.array([s.min_readings for _, s in pool]),
                              np.array([s.max_readings for _, s in pool]),
                              np.array([s.template for _, s in pool]), np.array(setup_min),
                              np.array(read_min))


def _prior(prob) -> np.ndarray:
    """(q, q) the priors of the campaign-wide nuisances (1 / u^2, mm^-2)."""
    P = np.zeros((prob.q, prob.q))
    g = prob.n_global
    P[:g, :g] = np.diag(prob.prior)
    return P


#: weight of a requested parameter the map does not see, relative to the mean of the others
UNSEEN_WEIGHT = 1e-2


def _scaled(prob):
    f = prob.free
    W = prob.W / np.outer(prob.scale, prob.scale)
    P0 = _prior(prob) / np.outer(prob.scale, prob.scale)
    W, P0 = W[np.ix_(f, f)], P0[np.ix_(f, f)]
    # a requested parameter the map does not see at the plan's tool offset (an angular error
    # of the axis carrying the tool, read by angular optics) still has to be determined: a
    # small weight so that the greedy and the exchange value it
    d = np.diag(W).copy()
    unseen = d <= 1e-12 * max(float(d.max()), 1e-300)
    unseen[:int(np.sum(f[:prob.n_global]))] = False
    if unseen.any() and d.max() > 0:
        W = W + np.diag(np.where(unseen, UNSEEN_WEIGHT * float(d[~unseen].mean()), 0.0))
    return W, P0


def _choose(cand, prob, insts, pool, readings, minutes, criterion, seed):
    """The set-ups (pool indices) and their readings (module docstring of _design)."""
    W, P0 = _scaled(prob)
    caps = {i: _cap(inst) for i, inst in enumerate(insts)}
    path = _greedy_path(cand, W, P0, criterion, caps, readings)
    best = None
    options = []
    for k in range(1, len(path) + 1):
        sel = path[:k]
        if not _feasible(sel, cand, insts, readings):
            continue
        m = _design.allocate(cand, W, P0, criterion, sel, readings)
        t = _design.minutes(cand, sel, m)
        if (minutes is not None and t > minutes) or not _determined(cand, P0, sel, m, prob):
            continue
        options.append((_design.plan_value(cand, W, P0, criterion, sel, m), k, sel, m))
    if not options:
        return [], []
    top = min(v for v, *_ in options)
    good = [o for o in options if _close(o[0], top)]
    value, _, sel, m = good[0]
    swapped = _design.best_exchange(cand, W, P0, criterion, sel, seed=seed)
    if swapped != sel:
        m2 = _design.allocate(cand, W, P0, criterion, swapped, readings)
        v2 = _design.plan_value(cand, W, P0, criterion, swapped, m2)
        if v2 < value and (minutes is None or _design.minutes(cand, swapped, m2) <= minutes) \
                and _determined(cand, P0, swapped, m2, prob):
            sel, m = swapped, m2
    return sel, m


def _determined(cand, P0, sel, m, prob) -> bool:
    """Every requested column the pool determines is determined by the set-ups ``sel`` with
    readings ``m``: calibrate's rule (:mod:`volerr.calibrate.estimability`, the relative
    distance of each unit-scaled column to the span of the others above ``DISTANCE_TOL``),
    with the campaign-wide nuisances eliminated; ``d_j^2 = 1 / (C^-1)_jj``."""
    M = P0 + np.tensordot(np.asarray(m, float), cand.info[sel], axes=1)
    g = int(np.sum(prob.free[:prob.n_global]))
    A = M[g:, g:]
    if g:
        A = A - M[g:, :g] @ np.linalg.pinv(M[:g, :g], hermitian=True) @ M[:g, g:]
    d = np.sqrt(np.maximum(np.diag(A), 0.0))
    if np.any(d <= 0):
        return False
    w, V = np.linalg.eigh(A / np.outer(d, d))
    if w[0] <= 1e-14 * w[-1]:
        return False
    inv_diag = np.einsum("ij,j,ij->i", V, 1.0 / w, V)
    return bool(np.all(inv_diag < 1.0 / estimability.DISTANCE_TOL ** 2))


def _close(value, top) -> bool:
    if not np.isfinite(value):
        return False
    if top > 0:
        return value <= _design.GOOD_ENOUGH * top
    return value <= top + abs(top) * (_design.GOOD_ENOUGH - 1) + math.log(_design.GOOD_ENOUGH)


def _greedy_path(cand, W, P0, criterion, caps, readings) -> list:
    """The greedy order, each instrument up to its cap, at most as many set-ups as the
    readings allow (each its minimum)."""
    k_max = int(min(len(cand.info), readings // max(int(cand.min_readings.min()), 1), 40))
    return _design.greedy(cand, W, P0, criterion, k_max, caps)


def _feasible(sel, cand, insts, readings) -> bool:
    """Every instrument present with its fewest set-ups and the minimum readings fit."""
    for i, inst in enumerate(insts):
        if sum(1 for s in sel if cand.inst[s] == i) < _floor(inst):
            return False
    return int(cand.min_readings[sel].sum()) <= readings <= int(cand.max_readings[sel].sum())


def _finish(model, insts, request, files, cand, picked, counts, criterion, readings, pool):
    """The prediction of the plan, of each instrument alone (with the plan's whole request)
    and of the baseline."""
    spec, union, req = request
    tool = _information.tool_of(insts)
    parts = [_files.observations(model, f) for f in files]
    pred = predict(model, parts, spec, tool)
    alone = {}
    for kind in sorted({f.kind for f in files}):
        sub = [p for p, f in zip(parts, files) if f.kind == kind]
        alone[kind] = predict(model, sub, spec or ",".join(union), tool)
    mins = [_file_minutes(f, cand, picked, counts, pool) for f in files]
    base = _baseline.baseline(model, insts, spec, files, tool)
    grid = {"linear_points": _information.GRID_LINEAR, "rotary_points": _information.GRID_ROTARY,
            "tool_mm": [float(v) for v in tool],
            "note": "every axis over its travel (rotary axes at most one turn), the tool point "
                    "at the instruments' tool offset; standard uncertainty (k = 1) of each "
                    "component of the volumetric error from the determined parameters"}
    # the request as calibrate will print it (its namer: Fourier terms of a turning axis),
    # without what it holds at zero by convention (the gauge)
    requested = list(pred.parameters) + list(pred.unidentifiable)
    return Plan(model, insts, requested, files, pred, base, alone, mins, criterion,
                readings, len(pool), int(sum(s.template for _, s in pool)), map_grid=grid)


def _file_minutes(f, cand, picked, counts, pool) -> float:
    total = 0.0
    for c, m in zip(picked, counts):
        if any(pool[c][1] is s for s, _ in f.setups):
            total += cand.setup_min[c] + m * cand.read_min[c]
    return round(total, 1)
