"""What each candidate set-up tells about the requested parameters, from the observation model
``calibrate`` solves (:mod:`volerr.estimate.blocks`, the instruments' readers): its weighted
normal equations (weights ``1 / u^2``, mm) with its own set-up unknowns (a pivot and a bar
length, a sphere centre, a station and its dead path) eliminated -- the Schur complement
``I_s = G_pp - G_ps G_ss^+ G_sp`` -- over the columns the plan optimises: the campaign-wide
nuisances first (the tool-length error ``tool_dz`` of each sphere file, known to ``tool_u_um``
when given) and then the requested parameters' columns after calibrate's gauge fixing.

The map weight ``W``: the mean over a grid of the working volume of ``J^T J``, ``J`` (3, p) the
volumetric error's columns at a grid pose (the tool point at the instruments' tool offset), so
that ``trace(W C)`` is the mean squared standard uncertainty of the map over the grid (three
components summed) for a covariance ``C`` of the parameters (I-optimality).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from ..estimate import blocks
from ..estimate.design import gauge_mask, parameter_labels
from ..instruments import Observations
from . import _files

#: points per linear axis and per rotary axis of the map grid
GRID_LINEAR, GRID_ROTARY = 5, 5
#: relative eigenvalue below which a set-up's information is zero (rank of its factor)
RANK_TOL = 1e-10


@dataclass
class Problem:
    """The columns the plan optimises: ``labels`` the kept parameter columns (calibrate's
    design labels), ``n_global`` nuisance columns in front (``globals_of`` instrument index ->
    column), ``prior`` (q,) their prior weights (1 / u^2, mm^-2; 0 unknown), ``W`` (q, q)."""

    model: object
    chosen: list
    degree: int
    ranges: dict
    param_keep: np.ndarray
    labels: list
    globals_of: dict
    prior: np.ndarray
    W: np.ndarray = None

    @property
    def n_global(self) -> int:
        return len(self.globals_of)

    @property
    def q(self) -> int:
        return self.n_global + len(self.labels)


def ranges_of(model, positions: list) -> dict:
    """Axis -> (lo, hi) of all the given position dicts (as ``data_ranges``)."""
    out = {}
    for a in model.axes:
        v = np.concatenate([np.asarray(p[a], float) for p in positions])
        lo, hi = float(v.min()), float(v.max())
        out[a] = (lo - 0.5, hi + 0.5) if hi - lo < 1e-9 else (lo, hi)
    return out


def problem(model, instruments, pool: list, req) -> Problem:
    """The optimisation's columns for the candidate ``pool`` [(instrument index, SetUp)] and
    the request ``req`` (:class:`volerr.calibrate.terms.Request`; its reversals are left to the
    prediction)."""
    degree = max(1, req.max_term())
    builds = [s.build(s.template) for _, s in pool]
    ranges = ranges_of(model, builds)
    i0, s0 = pool[0]
    obs0 = _files.observations(model, _files.PlanFile("x.csv", s0.kind, i0, [(s0, s0.template)],
                                                      _files.columns_of(instruments[i0],
                                                                        [(s0, s0.template)])))
    keep, _ = gauge_mask(model, obs0, degree, ranges, req.parameters, constants=False)
    param_keep = keep[len(obs0.setup_labels):]
    param_keep &= np.array([req.fits(lab) for lab in parameter_labels(model, degree)])
    labels = [lab for lab, k in zip(parameter_labels(model, degree), param_keep) if k]
    chosen = req.parameters
    globals_of, prior = {}, []
    for i, inst in enumerate(instruments):
        if inst.kind == "sphere":
            globals_of[i] = len(globals_of)
            prior.append(0.0 if inst.tool_u_um is None else (1e3 / inst.tool_u_um) ** 2)
    prob = Problem(model, chosen, degree, ranges, param_keep, labels, globals_of,
                   np.array(prior, float))
    prob.W = map_weight(prob, instruments)
    return prob


def setup_information(prob: Problem, instruments, i: int, s, m: int | None = None
                      ) -> np.ndarray:
    """(q, q) information of set-up ``s`` of instrument ``i`` with ``m`` readings (default
    its template), its own set-up unknowns eliminated."""
    m = s.template if m is None else m
    inst = instruments[i]
    pf = _files.PlanFile("x.csv", s.kind, i, [(s, m)],
                         _files.columns_of(inst, [(s, m)]))
    obs = _files.observations(prob.model, pf)
    return information(prob, obs, i)


def information(prob: Problem, obs: Observations, i: int) -> np.ndarray:
    """(q, q) Schur information of the readings ``obs`` (one instrument ``i``'s), every set-up
    unknown of ``obs`` eliminated except the campaign-wide tool length (a global column)."""
    n_setup = len(obs.setup_labels)
    keep = np.concatenate([np.ones(n_setup, bool), prob.param_keep])
    design = blocks.Design(prob.model, obs, prob.degree, prob.ranges, keep)
    G = np.zeros((design.p, design.p))
    sw = 1.0 / obs._sigmas()
    for _, idx in blocks.blocks(np.arange(obs.n)):
        At = design.block(idx) * blocks.wrows(sw[idx])
        G += At @ At.T
    own = [j for j, lab in enumerate(obs.setup_labels) if "#" in lab or not lab.endswith("tool_dz")]
    tool = [j for j, lab in enumerate(obs.setup_labels) if j not in own]
    for j, u in enumerate(obs.setup_priors):
        if u and j in own and G[j, j] > 0:
            G[j, j] += 1.0 / u ** 2
    rest = tool + list(range(n_setup, design.p))
    S = G[np.ix_(own, own)]
    B = G[np.ix_(own, rest)]
    schur = G[np.ix_(rest, rest)] - B.T @ np.linalg.pinv(S, rcond=1e-12, hermitian=True) @ B
    out = np.zeros((prob.q, prob.q))
    cols = ([prob.globals_of[i]] if tool else []) + list(prob.n_global +
                                                         np.arange(len(prob.labels)))
    out[np.ix_(cols, cols)] = 0.5 * (schur + schur.T)
    return out


def grid(model, tool) -> tuple[dict, np.ndarray]:
    """Poses of the map grid: every linear axis in ``GRID_LINEAR`` steps over its travel, every
    rotary axis in ``GRID_ROTARY`` steps over its travel (at most one turn); the tool offset."""
    ticks = []
    for a in model.axes:
        lo, hi = model.travel[a]
        if a in model.rotary_axes:
            hi = min(hi, lo + 360.0)
            k = GRID_ROTARY
            ticks.append(lo + (hi - lo) * np.arange(k) / (k if hi - lo >= 360.0 else k - 1))
        else:
            ticks.append(np.linspace(lo, hi, GRID_LINEAR))
    pts = np.array(list(itertools.product(*ticks)))
    pos = {a: pts[:, k] for k, a in enumerate(model.axes)}
    return pos, np.tile(np.asarray(tool, float), (len(pts), 1))


def map_rows(model, labels: list, param_keep, degree, ranges, tool) -> np.ndarray:
    """(k, 3, n) the parameter columns ``labels`` of a 3-D reading of the tool point over the
    map grid (:func:`grid`), mm/mm, mm/rad."""
    pos, probe = grid(model, tool)
    n = len(probe)
    covs = {c: np.zeros(n) for c in model.covariates}
    obs = Observations(pos, probe, np.zeros((n, 3)), covs)
    keep = np.concatenate([np.zeros(len(obs.setup_labels), bool), param_keep])
    design = blocks.Design(model, obs, degree, ranges, keep)
    assert design.labels == list(labels)
    return design.block(np.arange(n)).reshape(len(labels), 3, n)


def tool_of(instruments) -> tuple:
    """The tool offset of the map: the first instrument's with a non-zero one, else 0."""
    for inst in instruments:
        if any(inst.tool):
            return tuple(inst.tool)
    return (0.0, 0.0, 0.0)


def map_weight(prob: Problem, instruments) -> np.ndarray:
    J = map_rows(prob.model, prob.labels, prob.param_keep, prob.degree, prob.ranges,
                 tool_of(instruments))
    n = J.shape[2]
    W = np.zeros((prob.q, prob.q))
    g = prob.n_global
    W[g:, g:] = np.einsum("ain,bin->ab", J, J) / n
    return W
