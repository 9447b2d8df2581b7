"""Thermal compensation a controller can run, from an augmented layout's thermal effects.

An augmented layout (``*_aug.toml``, written by ``volerr loop``) carries effects
``[effects.NAME]`` whose terms add ``parameter * basis`` to an error of the chain, the basis a
function of the axis positions, of logged temperatures ``T_*`` and of first-order lags of them
(``lag(T_motorX, 1249.5)``, :mod:`volerr.machine.lags`).  A controller's temperature
compensation is simpler: per linear machine axis ``A`` an error line in the axis' own
position ``P``::

    K_A(P, T) = K0_A(T) + tan(beta_A)(T) (P - P0_A)

whose offset ``K0`` and gradient ``tan(beta)`` the PLC sets from the temperatures the
controller reads (static: linear in ``T_j - 20`` degC, no lag).  The controller moves the
axis against ``K`` (the values are errors, as its axis compensation tables are).

Sources: SINUMERIK 840D sl Function Manual Extended Functions K3, "Temperature compensation"
(6FC5397-1BP40-3BA1, 03/2013, sec. 4.2): MD32750 ``$MA_TEMP_COMP_TYPE`` bit 0 the
position-independent value SD43900 ``$SA_TEMP_COMP_ABS_VALUE`` (mm), bit 1 the
position-dependent one with SD43920 ``$SA_TEMP_COMP_REF_POSITION`` (``P0``, mm) and SD43910
``$SA_TEMP_COMP_SLOPE`` (``tan beta``), the error line approximated as above and its
parameters updated by the PLC or part program as the temperature changes (840C: "the
parameters of new error lines ... must be transferred to the NC again"); MD32760
``$MA_COMP_ADD_VELO_FACTOR`` limits the compensation per IPO cycle.  ISG kernel (Beckhoff
TwinCAT CNC, "Temperature compensation", axis parameters): P-AXIS-00271
``lr_param.temp_comp`` on/off, P-AXIS-00272 ``temp_comp_position_0`` (basic position, 0.1 um),
P-AXIS-00273 ``temp_comp_offset_0`` (the temperature-dependent deviation there, 0.1 um),
P-AXIS-00274 ``temp_comp_coefficient`` (um/m), "adjusted by the PLC depending on the current
temperature".

What :func:`fit` does (the algorithm):

1. the log (time column, the temperatures) gives the temperatures and, through the layout's
   own lags, the lagged states; at most :data:`MAX_SAMPLES` readings equally spaced in the
   log are used (the lags are computed over the whole log first);
2. the full model's thermal error (every ``thermal`` effect with its fitted parameters; the
   first-order volumetric error of the augmented layout) on a grid over the working volume
   (``grid`` points per linear axis over the travel, rotary axes at fixed positions) at each
   of those readings;
3. the controller's model: per linear axis ``K0`` and ``tan beta`` linear in the sensors
   (``T_j - 20``), fitted by least squares to the full error: the axis' correction moves the
   tool tip by ``J_A K_A`` (``J_A`` the nominal Jacobian's column of the axis);
4. what that leaves: the full thermal error minus the corrections, max and rms of its length
   over grid and readings, beside the full error itself (no compensation).  Where the effects
   act through lags the controller's static model does not compute, the same fit with the
   lagged sensors as inputs (what a PLC that filtered each sensor with its time constant
   would do) is reported too.

Units: mm and mm/mm inside, um in the summary; temperatures degC; times s.
"""

from __future__ import annotations

import json
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from ..fileio import read_csv_rows
from ..machine.lags import TIME_COLUMNS, lag_of_columns

#: log readings used at most: a thermal state changes over minutes, a few hundred readings
#: of a day's log resolve it while grid x readings stays small (125 x 200 model evaluations)
MAX_SAMPLES = 200
#: the reference temperature of the sensors' terms (ISO 1: 20 degC)
T_REF = 20.0
#: decimals written: offsets in mm (1 nm), gradients in mm/mm (1e-4 um/m): finer than either
#: controller's resolution (ISG: 0.1 um and 1 um/m), so the rounding adds nothing
OFFSET_DECIMALS, SLOPE_DECIMALS = 6, 10
FORMATS = ("sinumerik-temp", "isg-temp")


@dataclass
class TempLog:
    """A temperature log: ``time`` the time column's name, ``t_s`` (S,) seconds,
    ``columns`` name -> (S,) every numeric column (the time column in its own unit)."""

    path: str
    time: str
    t_s: np.ndarray
    columns: dict


def read_log(path) -> TempLog:
    """A CSV log: a time column (``t_s``, ``t_min``, ``t_h``, ``time_s`` ...) increasing, and
    numeric columns (temperatures ``T_*`` degC, anything else); ``t_s`` is added in seconds
    when the log has another time column."""
    rows = read_csv_rows(path, missing=f"temperature log not found: {path}")
    header, body = rows[0][1], rows[1:]
    require(len(body) >= 2, f"{path}: fewer than two readings")
    times = [h for h in header if h in TIME_COLUMNS]
    require(times, f"{path}: no time column ({', '.join(TIME_COLUMNS)})")
    cols = {}
    for j, h in enumerate(header):
        vals = []
        for n, cells in body:
            require(len(cells) == len(header), f"{path} line {n}: {len(cells)} cells for "
                                               f"{len(header)} columns")
            try:
                vals.append(float(cells[j]))
            except ValueError:
                vals = None
                break
        if vals is not None:
            v = np.array(vals)
            require(np.all(np.isfinite(v)), f"{path}: column {h} has NaN or infinite values")
            cols[h] = v
    time = times[0]
    require(time in cols, f"{path}: the time column {time} is not numeric")
    t = cols[time] * TIME_COLUMNS[time]
    require(np.all(np.diff(t) > 0), f"{path}: the time column {time} must increase from "
                                    "reading to reading")
    cols.setdefault("t_s", t)           # the lags of a layout run over t_s by default
    return TempLog(str(path), time, t, cols)


def _to_model_units(value: float, unit: str, where: str) -> float:
    """A loop report's value (``um``, ``urad``, ``um/m/K`` ...) in the model's units (mm,
    rad, mm/mm per basis unit)."""
    head = unit.split("/")[0]
    scale = {"um": 1e-3, "urad": 1e-6, "mm": 1.0, "rad": 1.0}.get(head)
    require(scale is not None, f"{where}: unit {unit!r} not understood")
    if re.search(r"/m(/|$)", unit):
        scale *= 1e-3
    return value * scale


def effect_values(model, loop_json) -> dict:
    """The fitted parameters (model units) of the layout's ``thermal`` effects, from the loop
    report (``volerr loop --json``) that wrote the augmented layout."""
    p = Path(loop_json)
    require(p.is_file(), f"loop report not found: {loop_json}")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{p}: not a loop report (JSON: {exc})") from None
    require(isinstance(doc, dict) and isinstance(doc.get("effects"), list),
            f"{p}: not a loop report (no \"effects\" list)")
    given = {}
    for e in doc["effects"]:
        units = e.get("units", {}) if isinstance(e, dict) else {}
        for name, v in (e.get("parameters", {}) if isinstance(e, dict) else {}).items():
            given[name] = _to_model_units(float(v), str(units.get(name, "")), f"{p}: {name}")
    thermal = [e for e in model.layout.effects if e.kind == "thermal"]
    require(thermal, f"{model.name}: the layout has no thermal effect ([effects.*] kind "
                     "\"thermal\"; an augmented layout written by volerr loop)")
    out = {}
    for e in thermal:
        for name in e.parameters:
            require(name in given, f"{p}: no value of {name} (effect {e.name}): the report of "
                                   f"the loop run that wrote {model.name}")
            out[name] = given[name]
    return out


def used_sensors(model) -> list:
    """The sensors the thermal effects' bases read (also inside a lag), in order."""
    text = " ".join(t.basis for e in model.layout.effects if e.kind == "thermal"
                    for t in e.terms)
    return list(dict.fromkeys(re.findall(r"\bT(?:_\w+)?\b", text)))


@dataclass
class AxisComp:
    """The controller's error line of one linear axis: ``ref_position`` ``P0`` (mm),
    ``offset`` / ``slope`` (1 + m,): constant then one coefficient per sensor (per K) of
    ``K0`` (mm) and ``tan beta`` (mm/mm)."""

    axis: str
    ref_position: float
    offset: np.ndarray
    slope: np.ndarray


@dataclass
class TempComp:
    """The fit of :func:`fit`: ``axes`` the :class:`AxisComp` s, ``sensors`` the inputs,
    ``before`` / ``left`` (N,) lengths of the full thermal error and of what the controller's
    model leaves (mm), ``left_lagged`` the same with lagged inputs (None without lags),
    ``lags`` (covariate, tau_s) of the effects, ``points`` grid points, ``samples`` readings."""

    layout: str
    axes: list
    sensors: list
    before: np.ndarray
    left: np.ndarray
    left_lagged: np.ndarray | None
    lags: list = field(default_factory=list)
    points: int = 0
    samples: int = 0

    def summary(self) -> dict:
        def stats(v):
            return {"max": float(v.max() * 1e3), "rms": float(np.sqrt(np.mean(v ** 2)) * 1e3)}

        out = {"layout": self.layout, "sensors": self.sensors, "points": self.points,
               "samples": self.samples, "before_um": stats(self.before),
               "left_um": stats(self.left),
               "lags": [{"covariate": c, "lag_s": tau} for c, tau in self.lags],
               "left_with_lagged_sensors_um": None if self.left_lagged is None
               else stats(self.left_lagged),
               "axes": {a.axis: {"ref_position_mm": a.ref_position,
                                 "offset_mm": _coefs(a.offset, self.sensors),
                                 "slope": _coefs(a.slope, self.sensors)} for a in self.axes}}
        return out


def _coefs(c: np.ndarray, sensors) -> dict:
    return {"constant": float(c[0]),
            "per_K": {s: float(v) for s, v in zip(sensors, c[1:])}}


def _grid(model, grid: int, at: dict) -> np.ndarray:
    lin = [a for a in model.axes if a not in model.rotary_axes]
    ticks = [np.linspace(*model.travel[a], grid) for a in lin]
    mesh = np.meshgrid(*ticks, indexing="ij")
    q = np.zeros((mesh[0].size, len(model.axes)))
    for a, m in zip(lin, mesh):
        q[:, model.axes.index(a)] = m.ravel()
    for a in model.rotary_axes:
        lo, hi = model.travel[a]
        q[:, model.axes.index(a)] = min(max(float(at.get(a, 0.0)), lo), hi)
    return q


def _covariates(model, log: TempLog, idx: np.ndarray, g: int) -> dict:
    """The model's covariates at readings ``idx``, each repeated for the ``g`` grid points;
    a covariate the log lacks is 0 (refused where a thermal effect reads it)."""
    used = " ".join(t.basis for e in model.layout.effects if e.kind == "thermal"
                    for t in e.terms)
    cov = {}
    for c in model.covariates:
        if c in log.columns:
            cov[c] = np.repeat(log.columns[c][idx], g)
        else:
            require(re.search(rf"\b{re.escape(c)}\b", used) is None,
                    f"{log.path}: no column {c} (a thermal effect of {model.name} reads it)")
            cov[c] = np.zeros(len(idx) * g)
    for text, column, tau, time in model.lags:
        require(column in log.columns and time in log.columns,
                f"{log.path}: the lag {text} needs the columns {column} and {time}")
        cov[text] = np.repeat(lag_of_columns(log.columns, column, tau, time)[idx], g)
    return cov


def _thermal_error(model, q: np.ndarray, values: dict, cov: dict) -> np.ndarray:
    """The augmented model's volumetric error (N, 3) mm with the effects' ``values``, in
    blocks of the model's own block size: the lags go into the generated function as one
    dict, which :func:`volerr.machine.model._blocked` passes whole, not block by block."""
    from ..machine.model import BLOCK

    out = np.empty((len(q), 3))
    for i in range(0, len(q), BLOCK):
        sl = slice(i, i + BLOCK)
        out[sl] = model.volumetric_error(q[sl], values,
                                         covariates={k: v[sl] for k, v in cov.items()})
    return out


def _design(jac: np.ndarray, d: np.ndarray, r: np.ndarray) -> np.ndarray:
    """The columns of the error lines (3 N, L * 2 * (1 + m)): ``jac`` (N, 3, L) the axes'
    Jacobian columns, ``d`` (N, L) ``P - P0``, ``r`` (N, 1 + m) the inputs (1, T_j - 20);
    per axis the offset's coefficients, then the gradient's."""
    n, _, nl = jac.shape
    cols = []
    for a in range(nl):
        for part in (r, r * d[:, a:a + 1]):
            cols.append(jac[:, :, a:a + 1] * part[:, None, :])      # (N, 3, 1 + m)
    return np.concatenate(cols, axis=2).reshape(3 * n, -1)


def _solve(e: np.ndarray, design: np.ndarray) -> np.ndarray:
    """Least-squares coefficients (columns scaled to unit rms first)."""
    scale = np.sqrt(np.mean(design ** 2, axis=0))
    scale[scale == 0] = 1.0
    x, *_ = np.linalg.lstsq(design / scale, e.reshape(-1), rcond=None)
    return x / scale


def _left(e: np.ndarray, design: np.ndarray, x: np.ndarray) -> np.ndarray:
    """|what the corrections leave| (N,) mm."""
    return np.linalg.norm(e - (design @ x).reshape(e.shape), axis=1)


def fit(model, values: dict, log: TempLog, sensors=None, grid: int = 5, at=None) -> TempComp:
    """The controller's model fitted to the full one on the log (module docstring)."""
    from ..machine.kinematics import nominal_jacobian

    require(2 <= grid <= 30, "--grid must be 2..30 points per axis")
    sensors = list(sensors or used_sensors(model))
    require(sensors, f"{model.name}: its thermal effects read no temperature T_*")
    for s in sensors:
        require(s in log.columns, f"{log.path}: no column {s} (the sensors: "
                                  f"{', '.join(sensors)})")
    s_n = len(log.t_s)
    idx = np.unique(np.round(np.linspace(0, s_n - 1, min(s_n, MAX_SAMPLES))).astype(int))
    q = _grid(model, grid, at or {})
    g = len(q)
    q_all = np.tile(q, (len(idx), 1))
    e = _thermal_error(model, q_all, values, _covariates(model, log, idx, g))
    lin = [model.axes.index(a) for a in model.axes if a not in model.rotary_axes]
    jac = np.tile(nominal_jacobian(model, q)[:, :3, :][:, :, lin], (len(idx), 1, 1))
    ref = np.array([0.5 * sum(model.travel[model.axes[j]]) for j in lin])
    d = q_all[:, lin] - ref

    def inputs(series):
        return np.column_stack([np.ones(len(q_all))] +
                               [np.repeat(series[s][idx], g) - T_REF for s in sensors])

    design = _design(jac, d, inputs(log.columns))
    k = len(sensors) + 1
    # rounded as written (the left is what the written lines leave)
    coef = _solve(e, design).reshape(len(lin), 2, k)
    coef[:, 0] = np.round(coef[:, 0], OFFSET_DECIMALS)
    coef[:, 1] = np.round(coef[:, 1], SLOPE_DECIMALS)
    coef += 0.0                                         # no -0
    left = _left(e, design, coef.reshape(-1))
    lags = [(column, tau) for _, column, tau, _ in model.lags]
    left_lagged = None
    if lags:                # each sensor through (the first of) its effects' lags
        lagged = dict(log.columns)
        for _, column, tau, time in reversed(model.lags):
            lagged[column] = lag_of_columns(log.columns, column, tau, time)
        design2 = _design(jac, d, inputs(lagged))
        left_lagged = _left(e, design2, _solve(e, design2))
    # an axis whose line is 0 at every temperature is left out
    axes = [AxisComp(model.axes[j], float(ref[i]), coef[i, 0], coef[i, 1])
            for i, j in enumerate(lin) if np.any(coef[i] != 0)]
    require(axes, f"{model.name}: the thermal effects move no linear axis along itself on this "
                  "log (nothing a temperature compensation carries)")
    return TempComp(model.name, axes, sensors, np.linalg.norm(e, axis=1), left, left_lagged,
                    lags, g, len(idx))


# ---------------------------------------------------------------------------------------
# the files
def _num(v: float) -> str:
    s = f"{v:.12f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def _linear_text(c: np.ndarray, sensors, names) -> str:
    """``c0+c1*(R1-20)+...`` with the sensors' names ``names``."""
    out = _num(c[0])
    for v, n in zip(c[1:], names):
        out += f"{'+' if v >= 0 else '-'}{_num(abs(v))}*({n}-{_num(T_REF)})"
    return out


def write_sinumerik(result: TempComp) -> str:
    """A part program setting SD43900 / SD43910 / SD43920 of every linear axis from R
    parameters holding the temperatures (R1 the first sensor ...)."""
    r = [f"R{k + 1}" for k in range(len(result.sensors))]
    out = [f"; volerr export: layout {result.layout}; SINUMERIK temperature compensation "
           "(K3): K = SD43900 + SD43910 (P - SD43920), errors in mm",
           "; MD32750 $MA_TEMP_COMP_TYPE = 3 for each axis below (bit 0 position-"
           "independent, bit 1 position-dependent)",
           "; the temperatures (degC): " + ", ".join(f"{a} = {s}" for a, s in
                                                       zip(r, result.sensors)),
           "; the PLC (or a synchronized action) writes them and runs these lines again "
           "as they change", "%_N_TEMP_COMP_SPF"]
    for a in result.axes:
        ax = f"{a.axis}1"
        out += [f"$SA_TEMP_COMP_REF_POSITION[{ax}]={_num(a.ref_position)}",
                f"$SA_TEMP_COMP_ABS_VALUE[{ax}]={_linear_text(a.offset, result.sensors, r)}",
                f"$SA_TEMP_COMP_SLOPE[{ax}]={_linear_text(a.slope, result.sensors, r)}"]
    out.append("M17")
    return "\n".join(out) + "\n"


def write_isg(result: TempComp, axes) -> str:
    """ISG axis parameter lists (one block per linear axis, ``kopf.achs_nr`` the axis'
    number in the layout's order) with the values at 20 degC and the PLC's formulas."""
    out = [f"# volerr export: layout {result.layout}; ISG temperature compensation "
           "(P-AXIS-00271..00274): the values at 20 degC;",
           "# the PLC sets offset and coefficient from the temperatures (degC) as written "
           "in the comments (offset in mm, coefficient in mm/mm)"]
    names = result.sensors
    for a in result.axes:
        out += ["#", f"kopf.achs_nr {list(axes).index(a.axis) + 1}",
                f"# axis {a.axis}: offset_0 = {_linear_text(a.offset, names, names)}",
                f"# axis {a.axis}: coefficient = {_linear_text(a.slope, names, names)}",
                "lr_param.temp_comp 1",
                f"lr_param.temp_comp_position_0 {int(round(a.ref_position * 1e4))}",
                f"lr_param.temp_comp_offset_0 {int(round(a.offset[0] * 1e4))}",
                f"lr_param.temp_comp_coefficient {int(round(a.slope[0] * 1e6))}"]
    return "\n".join(out) + "\n"
