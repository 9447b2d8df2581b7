"""A second, independent simulator of spindle thermal drift (a machine other than
tests/helpers/drift_sim.py's): written from the physics, numpy only, none of volerr's code
(its own first-order filter, its own regression).

The machine
-----------
* **Spindle heat**: the power loss of the bearings and the motor grows with the speed to a
  power between 1 and 2 (Palmgren; Bossmanns & Tu 1999): ``q = (S / S_REF) ** HEAT_P`` with
  ``HEAT_P = 1.3``, ``S_REF = 12000 rpm`` (the top speed: a coefficient is the drift at it).
* **The planted drift of the tool point along the channel** (um)::

      d = A_FAST * lag(q, TAU_FAST) + A_SLOW * lag(q, TAU_SLOW) + B_ROOM * (room - room(t0))

  the spindle nose growing fast as the bearings heat (``TAU_FAST`` = 20 min) and the column
  bending back slowly as the headstock casting heats (``TAU_SLOW`` = 3 h, the opposite sign),
  plus the structure following the room (a daily sine of ``ROOM_AMP_K``); read with
  ``D_NOISE_UM`` Gaussian noise and an arbitrary zero per run.
* **Sensors** (logged with ``T_NOISE_K`` noise): ``T_room`` the room; ``T_bearing`` = room +
  ``K_BEARING`` lag(q, ``TAU_BEARING``) (fast proxy); ``T_casting`` = lag(room, 1 h) +
  ``K_CASTING`` lag(q, ``TAU_CASTING``) (slow proxy); ``T_coolant`` = the chiller's set point
  with its on/off cycle (``CHILLER_PERIOD_S``) + ``K_COOLANT`` lag(q, ``TAU_COOLANT``);
  ``T_cabinet`` an electrics cabinet wandering slowly on its own (a smooth random process),
  ``T_spare`` a sensor taped to nothing (noise about a constant): neither is related to d.
* **Runs**: every run starts with the machine at rest in equilibrium with the room (the lags
  start at zero), on another day (another phase of the room cycle), with its own duty cycle
  (speed steps and cool-downs, :data:`PROGRAMMES`); speed changes on whole minutes, so the
  speed is exactly piecewise constant between readings at 15 s or 60 s.

The first-order lag of a piecewise-constant input (the heat: zero-order hold), exactly:
``y_k = x_{k-1} + (y_{k-1} - x_{k-1}) exp(-h / tau)``; of a smooth input (the room) with the
input linear between samples: ``y_k = x_k - s tau + (y_{k-1} - x_{k-1} + s tau) exp(-h/tau)``,
``s`` the slope over the step.

The floor (:func:`true_model_prediction`): the TRUE model structure (its two time constants,
its exponent, the room) refitted by least squares on the training runs' logged inputs (a zero
per run) and predicting a held-out run from its logged inputs and its first reading, the way
the loop's contract predicts one.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

S_REF = 12000.0
HEAT_P = 1.3
A_FAST, TAU_FAST = 10.0, 1200.0          # um at S_REF, s (20 min)
A_SLOW, TAU_SLOW = -6.0, 10800.0         # um at S_REF, s (3 h)
B_ROOM = 1.5                             # um/K
ROOM_MEAN, ROOM_AMP_K, DAY_S = 20.0, 1.2, 86400.0
K_BEARING, TAU_BEARING = 8.0, 600.0
K_CASTING, TAU_CASTING = 5.0, 7200.0
CASTING_ROOM_TAU_S = 3600.0
COOLANT_SET, CHILLER_AMP_K, CHILLER_PERIOD_S = 22.0, 0.3, 1800.0
K_COOLANT, TAU_COOLANT = 1.5, 900.0
CABINET_MEAN, CABINET_STD_K, CABINET_TAU_S = 26.0, 0.4, 7200.0
SPARE_MEAN = 24.0
T_NOISE_K = 0.05
D_NOISE_UM = 0.3
SAMPLE_S = 15.0
RUN_H = 12.0
SENSORS = ("T_room", "T_bearing", "T_casting", "T_coolant", "T_cabinet", "T_spare")

#: duty cycles: (start h, rpm) steps, the last speed held to RUN_H; and the hour of day the
#: run starts (the room's phase)
PROGRAMMES = {
    "run1": (((0, 0), (0.25, 3000), (3, 6000), (6, 9000), (9, 0)), 6.0),
    "run2": (((0, 0), (0.25, 12000), (2.25, 0), (4.25, 12000), (6.25, 0), (8.25, 6000),
              (10.25, 0)), 14.0),
    "run3": (((0, 0), (0.25, 8000), (5, 0)), 22.0),
    "run4": (((0, 0), (0.25, 10000), (1.5, 4000), (3.5, 0), (5, 12000), (8, 2000),
              (10, 0)), 10.0),
}
HELD_OUT = "run4"


def lag_hold(x, tau_s: float, h: float) -> np.ndarray:
    """Lag of an input constant over each step (value at the step's start), at rest
    (``y_0 = 0`` for an input zero before the start)."""
    a = np.exp(-h / tau_s)
    y = np.zeros(len(x))
    for k in range(1, len(x)):
        y[k] = x[k - 1] + (y[k - 1] - x[k - 1]) * a
    return y


def lag_linear(x, tau_s: float, h: float) -> np.ndarray:
    """Lag of an input linear between samples, at rest at the start (``y_0 = x_0``)."""
    x = np.asarray(x, float)
    a = np.exp(-h / tau_s)
    y = np.empty(len(x))
    y[0] = x[0]
    for k in range(1, len(x)):
        s = (x[k] - x[k - 1]) / h
        y[k] = x[k] - s * tau_s + (y[k - 1] - x[k - 1] + s * tau_s) * a
    return y


def speed(t_s: np.ndarray, steps) -> np.ndarray:
    s = np.zeros(len(t_s))
    for start_h, rpm in steps:
        s[t_s >= start_h * 3600.0] = rpm
    return s


def simulate_run(name: str, seed: int, planted: bool = True, a_slow: float = A_SLOW) -> dict:
    """One run every ``SAMPLE_S`` s: {"t_s", "S_rpm", "d_x_um", sensors..., "truth": the
    noise-free drift, "noise": the displacement noise}; ``a_slow`` the slow term's size (um
    at S_REF; the default the opposite sign of the fast one)."""
    steps, hour = PROGRAMMES[name]
    rng = np.random.default_rng(seed)
    h = SAMPLE_S
    t = np.arange(0.0, RUN_H * 3600.0 + h / 2, h)
    S = speed(t, steps)
    q = (S / S_REF) ** HEAT_P
    room = ROOM_MEAN + ROOM_AMP_K * np.sin(2 * np.pi * (t + hour * 3600.0) / DAY_S)
    true = {
        "T_room": room,
        "T_bearing": room + K_BEARING * lag_hold(q, TAU_BEARING, h),
        "T_casting": lag_linear(room, CASTING_ROOM_TAU_S, h)
        + K_CASTING * lag_hold(q, TAU_CASTING, h),
        "T_coolant": COOLANT_SET + CHILLER_AMP_K * np.sin(2 * np.pi * t / CHILLER_PERIOD_S
                                                          + rng.uniform(0, 2 * np.pi))
        + K_COOLANT * lag_hold(q, TAU_COOLANT, h),
    }
    wander = lag_linear(rng.normal(size=len(t)), CABINET_TAU_S, h)
    wander = (wander - wander.mean()) / wander.std()
    true["T_cabinet"] = CABINET_MEAN + CABINET_STD_K * wander
    true["T_spare"] = np.full(len(t), SPARE_MEAN)
    drift = (A_FAST * lag_hold(q, TAU_FAST, h) + a_slow * lag_hold(q, TAU_SLOW, h)
             + B_ROOM * (room - room[0]))
    if not planted:
        drift = np.zeros(len(t))
    noise = rng.normal(0.0, D_NOISE_UM, len(t))
    zero = rng.uniform(-5.0, 5.0)
    out = {"t_s": t, "S_rpm": S, "d_x_um": zero + drift + noise, "truth": drift,
           "noise": noise}
    for k in SENSORS:
        out[k] = true[k] + rng.normal(0.0, T_NOISE_K, len(t))
    return out


def campaign(seed: int = 31, planted: bool = True, a_slow: float = A_SLOW) -> dict:
    """{run name: run} for every programme (seeds ``seed + i``)."""
    return {name: simulate_run(name, seed + i, planted, a_slow)
            for i, name in enumerate(PROGRAMMES)}


def subsample(run: dict, every: int) -> dict:
    """Every ``every``-th reading of the run (the same readings, a slower logger)."""
    return {k: v[::every] for k, v in run.items()}


def write_drift(path: Path, run: dict, direction: str = "X") -> Path:
    cols = ["t_s", "S_rpm", "d_x_um", *SENSORS]
    lines = ["# simulated spindle drift run (tests/helpers/spindle_machine_sim.py)",
             f"# channel d_x: {direction}", ",".join(cols)]
    data = np.column_stack([run[c] for c in cols])
    lines += [",".join(f"{v:.6f}" for v in row) for row in data]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return Path(path)


def write_campaign(folder: Path, runs: dict) -> list:
    return [write_drift(Path(folder) / f"{name}.csv", run) for name, run in runs.items()]


# ---- the references the loop is judged against ------------------------------------------
def _true_columns(run: dict) -> np.ndarray:
    """The true model's columns from the LOGGED inputs (speed, T_room), zero at the start."""
    h = float(np.median(np.diff(run["t_s"])))
    q = (run["S_rpm"] / S_REF) ** HEAT_P
    room = run["T_room"]
    return np.column_stack([lag_hold(q, TAU_FAST, h), lag_hold(q, TAU_SLOW, h),
                            room - room[0]])


def _static_columns(run: dict) -> np.ndarray:
    """Every temperature's change since the run's start (the shop's static regression)."""
    return np.column_stack([run[k] - run[k][0] for k in SENSORS if np.ptp(run[k]) > 0])


def _refit_predict(train: list, test: dict, columns) -> np.ndarray:
    """Least squares on the training runs (a zero per run), the held-out run predicted from
    its first reading plus the fitted terms (the columns are zero at its start)."""
    blocks = [columns(r) for r in train]
    n = [len(b) for b in blocks]
    Z = (np.repeat(np.arange(len(train)), n)[:, None] == np.arange(len(train))).astype(float)
    X = np.column_stack([Z, np.vstack(blocks)])
    y = np.concatenate([r["d_x_um"] for r in train])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    Xt = columns(test)
    return test["d_x_um"][0] + Xt @ coef[len(train):]


def true_model_prediction(train: list, test: dict) -> np.ndarray:
    return _refit_predict(train, test, _true_columns)


def static_prediction(train: list, test: dict) -> np.ndarray:
    return _refit_predict(train, test, _static_columns)


def errors(test: dict, pred: np.ndarray) -> dict:
    e = test["d_x_um"] - pred
    return {"mae": float(np.mean(np.abs(e))), "rms": float(np.sqrt(np.mean(e ** 2)))}


def term_contribution(run_list: list, effect: dict, term: dict) -> np.ndarray:
    """One reported term's contribution over the runs ``run_list`` (concatenated): its
    coefficient x its column, computed here from the effect's covariate(s), exponent, S_ref
    and lag, zero at every run's start."""
    total = []
    for run in run_list:
        h = float(np.median(np.diff(run["t_s"])))
        covs = effect["covariates"]
        lag_s = (term.get("lag_s") or {}).get("value") or 0.0
        if covs == ["S_rpm"]:
            x = (run["S_rpm"] / effect["S_ref_rpm"]) ** effect["heat_exponent"]
            col = lag_hold(x, lag_s, h) if lag_s > 0 else x
        else:
            parts = [lag_linear(run[c], lag_s, h) if lag_s > 0 else run[c] for c in covs]
            col = parts[0] - (parts[1] if len(parts) > 1 else 0.0)
        total.append(term["value"] * (col - col[0]))
    return np.concatenate(total)


def dominant_covariate(run_list: list, effects: list) -> str | None:
    """The covariate (joined by ' - ' for a difference) of the effect whose terms together
    move the prediction most over ``run_list`` (RMS of their summed contribution); None
    without effects.  Ties: the first effect in the report's order."""
    best, name = -1.0, None
    for e in effects:
        contrib = sum(term_contribution(run_list, e, t) for t in e["terms"])
        rms = float(np.sqrt(np.mean(contrib ** 2)))
        if rms > best:
            best, name = rms, " - ".join(e["covariates"])
    return name


def write_run(path, run: dict, env: str, cols, direction: str = "X") -> None:
    """One simulated run ``run`` {column: (N,)} as a drift file: the channel line (``d_x``
    along ``direction``, "?" for none), the columns ``cols`` to 6 decimals and the run's
    ``environment`` label on every row."""
    cols = list(cols)
    lines = [f"# channel d_x: {direction}", ",".join(cols + ["environment"])]
    lines += [",".join(f"{run[c][i]:.6f}" for c in cols) + f",{env}"
              for i in range(len(run["t_s"]))]
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
