"""Fanuc pitch error compensation: parameters 3620-3625 and the compensation data, as a
parameter tape.

Sources: FANUC Series 0i-PB Parameter Manual (B-63980EN/01, parameters 3620-3625 and the
example of compensation values per section, rotary axes), FANUC Series 16i/18i-MA/TA
Technical Report "Bidirectional pitch error compensation" (A-77810E: 3620 number of the
compensation point of the reference position, 3621 / 3622 the most distant points on the -
/ + side, 3623 magnification, 3624 point interval, 3625 travel per rotation of a rotary
axis); cnc.wiki "Fanuc pitch error compensation" (at most 128 points per axis, data entered
incrementally).

What is written (one tape; ``Ann`` the axis number in the layout's order, values in detection
units: 1 um for linear axes, 0.001 deg for rotary axes, IS-B)::

    %
    (volerr export: layout DMU50, pitch error compensation)
    N3620A1P20A2P64A3P107
    N3621A1P0A2P44A3P87
    N3622A1P40A2P84A3P127
    N3623A1P1A2P1A3P1
    N3624A1P12500A2P11000A3P10000
    N10000P0
    N10001P-2
    ...
    %

* Compensation points are ``interval`` apart from the reference position (the machine zero,
  0 mm: point 3620), numbered along the axis; point numbers 0 .. 1023 are shared by all axes
  (``N10000 + number``), at most :data:`MAX_POINTS` per axis.
* The data are incremental: the value at point ``k`` is the change of the compensation
  amount from point ``k - 1`` to ``k`` (the section between them), in detection units times
  the magnification 3623, each within +-:data:`MAX_STEP`; the amount at the reference position
  is 0 (the compensation is relative to it).  The amounts are compensations, the negated
  errors: volerr writes ``-(E(p_k) - E(p_ref))`` rounded so that their sums stay within half a
  detection unit of it.
* A rotary axis (endless, or a table over the turn): the points cover one turn from the
  reference (3625 = 360000), the sum over the turn is 0; the reference point's value is that
  of the last.

So a Fanuc table leaves the error at the reference position and everything but the
positioning errors.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ..errors import InputError, require
from . import comp_tables as ct

MAX_POINTS = 128
TOTAL_POINTS = 1024
MAX_STEP = 7
#: detection unit (IS-B): mm for linear axes, deg for rotary axes
UNIT = 1e-3


def build(funcs, max_points: int = MAX_POINTS) -> list:
    """Positioning tables on the Fanuc grid: points ``interval`` apart from 0 (the reference
    position), covering the error table's range; values are errors relative to the reference
    (rounded to detection units cumulatively)."""
    require(max_points <= MAX_POINTS, f"--points: Fanuc holds at most {MAX_POINTS} per axis")
    model = funcs.model
    out, used = [], 0
    for a in model.axes:
        name = f"E{a}{a}"
        if not ct.has_positioning(funcs, a):
            continue
        t = funcs.tables[a]
        lo, hi = float(t.positions[0]), float(t.positions[-1])
        mod = ct.endless(model, a)
        if mod:
            lo, hi = 0.0, 360.0
        finest = float(np.min(np.diff(t.positions)))
        n_want = int(math.ceil((hi - lo) / finest - 1e-9))
        interval_units = max(1, int(math.ceil((hi - lo) / min(n_want, max_points - 1) / UNIT)))
        interval = interval_units * UNIT
        if mod:
            interval_units = _divisor_interval(interval_units)
            interval = interval_units * UNIT
            k0, k1 = 0, int(round(360.0 / interval))
        else:
            k0, k1 = int(math.floor(lo / interval + 1e-9)), int(math.ceil(hi / interval - 1e-9))
            k0, k1 = min(k0, 0), max(k1, 0)         # the reference (0) is a point
        n = k1 - k0 + 1
        require(n <= max_points, f"axis {a}: {n} compensation points at {interval:g} apart "
                                 f"exceed {max_points} (the range includes the machine zero)")
        pos = np.arange(k0, k1 + 1) * interval
        lo_t, hi_t = (0.0, 360.0) if mod else (float(t.positions[0]), float(t.positions[-1]))
        e = ct.error_values(funcs, name, a, np.clip(np.mod(pos, 360.0) if mod else pos,
                                                    lo_t, hi_t))
        ref = int(np.argmin(np.abs(pos)))
        units, mag = _amounts((e - e[ref]) / UNIT, ref)
        require(mag <= 100, f"axis {a}: an error step of more than {7 * 100} detection "
                            "units between points needs a magnification above 100")
        out.append(ct.CompTable(name, a, a, float(pos[0]), interval, units * UNIT, mod,
                                scale=mag))
        used += n
    require(used <= TOTAL_POINTS, f"{used} compensation points in all, Fanuc holds "
                                  f"{TOTAL_POINTS}")
    return out


def _amounts(ideal: np.ndarray, ref: int) -> tuple:
    """Amounts (detection units) nearest the ideal ones, 0 at ``ref``, in multiples of the
    magnification whose steps between neighbours stay within +-MAX_STEP of it; outwards from
    the reference, each rounded and its step clipped -> (amounts, magnification)."""
    steps = np.abs(np.diff(ideal))
    mag = max(1, int(math.ceil(steps.max() / MAX_STEP))) if len(steps) else 1
    out = np.zeros(len(ideal))
    lim = MAX_STEP * mag
    for order in (range(ref + 1, len(ideal)), range(ref - 1, -1, -1)):
        for k in order:
            prev = out[k - 1] if k > ref else out[k + 1]
            want = np.round(ideal[k] / mag) * mag
            out[k] = min(max(want, prev - lim), prev + lim)
    return out, mag


def _divisor_interval(units: int) -> int:
    """The smallest interval of at least ``units`` that divides the turn (360000 units)."""
    while 360000 % units:
        units += 1
    return units


def write(model_name: str, tables: list, axes) -> str:
    """The parameter tape of positioning tables from :func:`build`."""
    index = {a: i + 1 for i, a in enumerate(axes)}
    params = {p: [] for p in (3620, 3621, 3622, 3623, 3624, 3625)}
    data = []
    first = 0
    for t in tables:
        n = len(t.values)
        ref = first + int(round(-t.start / t.step))
        ai = index[t.input]
        mag = t.scale
        inc = np.diff(np.round(-t.values / UNIT)).astype(int)   # compensation: -error
        require(np.all(inc % mag == 0) and np.all(np.abs(inc) <= MAX_STEP * mag),
                f"axis {t.input}: the values are not steps of at most {MAX_STEP} x {mag} "
                "detection units")
        vals = np.concatenate([[0], inc])
        if t.modulo:
            vals[0] = vals[-1]
        params[3620].append((ai, ref))
        params[3621].append((ai, first))
        params[3622].append((ai, first + n - 1))
        params[3623].append((ai, mag))
        params[3624].append((ai, int(round(t.step / UNIT))))
        if t.modulo:
            params[3625].append((ai, 360000))
        data += [(first + k, int(v // mag)) for k, v in enumerate(vals)]
        first += n
    out = ["%", f"(VOLERR EXPORT: LAYOUT {model_name.upper()}, PITCH ERROR COMPENSATION)"]
    for p, entries in params.items():
        if entries:
            out.append(f"N{p}" + "".join(f"A{a}P{v}" for a, v in entries))
    out += [f"N{10000 + k}P{v}" for k, v in data]
    out.append("%")
    return "\n".join(out) + "\n"


def read(text: str, axes, where: str = "Fanuc tape") -> list:
    params, data = {}, {}
    for n, raw in enumerate(text.splitlines(), start=1):
        line = re.sub(r"\([^)]*\)", "", raw).replace(" ", "").strip().rstrip(";")
        if not line or line == "%":
            continue
        m = re.fullmatch(r"N(\d+)((?:A\d+P-?\d+)+|P-?\d+)", line, re.IGNORECASE)
        if m is None:
            raise InputError(f"{where} line {n}: cannot interpret {raw.strip()[:40]!r}")
        num = int(m.group(1))
        if num >= 10000:
            require(num < 10000 + TOTAL_POINTS, f"{where} line {n}: point {num - 10000} "
                                                f"beyond {TOTAL_POINTS - 1}")
            data[num - 10000] = int(m.group(2)[1:])
            continue
        for a, v in re.findall(r"A(\d+)P(-?\d+)", m.group(2), re.IGNORECASE):
            k = int(a)
            require(1 <= k <= len(axes), f"{where} line {n}: axis A{k} (the layout has "
                                         f"{len(axes)} axes)")
            params.setdefault(num, {})[axes[k - 1]] = int(v)
    for p in (3620, 3621, 3622, 3623, 3624):
        require(p in params, f"{where}: parameter {p} missing")
    out = []
    for a in params[3620]:
        ref, lo, hi = params[3620][a], params[3621][a], params[3622][a]
        mag, step = params[3623].get(a, 1), params[3624][a]
        require(lo <= ref <= hi, f"{where}: axis {a}: the reference point {ref} is not "
                                 f"within {lo} .. {hi}")
        require(step > 0 and 1 <= mag <= 100, f"{where}: axis {a}: interval and "
                                              "magnification must be positive")
        vals = []
        for k in range(lo, hi + 1):
            require(k in data, f"{where}: axis {a}: compensation point {k} missing")
            require(abs(data[k]) <= MAX_STEP, f"{where}: point {k}: {data[k]} is beyond "
                                              f"+-{MAX_STEP}")
            vals.append(data[k] * mag)
        mod = a in params.get(3625, {})
        vals = np.array(vals, dtype=float)
        vals[0] = 0.0
        amount = np.cumsum(vals)
        amount -= amount[ref - lo]                   # 0 at the reference position
        out.append(ct.CompTable(f"E{a}{a}", a, a, (lo - ref) * step * UNIT, step * UNIT,
                                -amount * UNIT, mod, scale=mag))
    return out
