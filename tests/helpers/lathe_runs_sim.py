"""A simulated turning centre's many daily drift runs (issue 44 items 2 and 3), written from
the physics, numpy only, none of volerr's code (its own first-order filter, its own
regression).

The machine
-----------
* **Spindle heat**: ``q = (S / S_REF) ** HEAT_P`` (bearing and motor losses grow with the
  speed to a power between 1 and 2; Bossmanns & Tu 1999).
* **A thermal network**, every node a first-order lag of what drives it (the room air and the
  heat), each started near but not at the room's temperature (the machine stands overnight;
  the previous day's heat not quite gone: an offset per run relaxing with the node's room
  time constant):

  - ``nose`` (NOT measured): the spindle nose, ``K_NOSE lag(q, TAU_NOSE)``;
  - ``bearing``: ``room + K_BEARING lag(q, TAU_BEARING)``;
  - ``headstock``: ``lag(room, TAU_HS_ROOM) + K_HS lag(q, TAU_HS)``;
  - ``bed``: ``lag(room, TAU_BED_ROOM) + K_BED lag(q, TAU_BED)`` (the room reaches the bed
    through hours);
  - the coolant (the chiller's cycle plus a little heat), the electrics cabinet (wandering on
    its own) and a spare sensor: no part of the drift.
* **Tool-point drift** (um, the sum of structure expansions)::

      X = A_X_NOSE nose + A_X_HS (headstock - headstock_0) + A_X_BED (bed - bed_0)
      Z = A_Z_NOSE nose + A_Z_HS (headstock - headstock_0) + A_Z_BED (bed - bed_0)

  read with ``D_NOISE_UM`` noise and an arbitrary zero per run (re-zeroed each day).
* **Logged temperatures** (``T_NOISE_K`` noise): the room (two sensors, near duplicates), the
  bearing (front; the rear one a damped near duplicate), the headstock (two places), the bed
  (two places), the motor, the coolant, the cabinet, a spare.
* **Rooms** (the ``environment`` column): ``constant`` (air conditioning: +-0.15 K of slow
  swing), ``daily`` (the room following the day: +-ROOM_DAY_K), ``door`` (a hall door opened in
  the run's second hour: the room ROOM_DOOR_K cooler within half an hour).
* **Programmes** (spindle speed steps, :data:`PROGRAMMES`).

The floor (:func:`floor_prediction`): the TRUE network (the nodes as lags of the logged speed
and room air, every lag started at rest: the nodes' start offsets are not known from the logs)
refitted by least squares on the training runs (a zero per run), a held-out run predicted from
its first reading plus the fitted terms: what a model that knows the physics can do from these
logs.  The static regression (:func:`static_prediction`): every temperature's change since the
run's first reading, fitted the same way (the shop's model).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

S_REF, HEAT_P = 10000.0, 1.3
SAMPLE_S = 60.0
K_NOSE, TAU_NOSE = 1.0, 1200.0
K_BEARING, TAU_BEARING = 12.0, 600.0
K_HS, TAU_HS, TAU_HS_ROOM = 5.0, 5400.0, 7200.0
K_BED, TAU_BED, TAU_BED_ROOM = 1.0, 14400.0, 10800.0
A_X_NOSE, A_X_HS, A_X_BED = 4.0, 3.0, 2.5       # um, um/K, um/K
A_Z_NOSE, A_Z_HS, A_Z_BED = 12.0, 1.5, -4.0
ROOM_MEAN, ROOM_CONST_K, ROOM_DAY_K, ROOM_DOOR_K = 20.0, 0.15, 2.0, 1.5
DAY_S = 86400.0
T_NOISE_K, D_NOISE_UM = 0.03, 0.4
SENSORS = ("T_room", "T_room_2", "T_bearing", "T_bearing_rear", "T_headstock",
           "T_headstock_2", "T_bed", "T_bed_2", "T_motor", "T_coolant", "T_cabinet", "T_spare")
CHANNELS = ("X", "Z")

#: (start h, rpm) steps, and the run's length h
PROGRAMMES = {
    "A": (((0, 0), (0.1, 4000), (1.5, 8000), (3.5, 0)), 5.0),
    "B": (((0, 0), (0.1, 9000), (1.2, 0), (2.2, 6000), (3.8, 2000)), 5.0),
    "C": (((0, 0), (0.1, 10000), (2.5, 3000), (4.0, 0)), 5.0),
}


def lag(x, tau_s: float, h: float, y0=None) -> np.ndarray:
    """First-order lag of ``x`` sampled every ``h`` s, the input linear between samples,
    starting at ``y0`` (default ``x[0]``: at rest)."""
    x = np.asarray(x, float)
    a = np.exp(-h / tau_s)
    y = np.empty(len(x))
    y[0] = x[0] if y0 is None else y0
    for k in range(1, len(x)):
        s = (x[k] - x[k - 1]) / h
        y[k] = x[k] - s * tau_s + (y[k - 1] - x[k - 1] + s * tau_s) * a
    return y


def room(env: str, t: np.ndarray, hour: float, rng) -> np.ndarray:
    """The room air (degC) over the run's time ``t`` (s), the run starting at ``hour``."""
    if env == "constant":
        return ROOM_MEAN + ROOM_CONST_K * np.sin(2 * np.pi * t / 30000.0 + rng.uniform(0, 6.3))
    day = ROOM_MEAN + ROOM_DAY_K * np.sin(2 * np.pi * (t + hour * 3600.0) / DAY_S - np.pi / 2)
    if env == "daily":
        return day
    start = 3600.0 * rng.uniform(1.0, 2.0)
    return day - ROOM_DOOR_K * (1 - np.exp(-np.clip(t - start, 0, None) / 1800.0)) * (t > start)


def simulate_run(programme: str, env: str, hour: float, rng) -> dict:
    """One run: {"t_s", "S_rpm", "d_X_um", "d_Z_um", sensors..., "truth_X", "truth_Z"}."""
    steps, run_h = PROGRAMMES[programme]
    h = SAMPLE_S
    t = np.arange(0.0, run_h * 3600.0 + h / 2, h)
    S = np.zeros(len(t))
    for start_h, rpm in steps:
        S[t >= start_h * 3600.0] = rpm
    q = (S / S_REF) ** HEAT_P
    air = room(env, t, hour, rng)
    nose = K_NOSE * lag(q, TAU_NOSE, h, 0.0)
    hs = (lag(air, TAU_HS_ROOM, h, air[0] + rng.uniform(-0.3, 0.3))
          + K_HS * lag(q, TAU_HS, h, rng.uniform(0.0, 0.05)))
    bed = (lag(air, TAU_BED_ROOM, h, air[0] + rng.uniform(-0.3, 0.3))
           + K_BED * lag(q, TAU_BED, h, 0.0))
    bearing = air + K_BEARING * lag(q, TAU_BEARING, h, 0.0)
    wander = lag(rng.normal(size=len(t)), 5000.0, h, 0.0)
    true = {"T_room": air, "T_room_2": air + 0.1,
            "T_bearing": bearing, "T_bearing_rear": lag(bearing, 900.0, h, bearing[0]),
            "T_headstock": 0.6 * hs + 0.4 * lag(air, 1800.0, h),
            "T_headstock_2": 0.5 * hs + 0.5 * air,
            "T_bed": 0.7 * bed + 0.3 * lag(air, 2400.0, h),
            "T_bed_2": 0.5 * bed + 0.5 * air,
            "T_motor": air + 20.0 * lag(q, 300.0, h, 0.0),
            "T_coolant": 22.0 + 0.3 * np.sin(2 * np.pi * t / 1800.0 + rng.uniform(0, 6.3))
            + 1.0 * lag(q, 900.0, h, 0.0),
            "T_cabinet": 27.0 + 0.4 * wander / (wander.std() + 1e-12),
            "T_spare": np.full(len(t), 24.0)}
    out = {"t_s": t, "S_rpm": S}
    for ch, (a_n, a_h, a_b) in (("X", (A_X_NOSE, A_X_HS, A_X_BED)),
                                ("Z", (A_Z_NOSE, A_Z_HS, A_Z_BED))):
        truth = a_n * nose + a_h * (hs - hs[0]) + a_b * (bed - bed[0])
        out[f"truth_{ch}"] = truth
        out[f"d_{ch}_um"] = rng.uniform(-20, 20) + truth + rng.normal(0, D_NOISE_UM, len(t))
    for k in SENSORS:
        out[k] = true[k] + rng.normal(0.0, T_NOISE_K, len(t))
    return out


def campaign(plan, seed: int) -> list:
    """Runs of ``plan`` [(name, programme, environment, start hour)]: [(name, env, run)]."""
    rng = np.random.default_rng(seed)
    return [(name, env, simulate_run(prog, env, hour, rng)) for name, prog, env, hour in plan]


def write_run(path: Path, run: dict, env: str) -> Path:
    """One drift file (``volerr formats drift``): X and Z channels, an ``environment``."""
    cols = ["t_s", "S_rpm", "d_X_um", "d_Z_um", *SENSORS]
    lines = ["# simulated turning centre (tests/helpers/lathe_runs_sim.py)",
             "# channel d_X: X", "# channel d_Z: Z", ",".join(cols + ["environment"])]
    data = np.column_stack([run[c] for c in cols])
    lines += [",".join(f"{v:.5f}" for v in row) + f",{env}" for row in data]
    Path(path).write_text("\n".join(lines) + "\n", encoding="utf-8")
    return Path(path)


# ---- the references ------------------------------------------------------------------------
def _true_columns(run: dict) -> np.ndarray:
    """The network's nodes from the LOGGED speed and room air, every lag started at rest."""
    q = (run["S_rpm"] / S_REF) ** HEAT_P
    air = run["T_room"]
    cols = [lag(q, tau, SAMPLE_S, q[0]) for tau in (TAU_NOSE, TAU_HS, TAU_BED)]
    cols += [lag(air, tau, SAMPLE_S) for tau in (TAU_HS_ROOM, TAU_BED_ROOM)]
    return np.column_stack([c - c[0] for c in cols])


def _static_columns(run: dict) -> np.ndarray:
    return np.column_stack([run[k] - run[k][0] for k in SENSORS if np.ptp(run[k]) > 0])


def _refit_predict(train: list, test: dict, columns, ch: str) -> np.ndarray:
    """Least squares on the training runs (a zero per run); the held-out run predicted from
    its first reading plus the fitted terms (the columns are zero at its start)."""
    blocks = [columns(r) for r in train]
    n = [len(b) for b in blocks]
    Z = (np.repeat(np.arange(len(train)), n)[:, None] == np.arange(len(train))).astype(float)
    X = np.column_stack([Z, np.vstack(blocks)])
    y = np.concatenate([r[f"d_{ch}_um"] for r in train])
    coef, *_ = np.linalg.lstsq(X, y, rcond=None)
    return test[f"d_{ch}_um"][0] + columns(test) @ coef[len(train):]


def floor_prediction(train: list, test: dict, ch: str) -> np.ndarray:
    """The true network refitted (the floor)."""
    return _refit_predict(train, test, _true_columns, ch)


def static_prediction(train: list, test: dict, ch: str) -> np.ndarray:
    """The static regression on every temperature (the shop's model)."""
    return _refit_predict(train, test, _static_columns, ch)
