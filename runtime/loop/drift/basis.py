"""The basis of the loop on drift runs: what a displacement channel may vary with, and the
blocked folds it is judged on (:mod:`volerr.loop.drift.fit` runs the selection).

A drift run holds one machine position while the machine heats and cools: the declared
geometric model predicts a constant per channel (the run's zero).  What varies is heat; the
columns a channel may vary with are, over every reading of every run (train and test: a lag
is causal, the held-out part is predicted from its own inputs):

* each sensor ``T_*`` (and any other logged input but the spindle speed), as its change since
  the run's first reading, plain and through a first-order lag ``lag(T, tau)``
  (:func:`volerr.machine.lags.lag`: exact for readings linear between samples, started in
  equilibrium at the run's first reading, afresh in every run);
* the heat input of the spindle: ``q = (S / S_ref) ** p`` with ``S_ref`` the largest speed of
  the training part (so a coefficient is the displacement at that speed) and ``p`` an
  exponent on ``P_GRID`` (friction heat of a bearing grows with the speed to a power between
  about 1 and 2: Bossmanns & Tu 1999; Palmgren's friction moment), plain and through a lag:
  ``lag(q, tau)`` is the standard first-order thermal response to a heat source switched on
  and off;
* differences of two sensors (a gradient) are combinations of these columns
  (:mod:`volerr.loop.drift.select` forms them from the cross-products).

Time constants: a geometric grid of ``N_TAU`` values from ``TAU_MIN_STEPS`` reading intervals
(at least 60 s) to half the training duration; the selected one is refined between its grid
neighbours, within the grid's range.  Columns are scaled to unit RMS over the training part (conditioning; the
reported coefficients are in the units of the unscaled column).

Folds (the split rule of ``volerr formats loop-lags``): where the files name the runs'
``environment`` (a room held constant or varying, another programme) and the training runs
span at least ``RUN_FOLDS_MIN`` environments, every fold is one whole environment (all its
runs, each predicted from its own zero, its first reading): the cross-validation then
measures how a model carries over to a room behaviour it was not fitted on, not how it
interpolates within one (two environments are two folds, each fitted on half the runs: too
coarse to select with; measured on tests/loop/test_drift_environment.py's machine with two
training environments, 1.7-2.0 x the floor against 1.1-1.3 x by whole runs); otherwise,
with at least ``RUN_FOLDS_MIN`` training runs every fold is one whole run;
otherwise ``K_FOLDS`` folds, fold k being the k-th of ``K_FOLDS`` contiguous stretches of
every run's training readings (each run keeps a zero fitted on its other stretches).  Folds
are whole stretches, never readings drawn at random: readings 15 s apart are almost equal.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import require
from .series import DriftSeries

__all__ = ["Column", "DriftSeries", "folds", "whole_runs", "heat", "kept_out", "library",
           "many_runs", "modelled", "reference", "room", "room_undecided", "series", "sensors",
           "tau_grid", "trained_runs", "unseen"]

P_GRID = (0.5, 1.0, 1.5, 2.0, 2.5)   # exponents of the spindle speed tried for the heat input
N_TAU = 14                # time constants on the grid
TAU_MIN_STEPS = 4.0       # the shortest lag: this many reading intervals (and >= 60 s)
K_FOLDS = 6               # contiguous stretches per run when the folds are not whole runs
RUN_FOLDS_MIN = 3         # training runs from which every fold is one whole run
SENSOR_TAU_SPAN = 0.125  # a sensor's lag is searched up to this share of the training span
SPEED = "S_rpm"           # the logged input the heat input is derived from
#: a sensor whose changes in the held-out runs span more than this many times its changes in
#: the training runs is kept out of the lag model (its coefficient was never determined there)
KEEP_OUT_RATIO = 4.0
#: training runs (in folds of whole runs) from which the run is the unit: "many runs"
MANY_RUNS = 6
#: words in a logged input's name that make it a sensor of the room air (the environment)
ROOM_WORDS = ("room", "ambient")
#: the training runs hold the room for a sensor where the room's change spans at most this
#: share of the sensor's own change (:func:`room_undecided`)
ROOM_HELD_SHARE = 0.2
#: ... and the held-out runs' room changes by more than this many times the training's
ROOM_VARY_RATIO = 3.0
ROOM_RULE = (f"the held-out runs' room changes (peak to peak since each run's zero) more "
             f"than {ROOM_VARY_RATIO:g} x the training runs', and the sensors named change "
             f"in training at least {1 / ROOM_HELD_SHARE:g} x the room: their absolute "
             f"change and their rise over the room are one column there")


@dataclass
class Column:
    """One basis column: ``source`` (a sensor or ``heat``), ``tau_s`` (0: no lag), ``p`` (the
    heat input's exponent, None for a sensor), ``scale`` (its RMS over training)."""

    source: str
    tau_s: float
    p: float | None = None
    scale: float = 1.0
    minus: str | None = None     # the room sensor a sensor's rise is taken over (reference)

    @property
    def label(self) -> str:
        what = self.source if self.p is None else f"(S/S_ref)^{self.p:g}"
        what = f"{what} - {self.minus}" if self.minus else what
        return f"lag({what}, {self.tau_s:.0f} s)" if self.tau_s > 0 else what


def tau_grid(s: DriftSeries) -> np.ndarray:
    """The time constants (s) searched: ``N_TAU`` from the shortest lag to half the training
    duration (geometric); kept in ``memo`` for the split it was computed on."""
    key = ("_tau_grid", s.test.tobytes())
    if key not in s.memo:
        s.memo[key] = _tau_grid(s)
    return s.memo[key]


def _tau_grid(s: DriftSeries) -> np.ndarray:
    tr = s.train
    dt = float(np.median(np.diff(s.t_s)[np.diff(s.run) == 0])) if len(s.t_s) > 1 else 1.0
    lo = max(60.0, TAU_MIN_STEPS * dt)
    span = max(float(np.ptp(s.t_s[tr & (s.run == r)])) if np.any(tr & (s.run == r)) else 0.0
               for r in range(len(s.runs)))
    hi = max(span / 2.0, 4 * lo)
    return np.geomspace(lo, hi, N_TAU)


def sensors(s: DriftSeries) -> list:
    """The logged inputs read as sensors: every input but the speed and constant ones, in the
    order of the file."""
    tr = s.train
    return [k for k, v in s.inputs.items() if k != SPEED and np.ptp(v[tr]) > 0]


def many_runs(s: DriftSeries) -> bool:
    """Whether the training part is "many runs": folds of whole runs (:func:`folds`) and at
    least ``MANY_RUNS`` training runs.  Then the run is the unit: what a rule trusts to be
    judged on runs the fit never saw (a lag of hours, a room of its own) is judged on
    several of them (on three, a trend of one day passed for an effect)."""
    f, rule = folds(s)
    return whole_runs(rule) and len(np.unique(s.run[f >= 0])) >= MANY_RUNS


def reference(s: DriftSeries) -> str | None:
    """The room sensor every other sensor's rise is taken over: with many runs
    (:func:`many_runs`), the first logged sensor whose name holds one of ``ROOM_WORDS``
    (None: no such sensor, or not many runs).  Why: a sensor on the machine reads the room plus what the machine's
    heat adds; trained where the room is held, its coefficient is the heat's, and applied
    to its reading in a varying room it would carry the room's change into the drift at the
    heat's rate.  Taken as its rise over the room (``T - T_room``, through the same lag) the
    heat's part enters alone, and the room enters as an input of its own, plain and through
    its own lags (room air reaches the structure through hours)."""
    return room(s) if many_runs(s) else None


def room(s: DriftSeries) -> str | None:
    """The room sensor: the first logged sensor whose name holds one of ``ROOM_WORDS``
    (None: none), whether or not the other sensors are taken as rises over it."""
    return next((k for k in sensors(s) if is_room(k)), None)


def alternative_reference(s: DriftSeries) -> str | None:
    """The other reading of the sensors (:func:`room_undecided`): plain where the model takes
    them as rises over the room (:func:`reference`), else their rise over the room sensor
    (:func:`room`)."""
    return None if reference(s) else room(s)


def is_room(k: str) -> bool:
    """Whether the input named ``k`` is a sensor of the room air (``ROOM_WORDS``)."""
    return any(w in k.lower() for w in ROOM_WORDS)


def entered(s: DriftSeries, k: str, ref: str | None) -> np.ndarray:
    """The sensor ``k`` as the model takes it: its reading, or its rise over the room
    sensor ``ref`` (:func:`reference`; a room sensor itself is taken plain)."""
    v = np.asarray(s.inputs[k], float)
    return v - np.asarray(s.inputs[ref], float) if ref and not is_room(k) else v


def kept_out(s: DriftSeries) -> list:
    """The sensors kept out of the lag model: where whole runs are held out, every sensor whose
    change since the run's zero spans (peak to peak) more than ``KEEP_OUT_RATIO`` times as much
    in the held-out runs as in the training runs (a room held constant in training, varying in
    the runs judged).  Its coefficient would rest on changes a fraction of those it is applied
    to, often on its noise, or carry an effect of the heat it happened to follow in training:
    a coefficient these data never determined, extrapolated.  The model leaves it out and the
    report names it; what the held-out runs do through it is then unmodelled, as the physics
    of the training runs allows.  [{"input", "train_change", "test_change"}] in file order
    (units of the input)."""
    whole = unseen(s)
    if not whole.any():
        return []
    out = []
    ref = reference(s)
    for k in sensors(s):
        v = entered(s, k, ref)
        a, b = _change_ptp(s, v, s.train), _change_ptp(s, v, whole)
        if b > KEEP_OUT_RATIO * a:
            out.append({"input": k if not (ref and not is_room(k)) else f"{k} - {ref}",
                        "sensor": k, "train_change": a, "test_change": b})
    return out


def trained_runs(s: DriftSeries) -> np.ndarray:
    """Per run (bool): whether it has a training reading (a run without one is predicted
    from its first reading)."""
    return np.array([np.any(s.train & (s.run == r)) for r in range(len(s.runs))])


def unseen(s: DriftSeries) -> np.ndarray:
    """The held-out readings of the runs without a training reading (whole held-out runs)."""
    return s.test & ~trained_runs(s)[s.run]


def _change_ptp(s: DriftSeries, v, mask) -> float:
    """Peak to peak (units of the input) of the input values ``v``'s change since its run's
    zero over the readings ``mask`` (pooled over their runs)."""
    v = np.asarray(v, float)
    d = (v - s.zero(v))[mask]
    return float(np.ptp(d)) if len(d) else 0.0


def room_undecided(s: DriftSeries) -> dict | None:
    """What a training in a held room cannot decide: whether a sensor acts by its absolute
    change (a temperature of the structure: its change carries over) or by its rise over
    the room (a proxy of the machine's heat: its rise carries over).  The two readings of a
    sensor differ by the room's change alone; where the training runs hold the room they
    are nearly one column, and the model's reading (:func:`reference`: rises with many
    runs, else plain) is an assumption these data do not test; where the held-out runs'
    room moves, the two predict differently.

    The rule (changes since each run's zero, peak to peak over all readings of a part,
    pooled over its runs, K): a room sensor (:func:`room`) and whole held-out runs; the
    held-out runs' room change more than ``ROOM_VARY_RATIO`` x the training runs' (several
    times: the two readings then differ there by more than anything the blocked CV saw);
    and the sensors named are the modelled ones (:func:`modelled`; not the room's own)
    whose own training change is at least 1 / ``ROOM_HELD_SHARE`` x the room's (the two
    readings differ in training by at most a fifth of the sensor's change: with a room
    independent of the heat they correlate above 0.98, which no blocked CV separates from
    the heat's lags).  None where it does not fire (no such sensor).  Returns {"room",
    "train_room_ptp_K", "held_out_room_ptp_K", "reading" (the model's: "rise over the
    room" or "absolute"), "alternative" (the other), "sensors": [{"sensor",
    "train_change_K", "room_share"}] in file order}."""
    k_room = room(s)
    whole = unseen(s)
    if k_room is None or not whole.any():
        return None
    v_room = s.inputs[k_room]
    a, b = _change_ptp(s, v_room, s.train), _change_ptp(s, v_room, whole)
    if not b > ROOM_VARY_RATIO * a:
        return None
    named = []
    for k in modelled(s):
        own = _change_ptp(s, s.inputs[k], s.train)
        if not is_room(k) and a <= ROOM_HELD_SHARE * own:
            named.append({"sensor": k, "train_change_K": own, "room_share": a / own})
    if not named:
        return None
    rise = reference(s) is not None
    return {"room": k_room, "train_room_ptp_K": a, "held_out_room_ptp_K": b,
            "reading": "rise over the room" if rise else "absolute",
            "alternative": "absolute" if rise else "rise over the room", "sensors": named}


def modelled(s: DriftSeries) -> list:
    """The sensors the lag model may use: :func:`sensors` but those :func:`kept_out`."""
    out = {e["sensor"] for e in kept_out(s)}
    return [k for k in sensors(s) if k not in out]


def heat(s: DriftSeries, p: float) -> np.ndarray:
    """``(S / S_ref) ** p`` (N,), ``S_ref`` the largest |speed| of the training part."""
    S = np.abs(np.asarray(s.inputs[SPEED], float))
    ref = float(S[s.train].max())
    return (S / ref) ** p


def series(s: DriftSeries, source: str, tau_s: float, p: float | None = None) -> np.ndarray:
    """The unscaled column: the change since each run's first reading of a sensor, or the
    heat input, through a lag ``tau_s`` (0: none), restarted in every run."""
    from ...machine.lags import lag

    u = heat(s, p) if source == "heat" else np.asarray(s.inputs[source], float)
    y = lag(u, tau_s, s.t_s, s.run, order=s.order()) if tau_s > 0 else u
    return y - s.zero(y)


def library(s: DriftSeries, alternative: bool = False) -> tuple[list, np.ndarray]:
    """Every basis column (list of :class:`Column`) and their values (N, m), scaled;
    ``alternative``: the sensors in their other reading (:func:`alternative_reference`), the
    same columns otherwise (same sensors, lags and order)."""
    taus = tau_grid(s)
    ref = alternative_reference(s) if alternative else reference(s)
    cols = []
    for name in modelled(s):
        m = ref if ref and not is_room(name) else None
        cols += [Column(name, 0.0, minus=m)] + [Column(name, float(t), minus=m) for t in taus]
    if SPEED in s.inputs and np.ptp(s.inputs[SPEED][s.train]) > 0:
        for p in P_GRID:
            cols += [Column("heat", 0.0, p)] + [Column("heat", float(t), p) for t in taus]
    X = np.empty((len(s.t_s), len(cols)))
    for j, c in enumerate(cols):
        X[:, j] = series(s, c.source, c.tau_s, c.p)
        if c.minus:
            X[:, j] -= series(s, c.minus, c.tau_s)
    sc = np.sqrt(np.mean(X[s.train] ** 2, axis=0))
    sc = np.where(sc > 0, sc, 1.0)
    for c, v in zip(cols, sc):
        c.scale = float(v)
    X /= sc                    # in place: the same quotients, no second (N, m) array
    return cols, X


def folds(s: DriftSeries) -> tuple[np.ndarray, str]:
    """Fold index (N,) of every training reading (-1: held out) and the rule used
    (``"environments"``, ``"runs"`` or ``"stretches"``), by the rule of the module
    docstring."""
    tr = s.train
    f = np.full(len(s.t_s), -1)
    train_runs = [r for r in range(len(s.runs)) if np.any(tr & (s.run == r))]
    envs = list(dict.fromkeys(s.environments[r] for r in train_runs)) if s.environments else []
    if len(envs) >= RUN_FOLDS_MIN:
        for r in train_runs:
            f[tr & (s.run == r)] = envs.index(s.environments[r])
        return f, "environments"
    if len(train_runs) >= RUN_FOLDS_MIN:
        for k, r in enumerate(train_runs):
            f[tr & (s.run == r)] = k
        return f, "runs"
    for r in train_runs:
        idx = np.flatnonzero(tr & (s.run == r))
        f[idx] = np.minimum(np.arange(len(idx)) * K_FOLDS // len(idx), K_FOLDS - 1)
    require(len(set(f[tr])) >= 2, "loop: too few training readings for a cross-validation "
            "(at least two stretches of time are needed)")
    return f, "stretches"


def whole_runs(rule: str) -> bool:
    """Whether the folds of ``rule`` are whole runs (each predicted from its first reading)."""
    return rule in ("runs", "environments")
