"""Logged temperatures of a virtual machine: sensors, duty cycles and a lagged thermal effect
(for :func:`volerr.loop.simulate.simulate`, ``volerr simulate --sensors --duty``).

A machine's heat sources switch with its duty cycle: the drives (axis motors, spindle,
hydraulics) and the coolant pump.  Each logged sensor reads the room temperature (a slow
daily swing, its own share of it) plus its sources' heat through its own first-order lag;
the readings carry 0.01 K noise and 0.01 K resolution; the machine stood cold (every source
off) before the campaign.  A *lagged thermal effect* lets a
component error follow one sensor through a further first-order lag (heat flowing from a
motor into a ballscrew): ``EXX += k X (lag(T_motorX, tau) - 20)``.

Everything here is computed on a fine uniform time grid (``FINE_S``) with its own
discretisation (trapezoidal input, ``scipy.signal.lfilter``), not with the loop's lag of
sampled readings (:mod:`volerr.machine.lags`): a round trip simulate -> loop checks that.

Duty cycle ``SPEC``: ``on:6h,off:4h`` (the drives; the coolant pump follows them) or
``drives=on:2h,off:2h,on:6h;coolant=on:10h``; durations in ``h``, ``min`` or ``s``; the
last state holds to the end of the campaign.  Units: s, K, degC.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from ..errors import require

FINE_S = 2.0            # time step of the fine grid, s
SENSOR_NOISE_K = 0.01
ROOM_C = 20.0

#: sensor -> (heat source, rise at steady state K, time constant min, share of the room swing)
CATALOGUE = {
    "T_spindle": ("drives", 5.0, 12.0, 0.6),
    "T_motorX": ("drives", 7.0, 8.0, 0.5),
    "T_column": ("drives", 1.5, 90.0, 0.9),
    "T_bed": ("drives", 0.6, 180.0, 1.0),
    "T_coolant": ("coolant", 3.0, 35.0, 0.3),
    "T_air1": (None, 0.0, 1.0, 1.0),
    "T_air2": (None, 0.0, 1.0, 1.2),
    "T_hydraulics": ("drives", 4.0, 25.0, 0.7),
    "T_motorY": ("drives", 6.0, 10.0, 0.5),
    "T_motorZ": ("drives", 5.5, 14.0, 0.5),
    "T_table": ("drives", 0.8, 120.0, 0.95),
    "T_cabinet": ("drives", 2.5, 45.0, 0.4),
}
SOURCES = ("drives", "coolant")
_UNIT_S = {"h": 3600.0, "min": 60.0, "s": 1.0}


def sensor_names(spec) -> list:
    """``8`` -> the first eight sensors of :data:`CATALOGUE`; ``T_spindle,T_motorX`` -> those."""
    if isinstance(spec, int) or str(spec).strip().isdigit():
        n = int(spec)
        require(1 <= n <= len(CATALOGUE), f"--sensors: a number from 1 to {len(CATALOGUE)}")
        return list(CATALOGUE)[:n]
    names = [s.strip() for s in str(spec).split(",") if s.strip()]
    bad = [s for s in names if s not in CATALOGUE]
    require(names and not bad, f"--sensors: unknown sensor {bad[0] if bad else spec!r}; "
                               f"sensors are {' '.join(CATALOGUE)}")
    return names


def parse_duty(spec: str | None) -> dict:
    """Duty cycle text -> {source: [(state 0/1, seconds), ...]} (see the module docstring)."""
    spec = spec or "on:6h,off:4h"
    out = {}
    for part in filter(None, (p.strip() for p in spec.split(";"))):
        source, eq, segs = part.rpartition("=")
        source = source.strip() if eq else "drives"
        require(source in SOURCES, f"--duty {spec!r}: unknown source {source!r} "
                                   f"(sources: {' '.join(SOURCES)})")
        out[source] = [_segment(s, spec) for s in segs.split(",") if s.strip()]
        require(out[source], f"--duty {spec!r}: no segments for {source}")
    out.setdefault("drives", [(1, 6 * 3600.0), (0, 4 * 3600.0)])
    out.setdefault("coolant", out["drives"])
    return out


def _segment(text: str, spec: str) -> tuple:
    m = re.fullmatch(r"\s*(on|off)\s*:\s*([0-9.]+)\s*(h|min|s)\s*", text)
    require(m is not None, f"--duty {spec!r}: write segments as on:6h,off:30min,on:90s")
    seconds = float(m.group(2)) * _UNIT_S[m.group(3)]
    require(0 < seconds <= 1e7, f"--duty {spec!r}: a segment must last more than 0 s")
    return (1 if m.group(1) == "on" else 0, seconds)


def _state(segments, tf) -> np.ndarray:
    """0/1 state of a source on the fine grid (the last segment's state holds)."""
    ends = np.cumsum([s for _, s in segments])
    states = np.array([on for on, _ in segments] + [segments[-1][0]], float)
    return states[np.searchsorted(ends, tf, side="right")]


def first_order(u, tau_s: float, dt: float = FINE_S, start: float | None = None) -> np.ndarray:
    """``tau dy/dt + y = u`` on a uniform grid (trapezoidal input), in equilibrium with
    ``start`` (default ``u[0]``) before the first sample."""
    from scipy.signal import lfilter, lfilter_zi

    a = np.exp(-dt / tau_s)
    u = np.asarray(u, dtype=float)
    b, den = [(1 - a) / 2, (1 - a) / 2], [1.0, -a]
    u0 = u[0] if start is None else start
    y, _ = lfilter(b, den, np.concatenate([[u0], u]), zi=lfilter_zi(b, den) * u0)
    return y[1:]


@dataclass
class SensorLog:
    """Temperatures on the fine grid ``t`` (s): ``fine`` {sensor: (M,) degC}."""

    t: np.ndarray
    fine: dict
    duty: dict

    def at(self, t_s, rng) -> dict:
        """The logged readings at the times ``t_s``: noise and 0.01 K resolution."""
        out = {}
        for name, v in self.fine.items():
            x = np.interp(t_s, self.t, v) + rng.normal(0.0, SENSOR_NOISE_K, len(t_s))
            out[name] = np.round(x, 2)
        return out

    def lagged(self, sensor: str, tau_s: float, t_s) -> np.ndarray:
        """The true (noise-free) reading of ``sensor`` through a lag ``tau_s``, at ``t_s``."""
        require(sensor in self.fine, f"thermal_lag: sensor {sensor!r} is not logged (sensors: "
                                     f"{' '.join(self.fine)})")
        return np.interp(t_s, self.t, first_order(self.fine[sensor], tau_s))


def log_sensors(names, duty_spec, duration_s: float, rng) -> SensorLog:
    """Simulate the sensors ``names`` over ``duration_s`` with the duty cycle ``duty_spec``."""
    duty = parse_duty(duty_spec)
    tf = np.arange(0.0, duration_s + FINE_S, FINE_S)
    sources = {s: _state(duty[s], tf) for s in SOURCES}
    phase = rng.uniform(0, 2 * np.pi)
    room = ROOM_C + 0.6 * np.sin(2 * np.pi * tf / 86400.0 + phase) \
        + 0.15 * np.sin(2 * np.pi * tf / 5400.0 + rng.uniform(0, 2 * np.pi))
    fine = {}
    for name in names:
        source, rise, tau_min, share = CATALOGUE[name]
        v = ROOM_C + share * (room - ROOM_C) + rng.normal(0, 0.05)
        if source is not None:
            # the machine stood cold before the campaign: every source off
            v = v + rise * first_order(sources[source], 60.0 * tau_min, start=0.0)
        fine[name] = v
    return SensorLog(tf, fine, duty)


def thermal_lag(e: dict, log: SensorLog, positions, values, t_s, along) -> None:
    """Apply ``{"kind": "thermal_lag", "sensor", "tau_min" | "tau_s", "axis", "ppm_per_K"}``
    (the axis' positioning error grows ppm_per_K * position * (lagged reading - 20)) or with
    ``"component"`` and ``"um_per_K"`` (that error, an offset: um or urad per K)."""
    tau = float(e.get("tau_s", 60.0 * float(e.get("tau_min", 40.0))))
    require(tau > 0, "thermal_lag: tau must be positive")
    x = log.lagged(e.get("sensor", "T_motorX"), tau, t_s) - ROOM_C
    if "component" in e:
        comp = e["component"]
        require(comp in values, f"thermal_lag: {comp!r} is not an error parameter")
        scale = 1e-3 if comp[1] in "XYZ" else 1e-6
        values[comp] = values[comp] + float(e.get("um_per_K", 1.0)) * scale * x
        return
    a = e.get("axis", "X")
    require(a in along, f"thermal_lag: axis {a!r} is not a linear axis")
    values[along[a]] = values[along[a]] + float(e.get("ppm_per_K", 2.0)) * 1e-6 \
        * positions[a] * x
