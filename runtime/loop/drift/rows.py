"""Directed drift channels as rows of the layout's model, fitted jointly.

A channel with a direction reads, to first order, ``d = DIR . (t + r x (0, 0, z)) + zero``
(:mod:`volerr.instruments.drift`): ``t`` the tool point's offset (tool side relative to the
workpiece side at the test position, um) and ``r`` the rotation of the tool side relative to
the workpiece side (urad, right hand), ``z`` the sensor's height on the mandrel (mm, the tool
frame's ``Zp``; the tool point is ``z = 0``, a channel without a height stands there).  The
quantities that act at the test position, per machine axis ``A`` of the directed channels:

* ``EA_tool`` (``EX_tool``, ``EY_tool``, ``EZ_tool``): the tool point's offset along ``A``,
  um;
* for ``A`` = X or Y with channels at two or more distinct heights, the tilt about the
  perpendicular axis: ``EB_tool`` about +Y from the X channels (an X channel at ``z`` reads
  ``+EB_tool z``), ``EA_tool`` about +X from the Y channels (a Y channel reads
  ``-EA_tool z``), urad (um / mm = 1000 urad; ``1e-3 z`` um per urad): the tilts of
  ``volerr iso230-3``.  Z channels read no tilt (a rotation about a radial axis does not
  move a point on the spindle axis along it): the offset alone.

A channel's row: ``sign (offset + c z 1e-3 tilt)`` (``sign`` -1 for a ``-A`` channel, ``c``
+1 for X, -1 for Y).  The quantities of one axis are the least-squares solution of its
channels' rows reading by reading (two channels at two heights, or one channel: exact; more:
least squares, the residual reported per channel as ``row_residual_rms_um``: readings the
rows cannot explain -- a sensor that disagrees, a height given wrong).  ``?`` channels are no
row: modelled on their own, unchanged.

The loop (:func:`volerr.loop.drift.run_drift`) models every quantity as it models a channel
(its own zero per run); every directed channel's prediction is its row of the quantities'
predictions, plus the run constant of its least-squares residual (zero when exact).

The layout's own names of a quantity (``layout_parameters``): the layout's parameters whose
first-order effect at the test position is that quantity alone, with the factor (um per um,
urad per urad; e.g. on the DMU50 ``EXX EXY EXZ EX0C ...`` 1 and ``EB0Z`` Z mm for
``EX_tool``, ``EBZ`` alone for the tilt about +Y).  The quantity's symbol is the layout's
name of the same error of the last axis of the tool chain (the axis that carries the spindle
or the turret: ``EXZ EYZ EZZ`` offsets and ``EAZ EBZ`` tilts on the DMU50, ``EXX`` ``EBX``
on the turning centre TC_XZ) where that parameter is the quantity with factor 1, else the
neutral ``EX_tool`` ... ``EB_tool``: a drift at one position is that axis' component error
at that position changing with heat, all the data can say.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...units import SENSOR_TILT as TILT
from . import basis

ROTATION = {"X": "A", "Y": "B"}   # ISO 230-1 letters of the rotations about X, Y
UM_PER_URAD_MM = 1e-3          # a tilt of 1 urad moves a point 1 mm up the mandrel by 1e-3 um
LEVER_MM = 100.0               # the height at which the layout's sensitivity is read for tilts
PURE_TOL = 1e-9                # relative size below which a sensitivity is zero


@dataclass
class Quantity:
    """A quantity of the chain acting at the test position: ``symbol``, ``kind`` (offset |
    tilt), ``axis`` (the channels' axis), ``about`` (a tilt's axis), ``unit``, ``channels``."""

    symbol: str
    kind: str
    axis: str
    about: str | None
    unit: str
    channels: list
    layout_parameters: dict = field(default_factory=dict)

    def describe(self) -> str:
        if self.kind == "offset":
            return f"tool point offset along {self.axis}"
        return f"tilt of the tool side about +{self.about} (right hand)"


@dataclass
class Rows:
    """The quantities and the rows: ``A`` (n_channels, n_quantities), um per unit of the
    quantity; ``channels`` the directed channels in the order of ``A``."""

    quantities: list
    channels: list
    A: np.ndarray

    def row(self, label) -> dict:
        i = self.channels.index(label)
        return {q.symbol: float(self.A[i, j]) for j, q in enumerate(self.quantities)
                if self.A[i, j] != 0}

    def solve(self, Y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Channels ``Y`` (N, n_channels) -> (quantities (N, n_q), residual (N, n_channels))."""
        Q = np.linalg.lstsq(self.A, Y.T, rcond=None)[0].T
        return Q, Y - Q @ self.A.T


def rows_of(directions: dict, heights: dict) -> Rows | None:
    """The quantities and rows of the directed channels (module docstring); None without a
    directed channel."""
    directed = [k for k, d in directions.items() if d != "?"]
    if not directed:
        return None
    quantities, coef = [], []           # coef: per quantity, label -> um per unit
    for axis in "XYZ":
        chans = [k for k in directed if directions[k].lstrip("-") == axis]
        if not chans:
            continue
        sign = {k: -1.0 if directions[k].startswith("-") else 1.0 for k in chans}
        z = {k: float(heights.get(k) or 0.0) for k in chans}
        quantities.append(Quantity(f"E{axis}_tool", "offset", axis, None, "um", chans))
        coef.append(dict(sign))
        if axis in TILT and len(set(z.values())) >= 2:
            about, c = TILT[axis]
            quantities.append(Quantity(f"E{ROTATION[about]}_tool",
                                       "tilt", axis, about, "urad", chans))
            coef.append({k: sign[k] * c * z[k] * UM_PER_URAD_MM for k in chans})
    A = np.array([[cf.get(k, 0.0) for cf in coef] for k in directed])
    return Rows(quantities, directed, A)


def name_in_layout(rows: Rows, model, position: dict, taken=()) -> None:
    """Fill every quantity's ``layout_parameters`` from the layout's sensitivity at the test
    ``position``, and name it by the layout where it can (module docstring; ``taken``: names
    already used, the ``?`` channels')."""
    S0 = model.sensitivity(position, probe=(0.0, 0.0, 0.0))[0]          # (3, n_par)
    S1 = model.sensitivity(position, probe=(0.0, 0.0, LEVER_MM))[0]
    scale = max(float(np.abs(S0).max()), float(np.abs(S1).max()) / LEVER_MM, 1.0)
    tol = PURE_TOL * scale
    ix = {"X": 0, "Y": 1, "Z": 2}
    for q in rows.quantities:
        k = ix[q.axis]
        other = [i for i in range(3) if i != k]
        for j, name in enumerate(model.parameters):
            e0, e1 = S0[:, j], S1[:, j]
            if np.any(np.abs(e0[other]) > tol) or np.any(np.abs(e1[other]) > tol):
                continue
            if q.kind == "offset" and abs(e0[k]) > tol and abs(e1[k] - e0[k]) <= tol:
                q.layout_parameters[name] = round(float(e0[k]), 9)
            elif q.kind == "tilt" and abs(e0[k]) <= tol and abs(e1[k]) > tol:
                c = TILT[q.axis][1]
                q.layout_parameters[name] = round(float(e1[k] / LEVER_MM * c), 9)
    carrier = [a for a in model.layout.tool_chain if a in model.axes]
    taken = set(taken)
    for q in rows.quantities:
        letter = q.axis if q.kind == "offset" else ROTATION[q.about]
        own = f"E{letter}{carrier[-1]}" if carrier else None
        if own and q.layout_parameters.get(own) == 1.0 and own not in taken:
            q.symbol = own
            taken.add(own)


def modelled_series(s: basis.DriftSeries, rows: Rows) -> tuple[basis.DriftSeries, dict]:
    """The series the loop models: the quantities (their symbols) and the ``?`` channels
    unchanged; and every directed channel's least-squares residual (N,) um."""
    Y = np.column_stack([s.channels[k] for k in rows.channels])
    Q, E = rows.solve(Y)
    chans = {q.symbol: Q[:, j] for j, q in enumerate(rows.quantities)}
    chans.update({k: v for k, v in s.channels.items() if k not in rows.channels})
    keep = [k for k in s.channels if k not in rows.channels]
    out = basis.DriftSeries(s.t_s, s.run, s.runs, s.inputs, chans,
                            {k: s.directions.get(k, "?") for k in keep},
                            {k: s.heights.get(k) for k in keep}, s.test, s.environments)
    return out, {k: E[:, i] for i, k in enumerate(rows.channels)}


def run_constant(s: basis.DriftSeries, e: np.ndarray) -> np.ndarray:
    """The residual's constant per run, at every reading (N,): its mean over the run's
    training readings; a run without training readings, its zero (as a held-out run's zero
    is, :meth:`~volerr.loop.drift.series.DriftSeries.zero`)."""
    out = np.empty(len(e))
    zero = s.run_zeros(e)
    for r in range(len(s.runs)):
        m = s.run == r
        tr = m & s.train
        out[m] = e[tr].mean() if tr.any() else zero[r]
    return out


#: the model families, simplest first (a channel of rows: the most complex of its quantities')
FAMILY_ORDER = ("constant", "static", "regularised", "lag")


def map_back(s: basis.DriftSeries, rows: Rows, qpred: dict, resid: dict) -> dict:
    """Every directed channel's predictions from the quantities' (``qpred`` symbol ->
    {"after", "static", "terms"}): its row of them plus its residual's run constant; the
    "before" is the channel's own zero (its first reading per run)."""
    out = {}
    for i, k in enumerate(rows.channels):
        c = run_constant(s, resid[k])
        y = s.channels[k]
        p = {"before": s.zero(y), "terms": [], "quantities": []}
        on = [(j, q) for j, q in enumerate(rows.quantities) if rows.A[i, j] != 0]
        for name in ("after", "static", "constant", "regularised", "lag"):
            p[name] = c + sum(rows.A[i, j] * qpred[q.symbol][name] for j, q in on)
        # the channel's CV residual: its row of the quantities' plus its own row residual
        p["cv_resid"] = resid[k] - c + sum(rows.A[i, j] * qpred[q.symbol]["cv_resid"]
                                           for j, q in on)
        # the interval's scale: the largest leverage of its quantities' (interval.py)
        p["leverage"] = np.max([qpred[q.symbol]["leverage"] for _, q in on], axis=0) \
            if on else None
        alts = [qpred[q.symbol].get("alternative") for _, q in on]
        if any(a is not None for a in alts):    # the room's other reading (fit._Alternative)
            p["alternative"] = c + sum(rows.A[i, j] * (qpred[q.symbol]["after"] if a is None
                                                       else a) for (j, q), a in zip(on, alts))
        fams = [qpred[q.symbol]["family"] for _, q in on]
        p["family"] = max(fams, key=FAMILY_ORDER.index) if fams else "constant"
        for j, q in on:
            p["terms"] += qpred[q.symbol]["terms"]
            p["quantities"].append(q.symbol)
        out[k] = p
    return out


def residual_rms(s: basis.DriftSeries, e: np.ndarray) -> float:
    """RMS over the training readings of the residual less its run constant, um."""
    d = (e - run_constant(s, e))[s.train]
    return float(np.sqrt(np.mean(d ** 2))) if len(d) else 0.0
