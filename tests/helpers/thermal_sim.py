"""An independent exact simulator of a machine whose geometry follows its temperatures through a
first-order lag (acceptance tests of issue 30, "Loop lags"; never calls volerr's loop, simulate,
generated code or model: the chain is the one of ``tests/helpers/instrument_sim.py`` /
``family_sim.py``, numpy / scipy on the parsed layout).

What it simulates
-----------------
* **Duty cycles** (:class:`Duty`): when the drives run, when the coolant pump runs, over a day
  of ``hours`` (day A: drives 6 h on, then off, pump with the drives; day B: drives 2 h on, 2 h
  off, on again, pump all day).
* **Temperatures** (degC) on a fine time grid (``DT_S`` = 2 s), each a physical response through
  its own time constant(s): the room air (a slow warm-up plus the air-conditioning cycle), motors
  and spindle heated by their load while the drives run, the coolant heated by its pump, the
  hydraulic unit (powered all day, thermostat cycle), column and bed following air and the heat
  sources slowly.  They are correlated like real sensors (every one rides on the room air; most
  respond to the same drives), but each has its own signature.  Logged sensors are these
  temperatures at the points' times plus 0.01 K noise; ``twins`` adds sensors that repeat
  another one up to noise and an offset (two sensors no campaign can separate).
* **The planted effect** acts through :func:`lag` of the TRUE (noise-free, fine-grid) temperature
  of ONE sensor: on a CMM the X scale ``EXX += k * 1e-6 * X * (lag(T_motorX, tau) - 20)`` (k in
  um/m/K, X mm); on a five-axis machine a location error of a rotary axis
  ``EX0C += k * 1e-3 * (lag(T, tau) - 20)`` (k in um/K).
* **Static errors**: polynomials of low degree (squareness, slopes, Legendre P2 terms; rotary
  location errors), so that the loop's declared model holds the truth; the instrument's rigid
  placement is unknown (six set-up unknowns).
* **Readings**: exact chain, ``dx_um, dy_um, dz_um`` with Gaussian noise ``u_um`` (0.3 um).

:func:`lag` is exact for a piecewise-linear input: ``tau dy/dt = x - y`` with ``y(t0) = x(t0)``
(at rest at the first sample); the step from t_k to t_(k+1), h long, with the input's slope
``s = (x_(k+1) - x_k) / h`` and ``a = exp(-h / tau)``:
``y_(k+1) = x_(k+1) - tau s + a (y_k - x_k + tau s)``.

:meth:`Campaign.floor`: the held-out RMS (um, length of each point's residual vector) that the
TRUE model reaches on the same data: the planted static terms, the planted lag term (with the
true tau and the true noise-free temperature) and the six set-up unknowns refitted by least
squares on the training rows, evaluated on the held-out rows (``test_rows`` of the loop's
JSON).  :meth:`Campaign.heldout_rms` does the same for any other lag basis (another sensor, a
wrong tau): what a proxy model reaches.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.signal import lfilter

from helpers import family_sim as F
from helpers import instrument_sim as S

DT_S = 2.0                     # fine time grid of the physics, s
SENSOR_NOISE_K = 0.01

#: the logged sensors of a CMM campaign (8) and of a five-axis campaign (9)
CMM_SENSORS = ("T_spindle", "T_motorX", "T_column", "T_bed", "T_coolant", "T_air1", "T_air2",
               "T_hydraulic")
FIVE_AXIS_SENSORS = CMM_SENSORS + ("T_table",)
STYLI = ((60, 0, -80), (-60, 0, -80), (0, 60, -80), (0, -60, -80), (0, 0, -60), (0, 0, -150))


# ---- exact first-order lag -----------------------------------------------------------------
def lag(t_s, x, tau_s: float, y0: float | None = None) -> np.ndarray:
    """First-order lag ``tau dy/dt = x - y`` of ``x`` sampled at ``t_s`` (s, increasing), exact
    for ``x`` linear between samples; ``y0``: the value at the first sample (default ``x[0]``:
    at rest).  ``tau_s = 0`` returns ``x``."""
    t = np.asarray(t_s, float)
    x = np.asarray(x, float)
    y = np.empty_like(x)
    y[0] = x[0] if y0 is None else y0
    if tau_s == 0:
        return x.copy()
    h = np.diff(t)
    a = np.exp(-h / tau_s)
    s = np.divide(np.diff(x), h, out=np.zeros_like(h), where=h > 0)
    for k in range(len(h)):                         # a recursion: one pass, O(n)
        y[k + 1] = x[k + 1] - tau_s * s[k] + a[k] * (y[k] - x[k] + tau_s * s[k])
    return y


def _lag_fast(t_s, x, tau_s):
    """:func:`lag` on a uniform grid: the same recursion ``y_(k+1) = a y_k + b_k`` run as a
    one-pole filter (``scipy.signal.lfilter``)."""
    t = np.asarray(t_s, float)
    x = np.asarray(x, float)
    h = t[1] - t[0]
    if tau_s == 0 or not np.allclose(np.diff(t), h, rtol=1e-9, atol=1e-9):
        return lag(t, x, tau_s)
    a = np.exp(-h / tau_s)
    s = np.diff(x) / h
    b = x[1:] - tau_s * s - a * (x[:-1] - tau_s * s)
    y = np.empty_like(x)
    y[0] = x[0]
    y[1:], _ = lfilter([1.0], [1.0, -a], b, zi=[a * x[0]])
    return y


# ---- duty cycles and temperatures --------------------------------------------------------------
@dataclass(frozen=True)
class Duty:
    """Intervals (h from the start of the campaign) when the drives / the coolant pump run."""

    drives: tuple
    pump: tuple
    hours: float = 10.0

    def on(self, what: str, t_h: np.ndarray) -> np.ndarray:
        out = np.zeros_like(t_h)
        for lo, hi in getattr(self, what):
            out[(t_h >= lo) & (t_h < hi)] = 1.0
        return out


DAY_A = Duty(drives=((0.0, 6.0),), pump=((0.0, 6.0),))
DAY_B = Duty(drives=((0.0, 2.0), (4.0, 10.0)), pump=((0.0, 10.0),))


def _square(t_h, period_h, phase=0.0):
    return (np.sin(2 * np.pi * (t_h / period_h + phase)) > 0).astype(float)


def temperatures(duty: Duty, seed: int = 0) -> tuple[np.ndarray, dict]:
    """True temperatures (degC) on the fine grid: (t_s, {sensor: (n,)}).  Time constants in
    minutes in the comments; every response starts at rest (machine cold at t = 0)."""
    rng = np.random.default_rng(seed)
    # one step before t = 0: every input off and the room steady, so all start at rest
    t = np.arange(-DT_S, duty.hours * 3600.0 + DT_S, DT_S)
    t_h = t / 3600.0
    tp = np.clip(t_h, 0.0, None)
    L = lambda x, tau_min: _lag_fast(t, x, 60.0 * tau_min)  # noqa: E731
    ph = rng.uniform(0, 1, 4)
    # room: morning warm-up and the air-conditioning cycle (~95 min) that starts with the shift
    air = (19.8 + 0.5 * (1 - np.exp(-tp / 4.0))
           + 0.25 * (1 - np.exp(-tp / 0.5)) * np.sin(2 * np.pi * (tp / 1.6 + ph[0])))
    drives, pump = duty.on("drives", t_h), duty.on("pump", t_h)
    # loads: the X drive alternates long and short strokes (47 min), the spindle its program (73)
    load_x = drives * (0.7 + 0.6 * _square(t_h, 47 / 60, ph[1]))
    load_s = drives * (0.6 + 0.8 * _square(t_h, 73 / 60, ph[2]))
    T = {}
    T["T_air1"] = air
    T["T_air2"] = L(air, 6) + 0.5 * L(drives, 45)                 # near the machine
    T["T_motorX"] = L(air, 10) + 6.0 * L(load_x, 12)              # small mass, quick
    T["T_spindle"] = L(air, 15) + 5.0 * L(load_s, 22)
    T["T_coolant"] = L(air, 50) + 3.5 * L(pump, 35)               # the tank, its pump
    # hydraulics: powered all day, its thermostat cycles the cooler (~35 min)
    hyd = 4.0 * (1 - np.exp(-tp / 0.75)) - 0.6 * _square(tp, 35 / 60, ph[3]) * (t_h > 0)
    T["T_hydraulic"] = L(air, 30) + L(hyd, 8)
    T["T_column"] = L(0.5 * air + 0.5 * T["T_spindle"], 80)
    T["T_bed"] = L(0.8 * air + 0.2 * T["T_coolant"], 150)
    # the table drive indexes in phases of the program (2.2 h)
    T["T_table"] = L(air, 20) + 4.0 * L(drives * (0.3 + 1.4 * _square(t_h, 2.2, ph[1])), 18)
    return t, T


# ---- campaign ----------------------------------------------------------------------------------
def _scale_term(comp, key, name):
    """``comp += param * 1e-6 * q * (cov[key] - 20)``: param in um/m/K (a scale)."""
    axis = comp[2]
    return S.Term(name, comp, lambda b: 1e-6 * b.pos[axis] * (b.cov[key] - 20.0))


def _location_term(target, key, name):
    """``target += param * 1e-3 * (cov[key] - 20)`` (param um/K; urad/K for an angle)."""
    s = 1e-6 if S.is_angular(target) else 1e-3
    return S.Term(name, target, lambda b: s * (b.cov[key] - 20.0))


def _cmm_statics(m):
    tr = m.travel
    terms = [S.constant("EC0Y"), S.constant("EB0Z"), S.constant("EA0Z"),
             S.series("EXX", 1, *tr["X"]), F.legendre_term("EYX", 2, *tr["X"]),
             F.legendre_term("EZY", 2, *tr["Y"]), S.series("EYY", 1, *tr["Y"]),
             F.legendre_term("EBX", 2, *tr["X"]), F.legendre_term("ECY", 1, *tr["Y"]),
             F.legendre_term("EAZ", 1, *tr["Z"])]
    values = {"EC0Y": 15.0, "EB0Z": -10.0, "EA0Z": 8.0, "EXX@slope": 0.006, "EYX@P2": 3.0,
              "EZY@P2": -2.5, "EYY@slope": -0.004, "EBX@P2": 4.0, "ECY@P1": 3.0,
              "EAZ@P1": -3.0}
    return terms, values


def _five_axis_statics(m, rng):
    terms, values = _cmm_statics(m)
    locs = [n for a in m.rotary for n in m.layout.axes[a].location_errors]
    terms = terms + [S.constant(n) for n in locs]
    values = {**values, **{n: float(v) for n, v in zip(locs, rng.normal(0.0, 15.0, len(locs)))}}
    return terms, values


@dataclass
class Planted:
    """The planted effect: ``target`` (an ISO error) follows lag(``sensor``, ``tau_s``) with
    ``value`` (um/m/K for a scale ``EXX``-like component, um/K for a location error)."""

    target: str = "EXX"
    sensor: str = "T_motorX"
    tau_s: float = 2400.0
    value: float = 5.0


@dataclass
class Campaign:
    """One simulated file: its block, terms, planted values, set-up, readings (um)."""

    machine: S.Machine
    block: S.Block
    terms: list
    values: dict
    setup: dict
    y: np.ndarray
    sensors: tuple
    planted: Planted | None
    fine: tuple = field(repr=False, default=None)     # (t_s, true temperatures)
    twins: dict = field(default_factory=dict)         # twin sensor -> the sensor it repeats

    # -- files
    def columns(self) -> dict:
        cols = S.columns(self.machine, self.block, self.y, covariates=False)
        cols["t_s"] = self.block.cov["t_s"]
        for s in self.sensors:
            cols[s] = self.block.cov[s]
        return cols

    def write(self, path) -> str:
        return S.write_csv(path, self.columns())

    # -- true lagged temperatures
    def true_lag(self, sensor: str, tau_s: float) -> np.ndarray:
        """lag(true temperature of ``sensor``, tau) at the points' times (fine grid, exact)."""
        t, T = self.fine
        src = T[self.twins.get(sensor, sensor)]
        return np.interp(self.block.cov["t_s"], t, _lag_fast(t, src, tau_s))

    def logged_lag(self, sensor: str, tau_s: float) -> np.ndarray:
        """lag of the LOGGED (noisy, sampled) sensor column: what a model of the file can use."""
        return lag(self.block.cov["t_s"], self.block.cov[sensor], tau_s)

    # -- held-out RMS of a model
    def _statics(self):
        """Design of the planted static terms and the set-ups (cached)."""
        if getattr(self, "_static_design", None) is None:
            terms = [t for t in self.terms if self.values.get(t.param) and t.param != "LAG"]
            self._static_design = F.design(self.machine, [self.block], terms)
        return self._static_design

    def _unit(self, target: str) -> np.ndarray:
        """(3n,) change of the readings per unit of the basis' temperature factor: central
        differences of the exact chain with ``target`` driven by a temperature 1 K above 20."""
        b = self.block
        b.cov["_unit"] = np.full(b.n, 21.0)
        term = (_scale_term if _is_scale(target) else _location_term)(target, "_unit", "U")
        try:
            d = F.design(self.machine, [b], [term])
        finally:
            b.cov.pop("_unit")
        return d.J[:, 0]

    def heldout_rms(self, test_rows, lagged=None, target=None) -> float:
        """Held-out RMS (um, length of each point's residual vector) of the static terms + the
        set-ups + one term on ``target`` (default the planted one) driven by ``lagged`` (an (n,)
        temperature, degC: ``target += c * (lagged - 20)``, times X for a scale), fitted by
        least squares on the other rows; ``lagged=None``: the declared statics alone.  The
        term's column is the exact chain's per-point derivative times ``lagged - 20`` (the
        readings are linear in it to far below the noise)."""
        d = self._statics()
        y = np.ravel(self.y)
        test = np.isin(d.rows[:, 1], np.asarray(test_rows, int))
        q, r_inv, w = self._train_basis(test)
        yw = y[~test] * w
        col = np.zeros_like(y)
        if lagged is not None:
            tgt = target or self.planted.target
            cache = self.__dict__.setdefault("_units", {})
            if tgt not in cache:
                cache[tgt] = self._unit(tgt)
            col = cache[tgt] * np.repeat(np.asarray(lagged, float) - 20.0, 3)
        # least squares of [col, statics] on the training rows by projection on the statics
        cw = col[~test] * w
        c_perp = cw - q @ (q.T @ cw)
        cc = c_perp @ c_perp
        coef = (c_perp @ yw) / cc if cc > 0 else 0.0
        theta = r_inv @ (q.T @ (yw - coef * cw))
        res = (y - coef * col - d.J @ theta)[test].reshape(-1, 3)
        return float(np.sqrt(np.mean(np.sum(res ** 2, axis=1))))

    def _train_basis(self, test):
        """Orthonormal basis (QR) of the weighted static columns on the training rows, cached
        per split."""
        cache = self.__dict__.setdefault("_qr", {})
        k = test.tobytes()
        if k not in cache:
            d = self._statics()
            w = d.weights[~test]
            q, r = np.linalg.qr(d.J[~test] * w[:, None])
            cache[k] = (q, np.linalg.pinv(r), w)
        return cache[k]

    def floor(self, test_rows) -> float:
        """Held-out RMS of the TRUE model (true sensor, true tau, true temperature) refitted
        on the training rows; clean campaigns: the statics and set-ups alone."""
        if self.planted is None:
            return self.heldout_rms(test_rows)
        return self.heldout_rms(test_rows, self.true_lag(self.planted.sensor, self.planted.tau_s))

    def best_proxy(self, test_rows, sensor, taus_s=None, target=None) -> tuple[float, float]:
        """(held-out RMS, tau_s) of the best model through lag(``sensor``, tau) of the LOGGED
        column over a grid of tau (0, 1 min .. 4 h): what the campaign lets that sensor reach."""
        grid = taus_s if taus_s is not None else np.concatenate(
            [[0.0], 60.0 * np.geomspace(1.0, 240.0, 25)])
        best = (np.inf, 0.0)
        for tau in grid:
            r = self.heldout_rms(test_rows, self.logged_lag(sensor, tau), target)
            best = min(best, (r, float(tau)))
        return best


def _is_scale(target: str) -> bool:
    return len(target) == 3 and target[1] == target[2]


def campaign(layout: str = "MB1", duty: Duty = DAY_A, planted: Planted | None = Planted(),
             n: int = 3000, seed: int = 0, u_um: float = 0.3, twins: dict | None = None,
             sensors=None, probes=STYLI, rotary_choices=None, temp_seed: int = 7) -> Campaign:
    """A deviations campaign of ``n`` points over ``duty.hours`` (one every hours/n, jittered),
    random positions over the travel, random styli among ``probes``; ``twins``: extra sensor
    name -> the sensor it repeats (up to 0.01 K noise and a 0.3 K offset); ``temp_seed``: the
    phases of the thermal cycles (the same machine on another day keeps them)."""
    m = F.Machine(layout)
    rng = np.random.default_rng(seed)
    five = bool(m.rotary)
    sensors = tuple(sensors or (FIVE_AXIS_SENSORS if five else CMM_SENSORS))
    t_fine, T = temperatures(duty, temp_seed)
    step = duty.hours * 3600.0 / n
    t_s = (np.arange(n) + 0.5 + rng.uniform(-0.3, 0.3, n)) * step
    cov = {"t_s": t_s}
    for s in sensors:
        cov[s] = np.interp(t_s, t_fine, T[s]) + rng.normal(0.0, SENSOR_NOISE_K, n)
    for twin, of in (twins or {}).items():
        cov[twin] = np.interp(t_s, t_fine, T[of]) + 0.3 + rng.normal(0.0, SENSOR_NOISE_K, n)
    sensors = sensors + tuple(twins or ())
    if five and rotary_choices is None:
        rotary_choices = {a: (np.arange(0.0, 181.0, 15.0) if a in ("A", "B")
                              else np.arange(-180.0, 180.0, 30.0)) for a in m.rotary}
    b = S.deviations_block(m, f"{layout}.csv", n, rng, probes=probes,
                           rotary_choices=rotary_choices, u_um=u_um, cov=cov)
    terms, values = _five_axis_statics(m, rng) if five else _cmm_statics(m)
    setup = F.placement(rng, [b])
    camp = Campaign(m, b, terms, values, setup, None, sensors, planted, (t_fine, T),
                    dict(twins or {}))
    if planted is not None:
        b.cov["_true"] = camp.true_lag(planted.sensor, planted.tau_s)
        term = (_scale_term if _is_scale(planted.target) else _location_term)(
            planted.target, "_true", "LAG")
        camp.terms = terms + [term]
        camp.values = {**values, "LAG": planted.value}
    exact = F.readings(m, b, camp.terms, camp.values, setup)
    camp.y = exact + rng.normal(0.0, u_um, exact.shape)
    return camp
