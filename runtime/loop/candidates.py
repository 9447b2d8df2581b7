"""Candidate effects of the closing loop: which extensions of the chain the data could need.

Each candidate is a list of effect terms (``parameter * basis`` added to a target, as in
``[effects.NAME]`` of a layout file, :mod:`volerr.machine.layout`), built from the layout and the
columns the data provide.  Families (``kind``):

* ``thermal``: a temperature column (``T_C``, ``T_<axis>``, ``temp``...): the scale of each
  linear axis grows with T - 20 degC about a fixed point A0 of the scale, which need not be
  the axis origin: ``E<d><A> += KT_A * A * (T - 20) + KT0_A * (T - 20)`` (KT in 1/K, KT0 in
  mm/K, A0 = -KT0/KT).  Measured against an artefact at the same temperature, KT is the
  *differential* expansion (scale minus artefact); its mean over the campaign also sits in
  the fitted scale error.
* ``drift``: a time column (``t_s``, ``t_min``, ``t_h``, ``time``): the instrument drifts
  linearly along x, y or z (``work.d<k> += DR_<k> * t``, DR in mm/h).
* ``reversal``: ``dir_<A>`` (+1 / -1): positioning of A differs by RV_A between approach
  directions (``E<d><A> += RV_A * dir_A / 2``; two levels coded otherwise, e.g. 0 / 1, are
  mapped to -1/2, +1/2, so RV_A is always the high-level minus the low-level position).
* ``coupling``: a component error of axis A depends on the position of another axis B:
  Legendre cross terms P1(a)P1(b), P2(a)P1(b), P1(a)P2(b), which no sum of one-dimensional
  functions can represent.
* ``periodic``: a cyclic translational error along an axis, ``a sin(2 pi q/P) + b cos(..)``,
  period P searched (periodogram of the residual, then refined).
* ``higher_order``: Legendre terms of a component beyond the fitted degree.
* ``probe_direction``: ``nx, ny, nz`` columns (or ``ni, nj, nk``, ``n_x ...``, ``i, j, k``:
  unit probing direction in the probe frame,
  which is the workpiece frame's orientation on a CMM): an error along the probing direction
  (effective probe radius), ``tool.d<k> += PR_R * n_k``.
* ``setup``: a grouping column (``setup``, ``round``, ``mount``, ``group``, ``placement``,
  ``run``, ``session``, ``batch``) with 2-50 levels:
  the instrument was re-placed, six rigid-placement coordinates per later group.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from volerr.loop.fit import Data

FAMILIES = ("thermal", "drift", "reversal", "coupling", "periodic", "higher_order",
            "probe_direction", "setup")
_TEMP = re.compile(r"^(T(_\w+)?|[Tt]emp\w*)$")   # T, T_C, T_X, temp_C (not t_s: time)
_TIME = {"t_s": "/3600", "time_s": "/3600", "t_min": "/60", "time_min": "/60", "t_h": "",
         "time_h": "", "time": ""}
_GROUP = ("setup", "round", "mount", "group", "placement", "run", "session", "batch")
#: column triples accepted as the probing direction (unit vector in the probe frame)
_PROBE_DIRS = (("nx", "ny", "nz"), ("ni", "nj", "nk"), ("n_x", "n_y", "n_z"), ("i", "j", "k"))


@dataclass
class Candidate:
    """A candidate effect: its terms and descriptive info (axis, component, period ...)."""

    kind: str
    name: str
    terms: list                       # [(parameter, target, basis)]
    info: dict = field(default_factory=dict)
    period_search: tuple | None = None  # (component, axis, periods) for periodic

    @property
    def parameters(self) -> list:
        return list(dict.fromkeys(t[0] for t in self.terms))


def _f(x: float) -> str:
    """A number for a basis expression, short and exact enough."""
    return repr(round(float(x), 9))


def _u(axis: str, lo: float, hi: float, rotary: bool = False) -> str:
    """Basis text of the position normalised to [-1, 1]: ((A - mid)/half); rotary axes are
    in rad inside bases, their range in deg."""
    if rotary:
        lo, hi = np.deg2rad(lo), np.deg2rad(hi)
    return f"(({axis} - {_f((lo + hi) / 2)})/{_f((hi - lo) / 2)})"


def along_component(layout, axis: str) -> str:
    """The component error along/about an axis' own direction (EXX, EYY, ECC ...)."""
    ax = layout.axes[axis]
    i = int(np.argmax(np.abs(ax.direction)))
    return "E" + ("XYZ" if ax.kind == "linear" else "ABC")[i] + axis


def temperature_columns(covariates) -> list:
    return [c for c in covariates if _TEMP.match(c) and c not in _TIME]


def build(model, data: Data, ranges: dict, degree: int) -> list:
    """All candidates for this layout and these data columns."""
    lay = model.layout
    cov = data.covariates
    linear = [a for a in model.axes if a not in model.rotary_axes]
    out: list[Candidate] = []
    for tcol in temperature_columns(cov):
        if np.ptp(cov[tcol]) < 0.05:
            continue
        sfx = "" if tcol == "T_C" else f"_{tcol}"
        for a in linear:
            comp = along_component(lay, a)
            out.append(Candidate("thermal", f"thermal_{a}{sfx}",
                                 [(f"KT_{a}{sfx}", comp, f"{a}*({tcol} - 20)"),
                                  (f"KT0_{a}{sfx}", comp, f"({tcol} - 20)")],
                                 {"axis": a, "component": comp, "covariate": tcol,
                                  "reference_C": 20.0}))
    for tcol, div in _TIME.items():
        if tcol in cov and np.ptp(cov[tcol]) > 0:
            for k in "xyz":
                out.append(Candidate("drift", f"drift_{k}",
                                     [(f"DR_{k.upper()}", f"work.d{k}", f"{tcol}{div}")],
                                     {"direction": k, "covariate": tcol}))
            break
    for a in model.axes:
        col = f"dir_{a}"
        if col in cov and len(np.unique(cov[col])) > 1:
            comp = along_component(lay, a)
            levels = np.unique(cov[col])
            basis = f"{col}/2"
            if len(levels) == 2 and not np.array_equal(levels, [-1.0, 1.0]):
                # two levels coded otherwise (0/1 ...): +-1/2 all the same, RV = high - low
                lo, hi = float(levels[0]), float(levels[1])
                basis = f"({col} - {_f((lo + hi) / 2)})/{_f(hi - lo)}"
            out.append(Candidate("reversal", f"reversal_{a}",
                                 [(f"RV_{a}", comp, basis)],
                                 {"axis": a, "component": comp, "covariate": col}))
    comps = [p for p in model.parameters if model.parameter_axis.get(p)]
    for p in comps:
        a = model.parameter_axis[p]
        for b in model.axes:
            if b == a:
                continue
            ua = _u(a, *ranges[a], a in model.rotary_axes)
            ub = _u(b, *ranges[b], b in model.rotary_axes)
            terms = [(f"CP_{p}_{b}_11", p, f"{ua}*{ub}"),
                     (f"CP_{p}_{b}_21", p, f"legendre(2, {ua})*{ub}"),
                     (f"CP_{p}_{b}_12", p, f"{ua}*legendre(2, {ub})")]
            out.append(Candidate("coupling", f"coupling_{p}_{b}", terms,
                                 {"component": p, "axis": a, "depends_on": b}))
    for p in comps:
        a = model.parameter_axis[p]
        if p[1] not in "XYZ" or a in model.rotary_axes:
            continue
        lo, hi = ranges[a]
        span = hi - lo
        uniq = np.unique(np.round(data.positions[a], 6))
        step = float(np.median(np.diff(uniq))) if len(uniq) > 2 else span
        pmin = max(2.2 * step, span / 60.0)
        pmax = span / 2.5
        if pmin >= pmax:
            continue
        freqs = np.arange(1.0 / pmax, 1.0 / pmin, 1.0 / (4.0 * span))
        out.append(Candidate("periodic", f"periodic_{p}", [], {"component": p, "axis": a},
                             period_search=(p, a, 1.0 / freqs)))
    for p in comps:
        a = model.parameter_axis[p]
        n_unique = len(np.unique(np.round(data.positions[a], 6)))
        top = min(degree + 6, 14, n_unique - 1)
        if top <= degree:
            continue
        ua = _u(a, *ranges[a], a in model.rotary_axes)
        terms = [(f"HO_{p}_{k}", p, f"legendre({k}, {ua})") for k in range(degree + 1, top + 1)]
        out.append(Candidate("higher_order", f"higher_order_{p}", terms,
                             {"component": p, "axis": a, "degrees": [degree + 1, top]}))
    for names in _PROBE_DIRS:
        if all(c in cov for c in names):
            out.append(Candidate("probe_direction", "probe_direction",
                                 [("PR_R", f"tool.d{k}", c) for k, c in zip("xyz", names)],
                                 {"covariates": list(names)}))
            break
    for g in _GROUP:
        if g not in cov:
            continue
        levels = np.unique(cov[g])
        if not 2 <= len(levels) <= 50:
            continue
        terms = []
        for lv in levels[1:]:
            tag = _f(lv).replace(".0", "").replace("-", "m").replace(".", "p")
            for k in ("dx", "dy", "dz", "ex", "ey", "ez"):
                terms.append((f"SU{tag}_{g}_{k.upper()}", f"work.{k}", f"ind({g}, {_f(lv)})"))
        out.append(Candidate("setup", f"setup_{g}", terms,
                             {"covariate": g, "levels": [float(v) for v in levels]}))
    return out


def periodic_terms(component: str, axis: str, period: float) -> list:
    """Terms of a periodic candidate with a fixed period (axis units)."""
    arg = f"2*pi*{axis}/{_f(period)}"
    return [(f"PS_{component}", component, f"sin({arg})"),
            (f"PC_{component}", component, f"cos({arg})")]
