"""Candidate effects of the closing loop, generated from the chain: "parameter P varies with C".

A candidate is one declared parameter ``P`` of the layout modulated by one covariate ``C``
through a basis; its columns are the generated sensitivity of ``P`` times the basis, so it
propagates through the chain exactly like ``P`` (Abbe arms included).  Written as
``[effects.NAME]`` terms (``parameter * basis`` added to a target,
:mod:`volerr.machine.layout`), which ``derive`` turns into new parameters.

Parameters ``P`` (:func:`targets`): every component error of every axis (modulated as offset +
slope along its own axis), every squareness and rotary location error, the instrument set-up
(``work.dx ... work.ez``: the rigid placement of the measuring instrument, workpiece end) and the
probe / tool offset (``tool.dx tool.dy tool.dz``, tool end), the probe radius along the
probing direction, and the nominal symbols of the chain (:mod:`volerr.loop.symbols`: the probe
/ tool offset growing along itself, ``param.d``, ``frame.F.x``, the scale of a rotary axis;
linear or *proportional* to the symbol's own value).

Covariates ``C`` (:func:`covariates`): every numeric data column that is not an axis, probe
offset or deviation: temperatures (``T``, ``T_C``, ``T_top``, ``temp_X`` ...: basis ``T - 20``)
and the differences of every pair of temperature channels (gradients), time (``t_s``, ``t_min``,
``t_h``, ``time``: linear in hours and a saturating warm-up ``1 - exp(-t / tau)``, tau
searched), approach directions ``dir_<axis>``, set-up / run ids (``setup``, ``round``, ``run``
...: one indicator per later level), the probing direction (``nx ny nz``), any other numeric
column (linear about its mean), and the positions of the axes: another axis (coupling:
Legendre cross terms), the parameter's own axis (Legendre terms beyond the fitted degree, a
step at a searched location, a periodic term with a searched period).

``kind`` names the familiar special cases of this one mechanism: ``thermal`` (any P x a
temperature or gradient), ``drift`` (any P x time, linear or saturating), ``reversal`` (x an
approach direction), ``setup`` (the set-up x a run id), ``group`` (another P x a run id),
``coupling`` (x another axis), ``higher_order``, ``step``, ``periodic`` (x its own axis),
``probe_direction`` (probe radius x probing direction) and ``covariate`` (x another column).

Units inside: mm, rad, K, h.  Each candidate carries, per parameter, the factor and unit in
which the report shows it.
"""

from __future__ import annotations

import itertools
import re
from dataclasses import dataclass, field

import numpy as np

from . import symbols as syms
from ..estimate.design import Data
from ..machine.iso_names import along_component  # noqa: F401  (also the loop's public name)

FAMILIES = ("thermal", "drift", "reversal", "coupling", "periodic", "higher_order",
            "probe_direction", "setup", "group", "step", "covariate")
_TEMP = re.compile(r"^(T(_\w+)?|[Tt]emp\w*)$")   # T, T_C, T_X, temp_C (not t_s: time)
#: time columns -> divisor to hours
_TIME = {"t_s": 3600.0, "time_s": 3600.0, "t_min": 60.0, "time_min": 60.0, "t_h": 1.0,
         "time_h": 1.0, "time": 1.0}
_GROUP = ("setup", "round", "mount", "group", "placement", "run", "session", "batch")
#: column triples accepted as the probing direction (unit vector in the probe frame)
_PROBE_DIRS = (("nx", "ny", "nz"), ("ni", "nj", "nk"), ("n_x", "n_y", "n_z"), ("i", "j", "k"))
SETUP_KEYS = ("dx", "dy", "dz", "ex", "ey", "ez")
#: warm-up time constants searched (h) and step locations (fractions of the range)
TAU_GRID_H = (0.15, 0.25, 0.4, 0.6, 0.9, 1.3, 1.8, 2.5, 3.5, 5.0)
STEP_GRID = tuple(np.linspace(0.06, 0.94, 45))


@dataclass(frozen=True)
class Covariate:
    """A covariate C: ``name`` (as reported), ``kind`` (temperature, difference, time,
    direction, group, probing_direction, numeric), ``expr`` (basis text of the centred
    variable), ``unit`` (for the report), ``columns`` (data columns used)."""

    name: str
    kind: str
    expr: str
    unit: str
    columns: tuple
    levels: tuple = ()


@dataclass(frozen=True)
class Target:
    """A declared parameter P: ``name`` (reported), ``kind`` (component, constant, setup,
    tool), ``chain`` (target text of effect terms), ``axis`` (own axis of a component)."""

    name: str
    kind: str
    chain: str
    axis: str | None = None

    @property
    def angular(self) -> bool:
        if self.kind in ("setup", "tool"):
            return self.chain.split(".")[1][0] == "e"
        return self.name[1] in "ABC"


@dataclass
class Search:
    """A nonlinear basis parameter searched on a grid (warm-up tau, step location, period):
    ``make(value) -> terms``."""

    what: str
    grid: tuple
    make: object


@dataclass
class Candidate:
    """A candidate effect: its terms [(parameter, target, basis)] and what it means."""

    kind: str
    name: str
    terms: list
    info: dict = field(default_factory=dict)
    search: Search | None = None
    units: dict = field(default_factory=dict)      # parameter -> (factor, unit)

    @property
    def parameters(self) -> list:
        return list(dict.fromkeys(t[0] for t in self.terms))

    @property
    def period_search(self):        # former name: candidates with a searched basis parameter
        return self.search

    def fixed(self, value: float) -> "Candidate":
        """This candidate with its searched parameter fixed at ``value``."""
        terms, extra = self.search.make(value)
        return Candidate(self.kind, self.name, terms, {**self.info, **extra}, self.search,
                         self.units)


def extra_parameters(cand) -> int:
    """Parameters a candidate costs in the BIC beyond its columns: a searched basis parameter
    (a time constant, a period, a step location) and the second sensor of a difference of
    two temperatures (the choice among the pairs): a single sensor is preferred over a
    combination of sensors that explains the data equally well."""
    kind_two = cand.kind == "thermal" and " - " in str(cand.info.get("covariate", ""))
    return (1 if cand.search is not None else 0) + (1 if kind_two else 0)


def _f(x: float) -> str:
    """A number for a basis expression, short and exact enough."""
    return repr(round(float(x), 9))


def _u(axis: str, lo: float, hi: float, rotary: bool = False) -> str:
    """Basis text of the position normalised to [-1, 1]: ((A - mid)/half); rotary axes are
    in rad inside bases, their range in deg."""
    if rotary:
        lo, hi = np.deg2rad(lo), np.deg2rad(hi)
    return f"(({axis} - {_f((lo + hi) / 2)})/{_f((hi - lo) / 2)})"


def _ident(text: str) -> str:
    return re.sub(r"\W+", "_", text).strip("_")


def temperature_columns(covs) -> list:
    return [c for c in covs if _TEMP.match(c) and c not in _TIME]


# ---- P: the parameters of the chain ---------------------------------------------------
def targets(model) -> list:
    """Every declared parameter of ``model`` a candidate can modulate."""
    # constants (squareness, location errors) first: where a component's offset gives the
    # same columns (a radial error of C and its location error EY0C), ties go to the constant,
    # as in the declared model's gauge order
    out = [Target(p, "constant", p) for p in model.parameters if not model.parameter_axis.get(p)]
    out += [Target(p, "component", p, model.parameter_axis[p]) for p in model.parameters
            if model.parameter_axis.get(p)]
    out += [Target(f"setup.{k}", "setup", f"work.{k}") for k in SETUP_KEYS]
    out += [Target(f"tool.{k}", "tool", f"tool.{k}") for k in ("dx", "dy", "dz")]
    return out


# ---- C: the covariate columns ------------------------------------------------------------
def covariates(cov: dict, model=None) -> tuple[list, list]:
    """Covariates of the data columns ``cov`` (name -> (N,) floats): (list of
    :class:`Covariate`, warnings).  A constant column or one with NaN is left out with a
    one-line warning."""
    out, warn = [], []
    good = {}
    for c, v in cov.items():
        v = np.asarray(v, dtype=float)
        if not np.all(np.isfinite(v)):
            warn.append(f"covariate column {c} has NaN or infinite values: left out of the "
                        f"candidates")
        elif np.ptp(v) == 0:
            warn.append(f"covariate column {c} is constant ({float(v[0]):g}): left out of the "
                        f"candidates")
        else:
            good[c] = v
    probe_dir = next((t for t in _PROBE_DIRS if all(c in good for c in t)), ())
    if probe_dir:
        out.append(Covariate("probing direction", "probing_direction", "", "1", probe_dir))
    temps = []
    for c, v in good.items():
        if c in probe_dir:
            continue
        if c in _TIME:
            out.append(Covariate(c, "time", f"{c}/{_f(_TIME[c])}" if _TIME[c] != 1 else c,
                                 "h", (c,)))
        elif _TEMP.match(c):
            temps.append(c)
            out.append(Covariate(c, "temperature", f"({c} - 20)", "K", (c,)))
        elif c.startswith("dir_"):
            levels = np.unique(v)
            if len(levels) != 2:
                out.append(Covariate(c, "numeric", f"({c} - {_f(np.mean(v))})", "1", (c,)))
                continue
            lo, hi = float(levels[0]), float(levels[1])
            expr = f"{c}/2" if (lo, hi) == (-1.0, 1.0) else f"({c} - {_f((lo + hi) / 2)})/{_f(hi - lo)}"
            out.append(Covariate(c, "direction", expr, "1", (c,), (lo, hi)))
        elif c in _GROUP or (len(np.unique(v)) <= 12 and np.all(v == np.round(v))
                             and c.lower().startswith(_GROUP)):
            levels = np.unique(v)
            if 2 <= len(levels) <= 50:
                out.append(Covariate(c, "group", "", "1", (c,), tuple(float(x) for x in levels)))
        else:
            out.append(Covariate(c, "numeric", f"({c} - {_f(np.mean(v))})", "unit", (c,)))
    for a, b in itertools.combinations(temps, 2):
        if np.ptp(good[a] - good[b]) > 0:
            out.append(Covariate(f"{a} - {b}", "difference", f"({a} - {b})", "K", (a, b)))
    out += lagged_covariates(temps, good)
    return out, warn


def lagged_covariates(temps, good: dict) -> list:
    """Every temperature channel through a first-order lag over the data's time column
    (:mod:`volerr.machine.lags`; ``TAU`` in the expression stands for the time constant, in
    seconds, searched on :func:`lag_grid`); none without a time column."""
    from ..machine.lags import TIME_COLUMNS

    time = next((c for c in TIME_COLUMNS if c in good), None)
    if time is None:
        return []
    grid = lag_grid(good[time] * TIME_COLUMNS[time])
    if not grid:
        return []
    arg = "" if time == "t_s" else f", {time}"
    return [Covariate(f"lag({c})", "lagged", f"(lag({c}, TAU{arg}) - 20)", "K", (c, time),
                      grid) for c in temps]


#: ratio of neighbouring time constants of the lag grid (refined between neighbours)
LAG_GRID_RATIO = 1.5


def lag_grid(t_s) -> tuple:
    """Time constants (s) searched for a lag: a geometric grid from 3 times the median
    sampling interval (at least 60 s) to the campaign's duration; () when the campaign is
    shorter than 10 minutes or the sampling too sparse to show a lag."""
    t = np.unique(np.asarray(t_s, dtype=float))
    if len(t) < 20 or np.ptp(t) < 600.0:
        return ()
    lo = max(60.0, 3.0 * float(np.median(np.diff(t))))
    hi = float(np.ptp(t))
    if hi < 4 * lo:
        return ()
    k = int(np.ceil(np.log(hi / lo) / np.log(LAG_GRID_RATIO)))
    return tuple(round(float(x), 1) for x in np.geomspace(lo, hi, k + 1))


# ---- P x C x basis ------------------------------------------------------------------------
_KIND = {"temperature": "thermal", "difference": "thermal", "lagged": "thermal", "time": "drift",
         "direction": "reversal", "numeric": "covariate", "group": "group"}
_PREFIX = {"thermal": "KT", "drift": "DR", "reversal": "RV", "covariate": "CV", "group": "GR"}


def _unit(target: Target, per: str, slope_axis: str | None, model) -> tuple[float, str]:
    """Report factor and unit of a parameter of P x C (per: unit of the covariate basis)."""
    f, u = (1e6, "urad") if target.angular else (1e3, "um")
    if slope_axis is not None:        # parameter * A (mm) * basis: per m of travel
        f, u = f * 1e3, f"{u}/m"
    if per in ("1", ""):
        return f, u
    return f, f"{u}/{per}"


def _names(target: Target, cov: Covariate, kind: str, special: dict) -> tuple[str, str, str]:
    """(effect name, slope parameter, offset parameter) -- the former names where they exist."""
    tag = _ident(target.name.replace("setup.", "").replace("tool.", "T"))
    ctag = _ident(cov.name)
    key = (target.name, cov.name)
    if key in special:
        return special[key]
    pre = _PREFIX[kind]
    return f"{kind}_{tag}_{ctag}", f"{pre}_{tag}_{ctag}", f"{pre}0_{tag}_{ctag}"


def _special_names(model, covs) -> dict:
    """The names the eight former families used (reports and tests rely on them)."""
    lay = model.layout
    out = {}
    temps = [c for c in covs if c.kind == "temperature"]
    for c in temps:
        sfx = "" if c.name == "T_C" else f"_{c.name}"
        for a in model.axes:
            if a in model.rotary_axes:
                continue
            comp = along_component(lay, a)
            out[(comp, c.name)] = (f"thermal_{a}{sfx}", f"KT_{a}{sfx}", f"KT0_{a}{sfx}")
    for c in covs:
        if c.kind == "time":
            for k in "xyz":
                out[(f"setup.d{k}", c.name)] = (f"drift_{k}", f"DR_{k.upper()}", "")
        if c.kind == "direction":
            a = c.name[4:]
            if a in model.axes:
                comp = along_component(lay, a)
                out[(comp, c.name)] = (f"reversal_{a}", f"RV_{a}", "")
    return out


def _linear(model, target: Target, cov: Covariate, special, gauge) -> list:
    """P x C, linear in C.  A component error of a linear axis A is modulated as an offset, a
    slope along A, or both -- each only where it is not a gauge term of the declared model
    (a straightness slope is carried by squareness, a translational offset by the
    instrument's placement: those are the candidates "squareness x C", "set-up x C").  The
    position error along A always gets both (scale and fixed point, ``thermal_X``)."""
    kind = _KIND[cov.kind]
    name, ps, p0 = _names(target, cov, kind, special)
    b = cov.expr
    info = {"parameter": target.name, "covariate": cov.name, "basis": "linear"}
    if target.axis:
        info.update({"axis": target.axis, "component": target.name})
    if kind == "thermal":
        info["reference_C"] = 20.0
    if target.kind != "component" or target.axis in model.rotary_axes:
        out = [Candidate(kind, name, [(ps, target.chain, b)], dict(info),
                         units={ps: _unit(target, cov.unit, None, model)})]
        for comp, ax in _squareness_as_slopes(model, target):
            # the same squareness seen as the tilt of the other axis (differs from the
            # layout's convention by a rigid rotation, which a varying squareness need not share)
            out.append(Candidate(kind, f"{name}_via_{comp}", [(ps, comp, f"{ax}*{b}")],
                                 {**info, "basis": f"linear, as the tilt of {ax} ({comp})"},
                                 units={ps: _unit(target, cov.unit, None, model)}))
        return out
    a = target.axis
    p0 = p0 or f"{ps}_0"
    slope = (ps, target.chain, f"{a}*{b}")
    offset = (p0, target.chain, b)
    u_slope, u_off = _unit(target, cov.unit, a, model), _unit(target, cov.unit, None, model)
    if (target.name, cov.name) in special:
        if kind == "reversal":                     # the former family: position offset
            return [Candidate(kind, name, [(ps, target.chain, b)], dict(info),
                              units={ps: u_off})]
        # the former thermal family: scale + its fixed point
        return [Candidate(kind, name, [slope, offset], {**info, "basis": "linear, scale"},
                          units={ps: u_slope, p0: u_off})]
    out = []
    # an angular error's offset stays a candidate even where the declared model fixes it by
    # convention: varying with C it is one cause (a yaw of Y), not squareness + a yaw of X
    has0 = target.angular or (target.name, 0) not in gauge
    has1 = target.angular or (target.name, 1) not in gauge
    if has0:
        out.append(Candidate(kind, name, [(ps, target.chain, b)], dict(info),
                             units={ps: u_off}))
    if has1:
        out.append(Candidate(kind, f"{name}_slope", [slope], {**info, "basis": f"linear x {a}"},
                             units={ps: u_slope}))
    if has0 and has1:
        out.append(Candidate(kind, f"{name}_both", [slope, offset],
                             {**info, "basis": f"linear, offset + slope along {a}"},
                             units={ps: u_slope, p0: u_off}))
    return out


def _squareness_as_slopes(model, target: Target) -> list:
    """(straightness component, axis) pairs whose slope is the squareness ``target`` (the two
    linear axes square to each other about its rotation axis)."""
    if target.kind != "constant" or target.name not in model.layout.squareness:
        return []
    about = "ABC".index(target.name[1])
    out = []
    for a in model.axes:
        if a in model.rotary_axes:
            continue
        i = int(np.argmax(np.abs(model.layout.axes[a].direction)))
        if i == about:
            continue
        j = 3 - about - i
        comp = "E" + "XYZ"[j] + a
        if comp in model.parameters:
            out.append((comp, a))
    return out


def _lagged(model, target: Target, cov: Covariate, special, gauge) -> list:
    """P x lag(C, tau): the linear candidates of P x C with C through a first-order lag, its
    time constant searched on the covariate's grid (``cov.levels``; ``lag_s`` in the info, the
    sensor's column name as ``covariate``; the info's ``basis`` names the lag as
    ``lag(C, tau_s)`` whatever the time column, the terms over the data's time column)."""
    out = []
    for c in _linear(model, target, cov, special, gauge):
        def make(tau, terms=tuple(c.terms), basis=c.info["basis"]):
            from ..machine.lags import lag_key

            tau = round(float(tau), 1)
            return ([(p, t, b.replace("TAU", _f(tau))) for p, t, b in terms],
                    {"lag_s": tau, "basis": f"{basis}, {lag_key(cov.columns[0], tau)}"})

        grid = cov.levels
        terms, extra = make(grid[len(grid) // 2])
        info = {**c.info, "covariate": cov.columns[0], "lag_time_column": cov.columns[1],
                **extra}
        out.append(Candidate(c.kind, c.name, terms, info, Search("lag_s", grid, make), c.units))
    return out


def _warmup(model, target: Target, cov: Covariate, special) -> Candidate:
    name, ps, _ = _names(target, cov, "drift", special)
    name, ps = name.replace("drift", "warmup", 1), ps.replace("DR", "WU", 1)
    hours = cov.expr

    def make(tau, ps=ps, chain=target.chain):
        return [(ps, chain, f"(1 - exp(-{hours}/{_f(tau)}))")], {"tau_h": round(float(tau), 4)}

    terms, extra = make(TAU_GRID_H[0])
    f, u = (1e6, "urad") if target.angular else (1e3, "um")
    info = {"parameter": target.name, "covariate": cov.name, "basis": "saturating",
            **extra}
    return Candidate("drift", name, terms, info, Search("tau_h", TAU_GRID_H, make),
                     {ps: (f, u)})


def _group(model, target: Target, cov: Covariate) -> Candidate:
    g = cov.name
    terms, units = [], {}
    f, u = (1e6, "urad") if target.angular else (1e3, "um")
    for lv in cov.levels[1:]:
        tag = _level_tag(lv)
        if target.kind == "setup" and target.chain == "work.dx":
            for k in SETUP_KEYS:
                pn = f"SU{tag}_{g}_{k.upper()}"
                terms.append((pn, f"work.{k}", f"ind({g}, {_f(lv)})"))
                units[pn] = (1e6, "urad") if k[0] == "e" else (1e3, "um")
        else:
            pn = f"GR{tag}_{g}_{_ident(target.name)}"
            terms.append((pn, target.chain, f"ind({g}, {_f(lv)})"))
            units[pn] = (f, u)
    if target.kind == "setup":
        return Candidate("setup", f"setup_{g}", terms,
                         {"parameter": "setup", "covariate": g, "basis": "indicator",
                          "levels": list(cov.levels)}, units=units)
    return Candidate("group", f"group_{_ident(target.name)}_{g}", terms,
                     {"parameter": target.name, "covariate": g, "basis": "indicator",
                      "levels": list(cov.levels)}, units=units)


def _positions(model, target: Target, data: Data, ranges, degree) -> list:
    """Position bases of a component error: other axes (coupling), own axis (higher order,
    step, periodic)."""
    a, p = target.axis, target.name
    out = []
    f, u = (1e6, "urad") if target.angular else (1e3, "um")
    ua = _u(a, *ranges[a], a in model.rotary_axes)
    for b in model.axes:
        if b == a:
            continue
        ub = _u(b, *ranges[b], b in model.rotary_axes)
        terms = [(f"CP_{p}_{b}_11", p, f"{ua}*{ub}"),
                 (f"CP_{p}_{b}_21", p, f"legendre(2, {ua})*{ub}"),
                 (f"CP_{p}_{b}_12", p, f"{ua}*legendre(2, {ub})")]
        out.append(Candidate("coupling", f"coupling_{p}_{b}", terms,
                             {"parameter": p, "covariate": b, "basis": "legendre",
                              "component": p, "axis": a, "depends_on": b},
                             units={t[0]: (f, u) for t in terms}))
    q = data.positions[a]
    uniq = np.unique(np.round(q, 6))
    top = min(degree + 6, 14, len(uniq) - 1)
    if top > degree:
        terms = [(f"HO_{p}_{k}", p, f"legendre({k}, {ua})") for k in range(degree + 1, top + 1)]
        out.append(Candidate("higher_order", f"higher_order_{p}", terms,
                             {"parameter": p, "covariate": a, "basis": "legendre",
                              "component": p, "axis": a, "degrees": [degree + 1, top]},
                             units={t[0]: (f, u) for t in terms}))
    if a in model.rotary_axes:
        return out
    lo, hi = ranges[a]
    locs = tuple(sorted({float(x) for x in np.quantile(q, STEP_GRID)}))

    def make_step(x0, p=p, a=a):
        # a step of height ST at A = x0 (smooth over 1 nm: no division by zero anywhere)
        d = f"({a} - {_f(x0)})"
        return [(f"ST_{p}", p, f"(1 + {d}/sqrt({d}**2 + 1e-12))/2")], {"location_mm": round(x0, 3)}

    terms, extra = make_step(locs[len(locs) // 2])
    out.append(Candidate("step", f"step_{p}", terms,
                         {"parameter": p, "covariate": a, "basis": "step", "component": p,
                          "axis": a, **extra}, Search("location_mm", locs, make_step),
                         {f"ST_{p}": (f, u)}))
    if p[1] in "XYZ":
        span = hi - lo
        step = float(np.median(np.diff(uniq))) if len(uniq) > 2 else span
        pmin, pmax = max(2.2 * step, span / 60.0), span / 2.5
        if pmin < pmax:
            freqs = np.arange(1.0 / pmax, 1.0 / pmin, 1.0 / (4.0 * span))
            out.append(Candidate("periodic", f"periodic_{p}", [],
                                 {"parameter": p, "covariate": a, "basis": "periodic",
                                  "component": p, "axis": a},
                                 Search("period", tuple(1.0 / freqs),
                                        lambda per, p=p, a=a: (periodic_terms(p, a, per),
                                                               {"period": round(per, 6)})),
                                 {f"PS_{p}": (f, u), f"PC_{p}": (f, u)}))
    return out


def _level_tag(level: float) -> str:
    return _f(level).replace(".0", "").replace("-", "m").replace(".", "p")


def _symbol(model, t: syms.SymbolTarget, cov: Covariate) -> list:
    """Candidates of a nominal symbol x a covariate (:mod:`volerr.loop.symbols`): linear (a
    constant of the chain) or proportional (the probe offset, a rotary axis position) in the
    covariate, a saturating warm-up in time, one value per level of a run / set-up column;
    none for an approach direction (a symbol does not reverse)."""
    if cov.kind not in _KIND or cov.kind == "direction":
        return []
    st, ctag = syms.tag(t), _ident(cov.name)
    info = {"parameter": t.name, "covariate": cov.name, "symbol": t.name,
            "basis": "proportional" if t.proportional else "linear"}
    if t.value is not None:
        info["nominal_value"] = t.value
    if cov.kind == "group":
        if len(cov.levels) > 20:
            return []
        terms, units = [], {}
        for lv in cov.levels[1:]:
            pn = f"GR{_level_tag(lv)}_{ctag}_{st}"
            terms += t.make_terms(pn, f"ind({cov.name}, {_f(lv)})")
            units[pn] = syms.unit(t, "1")
        return [Candidate("group", f"group_{st}_{ctag}", terms,
                          {**info, "basis": "indicator" if not t.proportional
                           else "proportional, indicator", "levels": list(cov.levels)},
                          units=units)]
    kind = _KIND[cov.kind]
    pn = f"{_PREFIX[kind]}_{st}_{ctag}"
    if kind == "thermal":
        info["reference_C"] = 20.0
    out = [Candidate(kind, f"{kind}_{st}_{ctag}", t.make_terms(pn, cov.expr), dict(info),
                     units={pn: syms.unit(t, cov.unit)})]
    if cov.kind == "time":
        pw = f"WU_{st}_{ctag}"

        def make(tau, pw=pw, t=t, hours=cov.expr):
            terms = t.make_terms(pw, f"(1 - exp(-{hours}/{_f(tau)}))")
            return terms, {"tau_h": round(float(tau), 4)}

        terms, extra = make(TAU_GRID_H[0])
        out.append(Candidate("drift", f"warmup_{st}_{ctag}", terms,
                             {**info, "basis": "saturating" if not t.proportional
                              else "proportional, saturating", **extra},
                             Search("tau_h", TAU_GRID_H, make), {pw: syms.unit(t, "1")}))
    return out


def build(model, data: Data, ranges: dict, degree: int, covs=None, gauge=()) -> list:
    """All candidates P x C x basis for this layout and these data columns (``gauge``: the
    (parameter, degree) labels the declared model fixes by convention).  P: the declared
    parameters, the instrument's set-up, the tool end and the chain's nominal symbols
    (:mod:`volerr.loop.symbols`, whose docstring gives the order and why)."""
    gauge = set(gauge)
    if covs is None:
        covs, _ = covariates(data.covariates, model)
    special = _special_names(model, covs)
    tgts = targets(model)
    sym_const, sym_var = syms.targets(model, data)
    ordered = sym_const + sym_var + tgts
    out: list[Candidate] = []
    for cov in covs:
        if cov.kind == "probing_direction":
            out.append(Candidate("probe_direction", "probe_direction",
                                 [("PR_R", f"tool.d{k}", c) for k, c in zip("xyz", cov.columns)],
                                 {"parameter": "probe radius", "covariate": cov.name,
                                  "basis": "linear", "covariates": list(cov.columns)},
                                 units={"PR_R": (1e3, "um")}))
            continue
        if cov.kind == "lagged":
            for t in tgts:
                out += _lagged(model, t, cov, special, gauge)
            continue
        for t in ordered:
            if isinstance(t, syms.SymbolTarget):
                out += _symbol(model, t, cov)
                continue
            if cov.kind == "group":
                if t.kind == "setup" and t.chain != "work.dx":
                    continue            # the set-up is one candidate: all six coordinates
                if len(cov.levels) > 20 and t.kind != "setup":
                    continue
                out.append(_group(model, t, cov))
                continue
            out += _linear(model, t, cov, special, gauge)
            if cov.kind == "time" and not (t.kind == "component" and (t.name, 0) in gauge):
                out.append(_warmup(model, t, cov, special))
    for t in tgts:
        if t.kind == "component":
            out += _positions(model, t, data, ranges, degree)
    return out


def periodic_terms(component: str, axis: str, period: float) -> list:
    """Terms of a periodic candidate with a fixed period (axis units)."""
    arg = f"2*pi*{axis}/{_f(period)}"
    return [(f"PS_{component}", component, f"sin({arg})"),
            (f"PC_{component}", component, f"cos({arg})")]
