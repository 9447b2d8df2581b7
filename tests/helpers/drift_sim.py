"""An independent simulator of thermal drift runs (ISO 230-3 spindle tests) for the acceptance
tests of the loop on drift runs (issue 35; written without volerr's loop, lags, simulate or
model: numpy only, its own first-order filter).

What it simulates
-----------------
* **A spindle programme** (:func:`programme`): a duty cycle ``"on:2h,off:2h,on:3h"`` at one
  speed (rpm); the machine at rest (in equilibrium with the room) at the start of every run.
* **Heat**: the spindle's power loss grows with speed, ``P = (S / 5000 rpm) ** HEAT_POWER``
  (bearing friction and motor losses grow faster than the speed).
* **Temperatures** on a fine grid of ``DT_S`` seconds, each a first-order response:
  the room ``T_room`` (20 degC, a swing of ``ROOM_SWING_K`` over a ``ROOM_PERIOD_H`` cycle of
  the air conditioning, its phase per run); ``T_fast`` (a sensor next to the bearings) = room +
  ``FAST_K`` x lag(P, ``FAST_TAU_S``); ``T_slow`` (the headstock casting) = lag(room,
  ``SLOW_ROOM_TAU_S``) + ``SLOW_K`` x lag(P, ``SLOW_TAU_S``); ``T_mid`` (the coolant return) =
  room + ``MID_K`` x lag(P, ``MID_TAU_S``): proxies of one heat source, correlated, each with
  its own response.  Logged every ``SAMPLE_S`` seconds with ``T_NOISE_K`` noise.
* **The planted displacement** (:class:`Planted`): the tool point moves along the channel by
  ``k * (lag(T, tau) - T(t0))`` um, ``T`` the TRUE (noise-free, fine-grid) temperature of one
  sensor, the lag at rest at the start; readings with ``D_NOISE_UM`` Gaussian noise and a
  zero of the sensor (arbitrary, per run).  Without a planted effect the readings are noise
  about the zero.

:func:`lag` is exact for an input linear between samples: with ``h`` the step, ``a =
exp(-h / tau)`` and ``s`` the input's slope over the step, ``y1 = x1 - s tau + (y0 - x0 + s tau)
a`` (the solution of ``tau y' + y = x0 + s t``), starting at rest ``y(t0) = x(t0)``.

:func:`true_prediction` is the contract's prediction of a held-out run by the TRUE model (its
logged inputs and its first displacement reading, nothing else): ``d(t0) + k (lag(T_log, tau)(t)
- T_log(t0))``, the floor the loop is judged against.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

DT_S = 5.0
SAMPLE_S = 60.0
HEAT_POWER = 1.5
ROOM_SWING_K = 0.8
ROOM_PERIOD_H = 9.0
FAST_K, FAST_TAU_S = 7.0, 420.0
MID_K, MID_TAU_S = 3.0, 1500.0
SLOW_K, SLOW_TAU_S = 5.0, 5400.0
SLOW_ROOM_TAU_S = 3600.0
T_NOISE_K = 0.01
D_NOISE_UM = 0.15
SENSORS = ("T_fast", "T_mid", "T_slow", "T_room")


@dataclass(frozen=True)
class Planted:
    """The planted effect: ``um_per_K`` x (lag(``sensor``, ``tau_s``) - its start) um."""

    sensor: str
    tau_s: float
    um_per_K: float


def lag(x: np.ndarray, tau_s: float, dt_s: float) -> np.ndarray:
    """First-order lag of ``x`` sampled every ``dt_s`` (linear between samples), at rest."""
    x = np.asarray(x, dtype=float)
    a = np.exp(-dt_s / tau_s)
    y = np.empty_like(x)
    y[0] = x[0]
    for k in range(1, len(x)):
        s = (x[k] - x[k - 1]) / dt_s
        y[k] = x[k] - s * tau_s + (y[k - 1] - x[k - 1] + s * tau_s) * a
    return y


def lag_irregular(x: np.ndarray, tau_s: float, t_s: np.ndarray) -> np.ndarray:
    """:func:`lag` over irregular times ``t_s`` (the logged samples)."""
    x, t = np.asarray(x, dtype=float), np.asarray(t_s, dtype=float)
    y = np.empty_like(x)
    y[0] = x[0]
    for k in range(1, len(x)):
        h = t[k] - t[k - 1]
        a = np.exp(-h / tau_s)
        s = (x[k] - x[k - 1]) / h
        y[k] = x[k] - s * tau_s + (y[k - 1] - x[k - 1] + s * tau_s) * a
    return y


def programme(spec: str, rpm: float) -> tuple[np.ndarray, np.ndarray]:
    """(t_s, S_rpm) on the fine grid of a duty cycle ``"on:2h,off:1.5h"`` (h, min or s)."""
    parts = []
    for item in spec.split(","):
        state, _, dur = item.strip().partition(":")
        m = re.fullmatch(r"([0-9.]+)(h|min|s)", dur.strip())
        secs = float(m.group(1)) * {"h": 3600.0, "min": 60.0, "s": 1.0}[m.group(2)]
        parts.append((state == "on", secs))
    total = sum(s for _, s in parts)
    t = np.arange(0.0, total + DT_S / 2, DT_S)
    s = np.zeros_like(t)
    start = 0.0
    for on, secs in parts:
        s[(t >= start) & (t < start + secs)] = rpm if on else 0.0
        start += secs
    return t, s


def temperatures(t: np.ndarray, s_rpm: np.ndarray, room_phase: float) -> dict:
    """The TRUE temperatures (degC) on the fine grid (module docstring)."""
    p = (s_rpm / 5000.0) ** HEAT_POWER
    room = 20.0 + ROOM_SWING_K * np.sin(2 * np.pi * t / (ROOM_PERIOD_H * 3600) + room_phase)
    return {"T_fast": room + FAST_K * lag(p, FAST_TAU_S, DT_S),
            "T_mid": room + MID_K * lag(p, MID_TAU_S, DT_S),
            "T_slow": lag(room, SLOW_ROOM_TAU_S, DT_S) + SLOW_K * lag(p, SLOW_TAU_S, DT_S),
            "T_room": room}


def simulate_run(spec: str, rpm: float, planted: Planted | None, seed: int,
                 room_phase: float = 0.0, zero_um: float = 0.0) -> dict:
    """One run: {"t_s", "S_rpm", "d_x_um", T_*: logged (N,) arrays, "truth_um": the
    noise-free displacement from the start (N,)}."""
    rng = np.random.default_rng(seed)
    t, s = programme(spec, rpm)
    temps = temperatures(t, s, room_phase)
    truth = np.zeros_like(t)
    if planted is not None:
        T = temps[planted.sensor]
        truth = planted.um_per_K * (lag(T, planted.tau_s, DT_S) - T[0])
    step = int(round(SAMPLE_S / DT_S))
    idx = np.arange(0, len(t), step)
    out = {"t_s": t[idx], "S_rpm": s[idx]}
    out["d_x_um"] = zero_um + truth[idx] + rng.normal(0.0, D_NOISE_UM, len(idx))
    for k in SENSORS:
        out[k] = temps[k][idx] + rng.normal(0.0, T_NOISE_K, len(idx))
    out["truth_um"] = truth[idx]
    return out


def write_drift(path: Path, run: dict, direction: str = "X") -> Path:
    """The run as a drift file (``volerr formats drift``): one channel ``d_x`` along
    ``direction``."""
    cols = ["t_s", "S_rpm", "d_x_um", *SENSORS]
    lines = [f"# simulated spindle drift run (tests/helpers/drift_sim.py)",
             f"# channel d_x: {direction}", ",".join(cols)]
    data = np.column_stack([run[c] for c in cols])
    lines += [",".join(f"{v:.6f}" for v in row) for row in data]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return Path(path)


def true_prediction(run: dict, planted: Planted | None) -> np.ndarray:
    """The TRUE model's prediction of a held-out run from its logged inputs and its first
    displacement reading (module docstring)."""
    d0 = run["d_x_um"][0]
    if planted is None:
        return np.full_like(run["d_x_um"], d0)
    T = run[planted.sensor]
    return d0 + planted.um_per_K * (lag_irregular(T, planted.tau_s, run["t_s"]) - T[0])


def true_mae(run: dict, planted: Planted | None) -> float:
    """Mean absolute error of :func:`true_prediction` over the run, um."""
    return float(np.mean(np.abs(run["d_x_um"] - true_prediction(run, planted))))


def fit_single(train: list, test: dict, column: str, tau_s: float,
               power: float | None = None) -> float:
    """The held-out MAE of the best model ``zero_run + k lag(column ** power, tau)`` fitted by
    least squares on ``train`` (one zero per run), predicted as the contract says: the
    simulator's own reference for telling candidates apart (not the loop)."""
    def basis(run):
        x = run[column] if power is None else (run[column] / 5000.0) ** power
        return lag_irregular(x, tau_s, run["t_s"])

    rows, ys = [], []
    for j, run in enumerate(train):
        b = basis(run)
        z = np.zeros((len(b), len(train)))
        z[:, j] = 1.0
        rows.append(np.column_stack([b, z]))
        ys.append(run["d_x_um"])
    coef = np.linalg.lstsq(np.vstack(rows), np.concatenate(ys), rcond=None)[0]
    b = basis(test)
    pred = test["d_x_um"][0] + coef[0] * (b - b[0])
    return float(np.mean(np.abs(test["d_x_um"] - pred)))


#: the acceptance campaigns: two training runs and one held-out run of different duty cycles,
#: speeds and room phases (spec, rpm, room phase rad)
SPECS = (("on:2h,off:2h,on:2h,off:2h", 3000.0, 0.3), ("on:4h,off:4h", 5000.0, 2.0),
         ("on:1h,off:1h,on:3h,off:3h", 4000.0, 4.0))
#: planted effects: a lag of the fast proxy (the bearings) and of the slow one (the casting)
CASES = {"fast": Planted("T_fast", 1800.0, 2.5), "slow": Planted("T_slow", 900.0, 3.0),
         "none": None}


def campaign(planted: Planted | None, folder: Path, seed: int = 10,
             direction: str = "X") -> list:
    """The runs of :data:`SPECS` with ``planted`` (None: no effect), written to
    ``folder/run1.csv`` .. ``run3.csv`` (the channel along ``direction``, ``?``: unknown);
    returns the runs' columns (with ``truth_um``)."""
    runs = []
    for i, (spec, rpm, phase) in enumerate(SPECS):
        run = simulate_run(spec, rpm, planted, seed + i, room_phase=phase, zero_um=3.0 * i)
        write_drift(Path(folder) / f"run{i + 1}.csv", run, direction)
        runs.append(run)
    return runs


#: one long run whose last part is held out by time (``--holdout-time``): spec, rpm, phase,
#: the start of the held-out window (s)
LONG_RUN = ("on:2h,off:1h,on:4h,off:3h,on:1h,off:1h,on:3h,off:3h", 4000.0, 1.0, 36000.0)


def long_run(planted: Planted, folder: Path, seed: int = 20) -> dict:
    """:data:`LONG_RUN` with ``planted``, written to ``folder/long.csv`` (zero 1.5 um)."""
    spec, rpm, phase, _ = LONG_RUN
    run = simulate_run(spec, rpm, planted, seed, room_phase=phase, zero_um=1.5)
    write_drift(Path(folder) / "long.csv", run)
    return run


def true_window_mae(run: dict, planted: Planted, start_s: float, zero_um: float = 1.5) -> float:
    """MAE over the readings at ``t >= start_s`` of the TRUE model continued through the run
    (its lag over the whole logged series, its true zero): the floor of a time hold-out."""
    T = run[planted.sensor]
    pred = zero_um + planted.um_per_K * (lag_irregular(T, planted.tau_s, run["t_s"]) - T[0])
    m = run["t_s"] >= start_s
    return float(np.mean(np.abs(run["d_x_um"][m] - pred[m])))
