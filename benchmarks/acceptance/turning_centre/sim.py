#!/usr/bin/env python3
"""Simulated turning centre: many daily thermal drift runs (X and Z tool-point drift).

Written from physics, independently of volerr's drift loop:

* a lumped thermal network (heat capacities C_i in J/K, conductances G_ij in W/K) of a
  slant-bed turning centre: front / rear spindle bearings (friction heat ~ (S/S_ref)^1.3),
  spindle shaft, spindle motor (losses ~ S, coolant jacket), headstock casting, bed top and
  bed bottom (floor below), X / Z ball screws and their servo motors (heated by axis motion),
  cross slide, saddle, turret (chips), coolant tank (pump heat, room-tracking chiller),
  hydraulic unit, electrical cabinet, the air inside the guard; boundaries: the room air
  (constant +-0.2 K slow, or a day cycle of +-1.5..3 K with a door opening) and the floor;
  integrated by implicit Euler with a 5 s step (heat inputs piecewise constant); the bearings'
  friction grows with the shaft-housing temperature difference (thermally induced preload);
* X and Z tool-point drift (tool side relative to the workpiece, um) as a sum of structure
  expansions alpha * L * (T_node - 20) and a bending term of the bed's top-bottom gradient;
  the spindle nose pulled in by 3 um x (S/S_ref)^2 (elastic, no lag); several driving nodes
  (the shaft, the two screws, the bed bottom) are NOT logged directly;
* 24 logged temperatures: weighted blends of nodes (some near-duplicates, some only weakly
  related: cabinet, hydraulics, ceiling air), local drafts each sensor reads (0.04-0.12 K,
  5-40 min correlation), 0.03 K noise, 0.01 K resolution; displacement
  noise 0.4 um (0.1 um resolution); each run's displacement zero arbitrary (re-zeroed daily).

Output (--out DIR): run_NN.csv (drift format of volerr: `# channel d_X: X`, `# channel d_Z: Z`,
columns t_s,d_X_um,d_Z_um,T_*,S_rpm,run,environment), truth_NN.csv (t_s, noise-free
d_X_um, d_Z_um on the same zero), and manifest.csv (run, file, date, environment,
programme, hours, dt_s, notes).  Deterministic for a given --seed.

--hard adds what a real campaign has (each day has its own random stream, so the other days
stay as they were): T_headstock_top +0.8 K from mid-run on day 4 (re-plugged), T_spindle_motor
frozen at its value from 40 % of day 7 (drop-out, the logger holds the last value), T_bed_rear
missing from the file of the first held-out day + 1, a `highspeed` programme (1.25 S_ref) on
every varying-room day of the last third (held out in both splits), a training day of 1.2 h and
a held-out last day of 1.0 h.
--three-rooms labels the varying days alternately `day_cycle` (no door opening) and `door`: the
training days of the date split then span three environments.
"""
import argparse
import csv
import os

import numpy as np

ALPHA_UM_PER_K_MM = 11.5e-6 * 1000.0   # um per K per mm of steel / cast iron
S_REF = 4000.0                          # rpm, the spindle's rated speed
H_STEP = 5.0                            # s, integration step

NODES = ["brg_f", "brg_r", "shaft", "motor", "headstock", "hs_rear", "bed_top", "bed_bot",
         "xscrew", "xmotor", "xslide", "zscrew", "zmotor", "saddle", "turret",
         "coolant", "hydraulic", "cabinet", "enc_air"]
IDX = {n: i for i, n in enumerate(NODES)}

# heat capacities, J/K
CAP = {"brg_f": 9e3, "brg_r": 7e3, "shaft": 25e3, "motor": 40e3, "headstock": 220e3, "hs_rear": 220e3,
       "bed_top": 1500e3, "bed_bot": 2000e3, "xscrew": 6e3, "xmotor": 5e3, "xslide": 120e3,
       "zscrew": 15e3, "zmotor": 6e3, "saddle": 300e3, "turret": 60e3, "coolant": 800e3,
       "hydraulic": 200e3, "cabinet": 80e3, "enc_air": 60e3}
# conductances between nodes, W/K
LINKS = [("brg_f", "shaft", 5), ("brg_f", "headstock", 10), ("brg_f", "coolant", 3),
         ("brg_r", "shaft", 4), ("brg_r", "hs_rear", 8), ("shaft", "motor", 6),
         ("shaft", "enc_air", 2), ("motor", "hs_rear", 5), ("headstock", "hs_rear", 25), ("motor", "coolant", 20),
         ("headstock", "bed_top", 8), ("hs_rear", "bed_top", 8), ("headstock", "enc_air", 6),
         ("hs_rear", "enc_air", 6),
         ("bed_top", "bed_bot", 60), ("bed_top", "enc_air", 25), ("bed_top", "zscrew", 5),
         ("bed_top", "coolant", 10), ("bed_top", "saddle", 15),
         ("xscrew", "xslide", 3), ("xscrew", "xmotor", 1), ("xscrew", "enc_air", 0.5),
         ("xslide", "saddle", 10), ("xslide", "turret", 5), ("xslide", "enc_air", 6),
         ("zscrew", "saddle", 3), ("zscrew", "zmotor", 1), ("zscrew", "enc_air", 1),
         ("saddle", "enc_air", 10), ("turret", "coolant", 4), ("turret", "enc_air", 3),
         ("coolant", "enc_air", 8), ("hydraulic", "xslide", 1)]
# conductances to the room air (outside the guard) and to the floor, W/K
TO_ROOM = {"xmotor": 2, "zmotor": 2, "hydraulic": 8, "cabinet": 12, "enc_air": 25,
           "headstock": 1.5, "hs_rear": 1.5}
TO_FLOOR = {"bed_bot": 40}
CHILLER_G = 60.0            # W/K, coolant to a set point that tracks the room air

# tool-point drift, um, as sum_k coef_k * (T_node - 20) (slant bed, 45 deg)
DRIFT = {
    "X": {"headstock": -ALPHA_UM_PER_K_MM * 250 * 0.7 * 1.5,   # spindle axis rises, front wall
          "hs_rear": ALPHA_UM_PER_K_MM * 250 * 0.7 * 0.5,      # rear wall: the axis tilts
          "xscrew": -ALPHA_UM_PER_K_MM * 220,               # screw, fixed end at the back
          "turret": ALPHA_UM_PER_K_MM * 150 * 0.7,          # tool holder height
          "saddle": ALPHA_UM_PER_K_MM * 120 * 0.7,
          "xslide": ALPHA_UM_PER_K_MM * 60},
    "Z": {"shaft": -ALPHA_UM_PER_K_MM * 90,                 # spindle nose grows
          "brg_f": -0.6,                                    # front bearing set
          "headstock": -ALPHA_UM_PER_K_MM * 60,
          "hs_rear": -ALPHA_UM_PER_K_MM * 60,
          "zscrew": ALPHA_UM_PER_K_MM * 380,                # screw to the nut
          "bed_top": -ALPHA_UM_PER_K_MM * 330,              # screw support vs headstock
          "turret": ALPHA_UM_PER_K_MM * 60},
}
BEND_X_UM_PER_K = 3.0       # bed top-bottom gradient tilts the headstock (X)
CENTRIFUGAL_Z_UM = 3.0      # spindle nose pulled in at S_ref (elastic, instant; grows with S^2)

# logged sensors: name -> {node: weight}; weights sum to 1 ("room" = room air, "floor")
SENSORS = {
    "T_spindle_front": {"brg_f": 0.6, "headstock": 0.4},        # outer ring housing
    "T_spindle_front2": {"brg_f": 0.55, "headstock": 0.45},      # near-duplicate
    "T_spindle_rear": {"brg_r": 0.6, "hs_rear": 0.4},
    "T_spindle_motor": {"motor": 0.7, "coolant": 0.3},
    "T_headstock_top": {"headstock": 0.4, "hs_rear": 0.4, "enc_air": 0.2},
    "T_headstock_side": {"headstock": 0.9, "enc_air": 0.1},      # near-duplicate
    "T_headstock_rear": {"hs_rear": 0.7, "brg_r": 0.3},
    "T_bed_front": {"bed_top": 0.85, "enc_air": 0.15},
    "T_bed_rear": {"bed_top": 0.9, "bed_bot": 0.1},
    "T_bed_lower": {"bed_bot": 0.6, "bed_top": 0.4},
    "T_X_nut": {"xslide": 0.85, "enc_air": 0.15},               # nut housing, not the screw
    "T_X_motor": {"xmotor": 1.0},
    "T_Z_nut": {"saddle": 0.85, "zscrew": 0.15},
    "T_Z_bearing": {"bed_top": 0.85, "zscrew": 0.15},
    "T_Z_motor": {"zmotor": 1.0},
    "T_saddle": {"saddle": 0.9, "enc_air": 0.1},
    "T_turret": {"turret": 0.85, "enc_air": 0.15},
    "T_coolant": {"coolant": 1.0},
    "T_coolant_return": {"coolant": 0.7, "bed_top": 0.3},
    "T_hydraulic": {"hydraulic": 1.0},
    "T_cabinet": {"cabinet": 1.0},
    "T_enclosure": {"enc_air": 1.0},
    "T_room": {"room": 1.0},
    "T_room_ceiling": {"ceiling": 1.0},                          # weakly related
}
PUBLISHED = ["T_spindle_front", "T_headstock_top", "T_room", "T_bed_front"]


def network_matrices():
    """Return (C, L, g_room, g_floor): C dT/dt = -L T + g_room T_room + g_floor T_floor + P."""
    n = len(NODES)
    cap = np.array([CAP[k] for k in NODES])
    lap = np.zeros((n, n))
    for a, b, g in LINKS:
        i, j = IDX[a], IDX[b]
        lap[i, i] += g
        lap[j, j] += g
        lap[i, j] -= g
        lap[j, i] -= g
    g_room = np.zeros(n)
    for k, g in TO_ROOM.items():
        g_room[IDX[k]] = g
    g_floor = np.zeros(n)
    for k, g in TO_FLOOR.items():
        g_floor[IDX[k]] = g
    lap += np.diag(g_room + g_floor)
    lap[IDX["coolant"], IDX["coolant"]] += CHILLER_G
    return cap, lap, g_room, g_floor


# ---------------------------------------------------------------- spindle programmes
#: the programmes of cuts and pauses: (cut length s (lo, hi), speed / S_ref (one value, or
#: a tuple chosen per cut), x duty, z duty, pause s (lo, hi)).  duty: production, 15-25 min
#: cuts, 5-10 min loading; light: finishing at a low speed, long pauses; highspeed: above
#: S_ref, only in --hard's held-out days
CUTS = {
    "duty": ((900, 1500), (0.7, 0.75, 0.8), 0.6, 0.8, (300, 600)),
    "light": ((1800, 3000), 0.35, 0.3, 0.4, (900, 1800)),
    "highspeed": ((1200, 2400), 1.25, 0.4, 0.9, (300, 900)),
}


def _cuts(segs, rng, work, t, on_s, speed, x_duty, z_duty, off_s):
    """Append cuts and pauses (:data:`CUTS`) to ``segs`` until ``work`` s; return the time."""
    while t < work:
        on = min(rng.uniform(*on_s), work - t)
        s = rng.choice(list(speed)) if isinstance(speed, tuple) else speed
        segs.append((on, s * S_REF, 1, x_duty, z_duty))
        t += on
        off = min(rng.uniform(*off_s), max(work - t, 1.0))
        segs.append((off, 0.0, 0, 0.0, 0.0))
        t += off
    return t


def programme_segments(name, hours, rng):
    """Return a list of (duration_s, S_rpm, cutting 0/1, x_duty, z_duty) filling `hours`.

    Every run starts with 10-25 min idle (the logger on, the machine warm-up not yet
    started) and ends with a cool-down idle of about a quarter of the run (ISO 230-3 style).
    """
    total = hours * 3600.0
    segs = [(rng.uniform(600, 1500), 0.0, 0, 0.0, 0.0)]
    cool = 0.25 * total
    work = total - segs[0][0] - cool
    t = 0.0
    if name == "steps":                 # speed steps, 25 % of S_ref each, then cutting at 60 %
        speeds = [0.25, 0.5, 0.75, 1.0]
        step = min(2700.0, work / 6)
        for s in speeds:
            segs.append((step, s * S_REF, 0, 0.05, 0.05))
            t += step
        segs.append((rng.uniform(900, 1800), 0.0, 0, 0.0, 0.0))
        t += segs[-1][0]
        while t < work:
            d = min(1200.0, work - t)
            segs.append((d, 0.6 * S_REF, 1, 0.5, 0.7))
            t += d
    elif name in CUTS:
        t = _cuts(segs, rng, work, t, *CUTS[name])
    else:
        raise ValueError(name)
    segs.append((max(total - sum(s[0] for s in segs), 60.0), 0.0, 0, 0.0, 0.0))
    return segs


def inputs_at(segs, times):
    """Piecewise-constant programme values at the given times (s)."""
    ends = np.cumsum([s[0] for s in segs])
    k = np.minimum(np.searchsorted(ends, times, side="right"), len(segs) - 1)
    arr = np.array([s[1:] for s in segs])
    return arr[k]


# ---------------------------------------------------------------- room
def room_air(times, env, p, rng_unused=None):
    """Room air temperature (degC) at times (s since the run's start)."""
    base = p["base"]
    if env == "constant":
        return base + p["amp"] * np.sin(2 * np.pi * times / p["period"] + p["phase"])
    clock = p["start_h"] * 3600.0 + times
    air = base + p["amp"] * np.sin(2 * np.pi * (clock / 86400.0 - 0.375))   # peak ~15:00
    air = air - p["amp"] * np.sin(2 * np.pi * (p["start_h"] / 24.0 - 0.375))  # start at base
    dt = times - p["door_t"]
    air = air + np.where(dt >= 0, -p["door_k"] * np.exp(-np.clip(dt, 0, None) / 900.0), 0.0)
    return air


def local_air_noise(rng, t):
    """What a surface sensor reads of its surroundings: drafts and local convection.

    A first-order autoregressive process, standard deviation 0.04-0.12 K and correlation time
    5-40 min (different for every sensor and day): slow enough to look like a real signal.
    """
    sigma, tau = rng.uniform(0.04, 0.12), rng.uniform(300.0, 2400.0)
    dt = np.diff(t, prepend=t[0] - (t[1] - t[0]))
    a = np.exp(-dt / tau)
    e = rng.normal(0.0, 1.0, len(t))
    out = np.empty(len(t))
    out[0] = sigma * e[0]
    for k in range(1, len(t)):
        out[k] = a[k] * out[k - 1] + sigma * np.sqrt(1 - a[k] ** 2) * e[k]
    return out


def simulate_run(rng, env, programme, hours, dt_s, run_idx, hard_notes):
    """Simulate one daily run.  Returns (t, truth dict, sensors dict, S)."""
    cap, lap, g_room, g_floor = network_matrices()
    n = len(NODES)
    m_inv = np.linalg.inv(np.diag(cap / H_STEP) + lap)
    segs = programme_segments(programme, hours, rng)
    total = hours * 3600.0
    tt = np.arange(0.0, total + 1e-9, H_STEP)
    prog = inputs_at(segs, tt)
    if env == "constant":
        rp = {"base": rng.uniform(19.8, 20.6), "amp": rng.uniform(0.08, 0.2),
              "period": rng.uniform(5, 12) * 3600, "phase": rng.uniform(0, 2 * np.pi)}
    else:
        rp = {"base": rng.uniform(19.0, 21.0), "amp": rng.uniform(1.5, 3.0),
              "start_h": rng.uniform(6.0, 9.0), "door_t": rng.uniform(0.2, 0.8) * total,
              "door_k": rng.uniform(1.5, 3.0)}
        if env == "day_cycle":            # --three-rooms: a varying day without the door
            rp["door_k"] = 0.0
    air = room_air(tt, env, rp)
    ceiling = np.empty_like(air)          # ceiling air: lags the room by 30 min, larger swing
    ceiling[0] = air[0] + 0.6
    a = np.exp(-H_STEP / 1800.0)
    for k in range(1, len(tt)):
        ceiling[k] = a * ceiling[k - 1] + (1 - a) * (1.3 * (air[k] - air[0]) + air[0] + 0.6)
    floor = rp["base"] - 0.4 + 0.02 * np.sin(tt / 40000.0)
    # heat inputs, W
    s_rel = prog[:, 0] / S_REF
    q_brg = s_rel ** 1.3
    cut = prog[:, 1]
    power = np.zeros((len(tt), n))
    power[:, IDX["brg_f"]] = 190.0 * q_brg
    power[:, IDX["brg_r"]] = 90.0 * q_brg
    power[:, IDX["motor"]] = 120.0 * s_rel + 150.0 * cut * s_rel
    power[:, IDX["xscrew"]] = 55.0 * prog[:, 2]
    power[:, IDX["xmotor"]] = 15.0 * prog[:, 2]
    power[:, IDX["zscrew"]] = 75.0 * prog[:, 3]
    power[:, IDX["zmotor"]] = 18.0 * prog[:, 3]
    power[:, IDX["turret"]] = 25.0 * cut
    power[:, IDX["coolant"]] = 180.0 * cut + 60.0 * cut * s_rel
    power[:, IDX["hydraulic"]] = 80.0
    power[:, IDX["cabinet"]] = 50.0 + 40.0 * s_rel
    door_open = np.zeros(len(tt))
    if env not in ("constant", "day_cycle"):
        door_open = ((tt >= rp["door_t"]) & (tt < rp["door_t"] + 600)).astype(float)
    # start: near, not at, room temperature (yesterday's heat in the slow parts)
    warm = {"bed_bot": rng.uniform(0.0, 0.4), "bed_top": rng.uniform(0.0, 0.5),
            "headstock": rng.uniform(0.0, 0.6), "hs_rear": rng.uniform(0.0, 0.6), "saddle": rng.uniform(0.0, 0.4),
            "coolant": rng.uniform(-0.3, 0.3), "hydraulic": rng.uniform(0.2, 1.5),
            "cabinet": rng.uniform(0.2, 1.5)}
    temp = np.array([air[0] + warm.get(k, rng.uniform(-0.1, 0.15)) for k in NODES])
    out = np.empty((len(tt), n))
    out[0] = temp
    ci = cap / H_STEP
    enc = IDX["enc_air"]
    for k in range(1, len(tt)):
        pk = power[k].copy()              # thermally induced preload: hotter shaft, more friction
        boost = 1.0 + 0.08 * np.clip(temp[IDX["shaft"]] - temp[IDX["headstock"]], 0.0, None)
        pk[IDX["brg_f"]] *= boost
        pk[IDX["brg_r"]] *= boost
        rhs = ci * temp + g_room * air[k] + g_floor * floor[k] + pk
        rhs[IDX["coolant"]] += CHILLER_G * (air[k] + 0.3)
        if door_open[k]:                  # door open: the guard air mixes with the room
            rhs[enc] += 60.0 * (air[k] - temp[enc])
        temp = m_inv @ rhs
        out[k] = temp
    # sample
    t = np.arange(0.0, total + 1e-9, dt_s)
    ks = np.round(t / H_STEP).astype(int)
    nodes = {k: out[ks, IDX[k]] for k in NODES}
    nodes["room"] = air[ks]
    nodes["ceiling"] = ceiling[ks]
    truth = {}
    for ax, coefs in DRIFT.items():
        truth[ax] = sum(c * (nodes[k] - 20.0) for k, c in coefs.items())
    truth["X"] = truth["X"] + BEND_X_UM_PER_K * (nodes["bed_top"] - nodes["bed_bot"])
    speed_true = inputs_at(segs, t)[:, 0]
    truth["Z"] = truth["Z"] + CENTRIFUGAL_Z_UM * (speed_true / S_REF) ** 2
    sensors = {}
    for name, w in SENSORS.items():
        v = sum(c * nodes[k] for k, c in w.items())
        v = v + local_air_noise(rng, t) + rng.normal(0.0, 0.03, len(t)) + rng.uniform(-0.2, 0.2)
        sensors[name] = np.round(v, 2)
    speed = inputs_at(segs, t)[:, 0]
    return t, truth, sensors, speed


def plan_runs(rng, n_runs, hard, three_rooms=False):
    """Days, environments, programmes, lengths, sampling intervals of the campaign."""
    n_train = int(round(n_runs * 2 / 3))
    envs = []
    for half, count in ((0, n_train), (1, n_runs - n_train)):
        e = ["constant"] * (count - count * 2 // 5) + ["varying"] * (count * 2 // 5)
        rng.shuffle(e)
        envs += e
    if three_rooms:                       # varying days: alternately without and with the door
        k = 0
        for i, e in enumerate(envs):
            if e == "varying":
                envs[i] = ("day_cycle", "door")[k % 2]
                k += 1
    runs = []
    for i in range(n_runs):
        programme = ["steps", "duty", "duty", "light"][rng.integers(0, 4)]
        hours = float(rng.uniform(3.0, 8.0))
        if hard and i >= n_train and envs[i] != "constant":
            programme = "highspeed"       # a programme never run in training (either split)
        if hard and i == n_train - 3:
            hours = 1.2                   # a short training day
        if hard and i == n_runs - 1:
            hours = 1.0                   # a short held-out day
        runs.append({"run": i, "date": f"2026-03-{i + 1:02d}" if i < 31 else f"2026-04-{i - 30:02d}",
                     "environment": envs[i], "programme": programme, "hours": hours,
                     "dt_s": float(rng.choice([30.0, 45.0, 60.0])), "notes": ""})
    return runs


def write_run(path, t, d, sensors, speed, run, env):
    cols = ["t_s", "d_X_um", "d_Z_um"] + list(sensors) + ["S_rpm", "run", "environment"]
    with open(path, "w", newline="") as f:
        f.write("# simulated turning centre (sim.py), tool-point drift, one daily run\n")
        f.write("# channel d_X: X\n# channel d_Z: Z\n")
        w = csv.writer(f)
        w.writerow(cols)
        for k in range(len(t)):
            row = [f"{t[k]:.0f}", f"{d['X'][k]:.1f}", f"{d['Z'][k]:.1f}"]
            row += [f"{sensors[s][k]:.2f}" for s in sensors]
            row += [f"{speed[k]:.0f}", f"day{run:02d}", env]
            w.writerow(row)


def hard_faults(sensors, t, i, n_train, r):
    """Sensor faults of a real campaign (--hard), in place."""
    if i == 4:                    # a thermocouple re-plugged: +0.8 K from mid-run (training)
        k = len(t) // 2
        sensors["T_headstock_top"][k:] += 0.8
        r["notes"] += "T_headstock_top +0.8 K from mid-run; "
    if i == 7:                    # a channel drops out, the logger holds its last value (training)
        k = int(0.4 * len(t))
        sensors["T_spindle_motor"][k:] = sensors["T_spindle_motor"][k]
        r["notes"] += "T_spindle_motor frozen from 40 % of the run; "
    if i == n_train + 1:          # a sensor missing from this (held-out) day's file
        del sensors["T_bed_rear"]
        r["notes"] += "T_bed_rear missing; "


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--hard", action="store_true", help="sensor faults, an unseen programme, a short run")
    ap.add_argument("--noise-um", type=float, default=0.4)
    ap.add_argument("--three-rooms", action="store_true",
                    help="label varying days `day_cycle` (no door) or `door`: three environments")
    a = ap.parse_args(argv)
    rng = np.random.default_rng(a.seed)
    os.makedirs(a.out, exist_ok=True)
    runs = plan_runs(rng, a.runs, a.hard, a.three_rooms)
    n_train = int(round(a.runs * 2 / 3))
    for r in runs:
        i = r["run"]
        rng = np.random.default_rng([a.seed, i])   # one stream a day: --hard leaves other days as they were
        t, truth, sensors, speed = simulate_run(rng, r["environment"], r["programme"],
                                                r["hours"], r["dt_s"], i, None)
        if a.hard:
            hard_faults(sensors, t, i, n_train, r)
        zero = {ax: rng.uniform(-60, 60) for ax in ("X", "Z")}
        truth_z = {ax: truth[ax] - truth[ax][0] + zero[ax] for ax in ("X", "Z")}
        meas = {ax: np.round(truth_z[ax] + rng.normal(0, a.noise_um, len(t)), 1) for ax in ("X", "Z")}
        fname = f"run_{i:02d}.csv"
        write_run(os.path.join(a.out, fname), t, meas, sensors, speed, i, r["environment"])
        with open(os.path.join(a.out, f"truth_{i:02d}.csv"), "w", newline="") as f:
            w = csv.writer(f)
            w.writerow(["t_s", "d_X_um", "d_Z_um"])
            for k in range(len(t)):
                w.writerow([f"{t[k]:.0f}", f"{truth_z['X'][k]:.4f}", f"{truth_z['Z'][k]:.4f}"])
        r["file"] = fname
        r["n"] = len(t)
        r["range_X_um"] = float(np.ptp(truth["X"]))
        r["range_Z_um"] = float(np.ptp(truth["Z"]))
    with open(os.path.join(a.out, "manifest.csv"), "w", newline="") as f:
        keys = ["run", "file", "date", "environment", "programme", "hours", "dt_s", "n",
                "range_X_um", "range_Z_um", "notes"]
        w = csv.DictWriter(f, fieldnames=keys)
        w.writeheader()
        for r in runs:
            w.writerow({k: (f"{r[k]:.2f}" if isinstance(r[k], float) else r[k]) for k in keys})
    return runs


if __name__ == "__main__":
    main()
