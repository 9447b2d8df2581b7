"""Honest splits of time series: which readings are held out (the split rule of
``volerr formats loop-lags``).

* ``--holdout-time A:B``: the readings with ``A <= t < B`` (``t`` the time of the run's file,
  units ``s``, ``min``, ``h``; an open end: ``100035s:``, ``:2h``);
* ``--holdout-files FILE...``: every run of those files;
* neither: with two runs or more the last run (whole) is held out; with one run the last
  ``DEFAULT_TEST`` of its time (one contiguous stretch).  Never readings drawn at random:
  readings seconds apart are almost equal, a model judged on them is judged on its neighbours.

The same rule splits the points of the 3-D loop when its file has a time column
(:func:`stretch_split`).
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ...errors import require
from .series import DriftSeries

DEFAULT_TEST = 0.25          # share of a single run's time held out at its end
_UNITS = {"s": 1.0, "min": 60.0, "h": 3600.0}
_END = re.compile(r"^\s*([-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?)\s*(s|min|h)\s*$")


def parse_window(text: str) -> tuple[float, float]:
    """``"A:B"`` -> (A, B) in seconds (an open end -inf / +inf); InputError otherwise."""
    head, sep, tail = str(text).partition(":")
    require(sep == ":" and (head.strip() or tail.strip()),
            f"--holdout-time {text!r}: give A:B with units s, min or h (e.g. 100035s:, "
            f"2h:4h)")
    out = []
    for part, inf in ((head, -np.inf), (tail, np.inf)):
        if not part.strip():
            out.append(inf)
            continue
        m = _END.match(part)
        require(m is not None, f"--holdout-time {text!r}: {part.strip()!r} is not a time "
                               f"with a unit s, min or h")
        out.append(float(m.group(1)) * _UNITS[m.group(2)])
    require(out[0] < out[1], f"--holdout-time {text!r}: the window is empty (A >= B)")
    return out[0], out[1]


def held_out(s: DriftSeries, window=None, files=()) -> tuple[np.ndarray, str]:
    """The test mask (N,) and a sentence saying how it was drawn."""
    test = np.zeros(len(s.t_s), bool)
    said = []
    if window is not None:
        a, b = parse_window(window)
        not_from_end(s.t_s, window, a, b)
        test |= (s.t_s >= a) & (s.t_s < b)
        said.append(f"readings with {window} held out")
    if files:
        names = {Path(f).name for f in files}
        known = {Path(f).name for f, _ in s.runs}
        bad = sorted(names - known)
        require(not bad, f"--holdout-files: {bad[0] if bad else ''} is not one of the drift "
                         f"files given ({', '.join(sorted(known))})")
        for r, (f, _) in enumerate(s.runs):
            if Path(f).name in names:
                test |= s.run == r
        said.append(f"runs of {', '.join(sorted(names))} held out")
    if window is None and not files:
        test, text = default_split(s)
        said.append(text)
    _enough(s, test, window, files)
    return test, "; ".join(said)


def not_from_end(t, window, a: float, b: float) -> None:
    """One line where a bound of ``--holdout-time`` (``a``, ``b`` s) is negative and no
    reading's time ``t`` (s) is: the likely mistake is a time counted back from the end
    (``-1h:`` for the last hour), which the rule (``A <= t < B``, ``t`` the file's time)
    would read as a time before the run's start and silently hold out another stretch."""
    lo, hi = float(np.min(t)), float(np.max(t))
    neg = [v for v in (a, b) if np.isfinite(v) and v < 0]
    require(not neg or lo < 0,
            f"--holdout-time {window!r}: {neg[0] if neg else 0:g} s is before every reading "
            f"(the runs' times span {lo:g} .. {hi:g} s, each in its file's time); a time counted "
            f"from the end is not read as such: give it from the start (e.g. "
            f"{max(hi - 3600.0, lo):g}s: for the last hour)")


def _enough(s: DriftSeries, test: np.ndarray, window, files) -> None:
    """One line naming the option when the split holds out nothing (with the runs' time
    range) or leaves fewer than 20 training readings (with what it held out)."""
    given = [f"--holdout-time {window}" if window is not None else "",
             "--holdout-files" if files else ""]
    opts = " and ".join(g for g in given if g) or "the default split"
    lo, hi = float(s.t_s.min()), float(s.t_s.max())
    require(test.any(), f"loop: nothing is held out: {opts} selects no reading (the runs' "
                        f"times span {lo:g} .. {hi:g} s = {lo / 3600:.4g} .. {hi / 3600:.4g} h, "
                        f"each in its file's time)")
    n = int((~test).sum())
    whole = sum(bool(np.all(test[s.run == r])) for r in range(len(s.runs)))
    require(n >= 20, f"loop: fewer than 20 training readings are left ({n} of {len(test)}): "
                     f"{opts} held out {int(test.sum())} readings ({whole} of {len(s.runs)} "
                     f"runs whole); hold out less, or give more runs")


def default_split(s: DriftSeries) -> tuple[np.ndarray, str]:
    """The rule of the module docstring without ``--holdout-*``."""
    n_runs = len(s.runs)
    if n_runs >= 2:
        return s.run == n_runs - 1, f"the last run ({s.runs[-1][0]}) held out"
    t = s.t_s
    cut = t[0] + (1 - DEFAULT_TEST) * (t[-1] - t[0])
    return t >= cut, (f"the last {DEFAULT_TEST:.0%} of the run's time held out "
                      f"(t >= {cut:.0f} s)")


#: equal-time blocks per file of the 3-D loop's held-out split
N_BLOCKS = 20


def stretch_split(t, groups, fraction: float) -> np.ndarray:
    """Held-out mask of the 3-D loop's points with a time column: every file's time span cut
    into ``N_BLOCKS`` equal blocks and ``round(fraction N_BLOCKS)`` of them held out, spread
    evenly (block ``floor((j + 1/2) N_BLOCKS / m)``, j = 0..m-1): whole contiguous stretches
    over the whole campaign (every phase of a duty cycle is judged), never points drawn at
    random (a point's neighbour in time is almost the same reading)."""
    t = np.asarray(t, float)
    g = np.zeros(len(t), int) if groups is None else np.asarray(groups)
    m = max(1, int(round(fraction * N_BLOCKS)))
    held = np.floor((np.arange(m) + 0.5) * N_BLOCKS / m).astype(int)
    test = np.zeros(len(t), bool)
    for f in np.unique(g):
        sel = g == f
        lo, hi = t[sel].min(), t[sel].max()
        if not hi > lo:
            continue
        block = np.minimum(((t[sel] - lo) / (hi - lo) * N_BLOCKS).astype(int), N_BLOCKS - 1)
        test[np.flatnonzero(sel)[np.isin(block, held)]] = True
    return test


#: a held-out input beyond the training range by more than this share of that range ...
EXTRAPOLATION_MARGIN = 0.05
#: ... and by more than this many times its reading-to-reading scatter (a run's zero is one
#: reading: every change of the run carries that reading's noise)
EXTRAPOLATION_NOISE = 3.0


def _scatter(v: np.ndarray, run: np.ndarray) -> float:
    """The median over the runs of an input's robust reading-to-reading scatter
    (:func:`volerr.instruments._fields.change_scores`; 0 for a commanded speed)."""
    from ...instruments._fields import change_scores

    found = [change_scores(v[run == r])[1] for r in np.unique(run) if np.sum(run == r) > 3]
    return float(np.median(found)) if found else 0.0


def extrapolation(s: DriftSeries) -> list:
    """The logged inputs whose held-out readings leave the range the training readings span
    (by more than ``EXTRAPOLATION_MARGIN`` of it): there a fitted drift model extrapolates
    (a speed never run, a warming never reached), its prediction is not supported by the
    data.  Judged on what the model uses: a temperature (any input but the speed) as its
    change since its run's first reading (every run its own zero, :meth:`DriftSeries.zero`;
    runs that start at different room temperatures are no extrapolation), the speed
    (``S_rpm``, the heat input ``(S/S_ref)^p``) as logged.  Beyond the range by more than
    ``EXTRAPOLATION_MARGIN`` of it and ``EXTRAPOLATION_NOISE`` times the input's scatter
    (:func:`_scatter`).  [{"input", "train_min",
    "train_max", "test_min", "test_max", "basis": "change" | "value"}] (the input's unit),
    in file order."""
    from .basis import SPEED

    out = []
    for name, v in s.inputs.items():
        v = np.asarray(v, float)
        change = name != SPEED
        if change:
            v = v - s.zero(v)
        tr, te = v[s.train], v[s.test]
        if not (len(tr) and len(te)):
            continue
        lo, hi = float(tr.min()), float(tr.max())
        pad = max(EXTRAPOLATION_MARGIN * max(hi - lo, 1e-12),
                  EXTRAPOLATION_NOISE * _scatter(v[s.train], s.run[s.train]))
        if te.min() < lo - pad or te.max() > hi + pad:
            out.append({"input": name, "train_min": lo, "train_max": hi,
                        "test_min": float(te.min()), "test_max": float(te.max()),
                        "basis": "change" if change else "value"})
    return out


def extrapolation_line(items: list) -> str:
    """One console line naming the inputs :func:`extrapolation` found (empty: '')."""
    if not items:
        return ""
    parts = [f"{e['input']}{' change' if e.get('basis') == 'change' else ''} "
             f"{e['test_min']:.4g}..{e['test_max']:.4g} (training "
             f"{e['train_min']:.4g}..{e['train_max']:.4g})" for e in items]
    return ("warning: the held-out readings leave the training range of " + ", ".join(parts)
            + ": there the model extrapolates, its held-out figures judge an extrapolation")


def kept_out_line(items: list) -> str:
    """One console line naming the sensors :func:`volerr.loop.drift.basis.kept_out` found
    (empty: '')."""
    if not items:
        return ""
    parts = [f"{e['input']} {e['test_change']:.3g} (training {e['train_change']:.3g})"
             for e in items]
    return ("warning: kept out of the lag model, their held-out runs change far more than the "
            "training runs (peak to peak since each run's zero): " + ", ".join(parts)
            + "; their coefficients were never determined, what they do there is unmodelled")


def room_undecided_line(item: dict | None) -> str:
    """One console line saying what :func:`volerr.loop.drift.basis.room_undecided` found
    (None: '')."""
    if not item:
        return ""
    names = ", ".join(e["sensor"] for e in item["sensors"])
    verb, its = ("acts", "its") if len(item["sensors"]) == 1 else ("act", "their")
    return (f"warning: the training runs hold the room ({item['room']} changes "
            f"{item['train_room_ptp_K']:.3g} K peak to peak, the held-out runs' "
            f"{item['held_out_room_ptp_K']:.3g} K), so whether {names} {verb} by {its} absolute "
            f"change (a structure temperature) or by {its} rise over the room (a heat proxy) "
            f"is not decided by these data (the model takes the {item['reading']}); the two "
            f"readings differ in the held-out room, the prediction interval holds both; a "
            f"training run in a varying room decides it")
