"""The one data type of the loop on drift runs: :class:`DriftSeries`, the runs of one or
more drift files stacked (every run its own zero and its own lag start), and the reading of
drift files into it (:func:`load_series`; the files' format: :mod:`volerr.instruments.drift`).

Units: time s, displacements um, temperatures degC, speed rpm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import require


@dataclass
class DriftSeries:
    """Drift runs stacked in time order within each run.

    ``t_s`` (N,) seconds; ``run`` (N,) run index into ``runs`` [(file, label)];
    ``inputs`` {name: (N,)} logged inputs (degC, rpm, ...); ``channels`` {label: (N,)} um;
    ``directions`` {label: "X".."-Z" or "?"}; ``heights`` {label: mm or None};
    ``test`` (N,) bool: held out; ``environments`` one label per run (the files'
    ``environment`` column; empty: none given); ``left_out`` the inputs left out of every
    run (:func:`read_runs`)."""

    t_s: np.ndarray
    run: np.ndarray
    runs: list
    inputs: dict
    channels: dict
    directions: dict = field(default_factory=dict)
    heights: dict = field(default_factory=dict)
    test: np.ndarray | None = None
    environments: list = field(default_factory=list)
    #: inputs left out of every run (missing from a file or faulty; series.read_runs)
    left_out: list = field(default_factory=list)
    #: every run's label for the rows of the predictions CSV (:meth:`row_label`)
    labels: list = field(default_factory=list)
    memo: dict = field(default_factory=dict, repr=False, compare=False)

    @property
    def train(self) -> np.ndarray:
        return ~self.test

    def indicators(self) -> np.ndarray:
        """The run-indicator matrix (N, n_runs): 1 where a reading belongs to the run (the
        columns of the runs' zeros); built once per series (kept in ``memo``)."""
        if "_R" not in self.memo:
            self.memo["_R"] = (self.run[:, None] == np.arange(len(self.runs))[None, :]
                               ).astype(float)
        return self.memo["_R"]

    def row_label(self, r: int) -> str:
        """Run ``r`` as the predictions CSV's ``run`` column names it: its label in its
        file's ``run`` column (also where the file holds one run), else its file name."""
        return (self.labels[r] if r < len(self.labels) else "") or self.runs[r][1] \
            or self.runs[r][0]

    def firsts(self) -> np.ndarray:
        """Index (n_runs,) of every run's first reading (kept in ``memo``)."""
        if "_firsts" not in self.memo:
            self.memo["_firsts"] = np.array([int(np.flatnonzero(self.run == r)[0])
                                             for r in range(len(self.runs))])
        return self.memo["_firsts"]

    def order(self) -> np.ndarray:
        """Indices (N,) that sort the readings by (run, time)
        (:func:`volerr.machine.lags.time_order`; kept in ``memo``): what every lag of the
        series sorts by."""
        if "_order" not in self.memo:
            from ...machine.lags import time_order

            self.memo["_order"] = time_order(self.t_s, self.run)
        return self.memo["_order"]

    def run_zeros(self, v) -> np.ndarray:
        """The zero (n_runs,) of ``v`` (N,) in every run: its first reading, the value a run
        is predicted from where its zero is not fitted (a held-out run, a fold of whole
        runs), the same for the readings and every model column (each column is its change
        since it), in every family.  (The mean of the first readings before the spindle
        starts was measured and not adopted: docs/drift_loop.md.)"""
        return np.asarray(v, float)[self.firsts()]

    def zero(self, v) -> np.ndarray:
        """:meth:`run_zeros` of ``v`` at every reading (N,)."""
        return self.run_zeros(v)[self.run]



def load_series(paths) -> DriftSeries:
    """Drift files (paths) -> one :class:`DriftSeries` (every run its own zero and its own lag
    start); runs must log the same channels; inputs not logged in every run, or faulty in
    one, are left out (:func:`read_runs`)."""
    return stack_runs(*read_runs(paths))


def read_runs(paths) -> tuple[list, list]:
    """(runs, left_out): the runs (:class:`volerr.instruments.drift.DriftRun`) of the drift
    files ``paths``, every run with the logged inputs every run has and none faulty, and the
    inputs left out [{"input", "reason": "missing" | "faulty", "files": [the runs that lack
    it], "faults": [the faults, :func:`volerr.instruments.drift.faults`]}], in order of first
    appearance.  Every run must log the same channels as the first (one line names the run;
    a channel is the measurand), and a faulty channel refuses its file."""
    from ...instruments.drift import fault_text, faults, read_runs as _read

    runs = [r for p in paths for r in _read(p, keep_constant=True)]
    first = runs[0]
    for r in runs[1:]:
        require(set(r.channels) == set(first.channels),
                f"{r.name}: its channels ({', '.join(r.channels)}) differ from {first.name}'s "
                f"({', '.join(first.channels)}); the runs of one loop log the same channels")
    _refuse_twice(runs)
    _refuse_unit_slip(runs)
    _refuse_time_slip(runs)
    found = [e for r in runs for e in faults(r)]
    bad = next((e for e in found if e.get("channel")), None)
    require(bad is None, f"{bad and bad['file']}: channel {bad and fault_text(bad)}: a channel "
                         f"is the measurand and cannot be left out; cut the run or check "
                         f"the sensor")
    names = list(dict.fromkeys(k for r in runs for k in r.inputs))
    left = []
    for k in names:
        lack = [r.name for r in runs if k not in r.inputs]
        bad_k = [e for e in found if e["input"] == k]
        if lack or bad_k:
            left.append({"input": k, "reason": "missing" if lack else "faulty",
                         "files": lack, "faults": bad_k})
    gone = {e["input"] for e in left}
    require(any(k not in gone for k in names), _none_left(runs, left))
    for r in runs:
        r.inputs = {k: v for k, v in r.inputs.items() if k not in gone}
    return runs, left


def _none_left(runs, left: list) -> str:
    """The line refusing a campaign whose every logged input is missing from a run or faulty
    in one: it names the run that lacks (or has faulty) the most of them, first in file
    order among equals, what it lacks, what is faulty in it (the faults' words) and what
    the other runs lost."""
    from ...instruments.drift import fault_where as where

    count = {r.name: 0 for r in runs}
    for e in left:
        for name in set(e["files"]) | {where(x) for x in e["faults"]}:
            count[name] += 1
    worst = max(count, key=lambda k: count[k])
    lacks = [e["input"] for e in left if worst in e["files"]]
    faulty = {x["input"]: x["fault"] for e in left for x in e["faults"] if where(x) == worst
              and e["input"] not in lacks}
    rest = [e["input"] for e in left if e["input"] not in lacks and e["input"] not in faulty]
    parts = [f"it lacks {', '.join(lacks)}" if lacks else "",
             "faulty in it: " + ", ".join(f"{k} ({v})" for k, v in faulty.items())
             if faulty else "",
             f"missing from or faulty in other runs: {', '.join(rest)}" if rest else ""]
    return (f"{worst}: no logged input is left for the model ({'; '.join(p for p in parts if p)}"
            f"); a model needs the inputs of every run")


def _refuse_twice(runs) -> None:
    """One line when two runs hold the same readings, times, channels and inputs alike (the
    same file given twice, or a copy under another name, e.g. once as data and once held
    out): a run counted twice is predicted from its own copy in the cross-validation of
    whole runs, and a held-out copy is judged on the readings the model was fitted on (its
    held-out figure is not held out)."""
    import hashlib

    seen: dict = {}
    for r in runs:
        h = hashlib.sha256(np.ascontiguousarray(r.t_s, float).tobytes())
        for k, v in sorted({**r.channels, **r.inputs}.items()):
            h.update(k.encode() + np.ascontiguousarray(v, float).tobytes())
        key = h.hexdigest()
        other = seen.setdefault(key, r)
        require(other is r, f"{r.name}: the same readings as {other.name} (one run given twice, "
                            f"or copied under another name): a run counted twice is judged on "
                            f"its own copy; give each run once")


#: a run whose channel ranges less than this share of the other runs' median range: a unit
#: slip (mm written under a ``_um`` header is 1000x small); real runs differ by far less,
#: since a channel's range holds at least its reading noise
UNIT_SLIP = 1 / 200


def _refuse_unit_slip(runs) -> None:
    """One line when, in a campaign of three runs or more, one run's channel spans less than
    ``UNIT_SLIP`` of the median span (peak to peak, um) of the runs: the likely mistake is a
    channel in mm under its ``_um`` header (nm under it is refused by the drift reader)."""
    if len(runs) < 3:
        return
    for k in runs[0].channels:
        span = np.array([float(np.ptp(r.channels[k])) for r in runs])
        med = float(np.median(span))
        for r, v in zip(runs, span):
            require(not (med > 0 and v < UNIT_SLIP * med),
                    f"{r.name}: channel d_{k}_um spans {v:.3g} um where the runs' median span "
                    f"is {med:.3g} um ({med / max(v, 1e-300):.0f}x more): mm under the _um "
                    f"header? give the channel in um")


#: a run whose reading interval and duration are both this many times below the campaign's
#: medians, while its drift and temperatures change at least ``SLIP_CHANGE`` of theirs: its
#: time column is in minutes (60x) or hours (3600x) under ``t_s``; real campaigns mix
#: intervals (15-60 s) and durations (1 h days beside 8 h ones) by far less than 30x both
TIME_SLIP = 30.0
SLIP_CHANGE = 1 / 3
#: the fastest a run's median temperature sensor is taken to change over the whole run,
#: K/min (15 K/h): a machine's structure (most of its sensors) warms with time constants of
#: tens of minutes to hours (FL_THERMAL 0.001, the turning-centre days, 1 h ones included,
#: at most 0.016 K/min; a spindle housing at full speed a few tenths in its first minutes,
#: less over a run); a run faster than this is a time column in minutes or hours under
#: ``t_s`` (60x, 3600x: a 5 h run in minutes 0.37 K/min) (judged with 3 sensors or more)
FASTEST_K_PER_MIN = 0.25
#: the same with one or two sensors (a spindle housing's alone may change a few tenths K/min
#: over a short run): the slower of them changing faster than this, K/min, is a time column
#: in hours under ``t_s`` (3600x: 1 K in a 3 h run read as 3 s is 20 K/min)
FASTEST_FEW_K_PER_MIN = 2.0


def _temperature_change(r) -> tuple[float, int, float]:
    """(the median over the run's ``T_*`` sensors of their peak-to-peak change, K; how many;
    the least of them, K)."""
    temps = [float(np.ptp(v)) for k, v in r.inputs.items() if k.startswith("T_")]
    return (float(np.median(temps)) if temps else 0.0), len(temps), min(temps, default=0.0)


def _refuse_time_slip(runs) -> None:
    """One line when a run's time column reads minutes or hours as seconds: its temperatures
    change faster than a machine warms (:data:`FASTEST_K_PER_MIN`, every run; the slower of
    one or two sensors :data:`FASTEST_FEW_K_PER_MIN`), or, in a
    campaign of three runs or more, its reading interval and duration are both
    :data:`TIME_SLIP` times below the runs' medians while its drift and temperatures change
    as much (:data:`SLIP_CHANGE`)."""
    dt = np.array([float(np.median(np.diff(r.t_s))) for r in runs])
    span = np.array([float(r.t_s[-1] - r.t_s[0]) for r in runs])
    changes = [_temperature_change(r) for r in runs]
    heat = np.array([c[0] for c in changes])
    drift = np.array([float(np.median([np.ptp(v) for v in r.channels.values()])) for r in runs])
    mdt, mspan = float(np.median(dt)), float(np.median(span))
    for i, r in enumerate(runs):
        change, n, least = changes[i]
        rate = change / max(span[i], 1e-300) * 60.0
        slow = least / max(span[i], 1e-300) * 60.0
        require(not (0 < n < 3 and slow > FASTEST_FEW_K_PER_MIN),
                f"{r.name}: its {'slower ' if n > 1 else ''}temperature changes {least:.3g} K "
                f"in {span[i]:g} s of its time column, {slow:.2g} K/min: faster than a machine "
                f"warms (at most {FASTEST_FEW_K_PER_MIN:g} K/min with {n} "
                f"sensor{'s' if n > 1 else ''}): time in hours under t_s? give seconds (or name "
                f"the column t_h)")
        require(not (n >= 3 and rate > FASTEST_K_PER_MIN),
                f"{r.name}: its temperatures change {change:.3g} K (median sensor) in {span[i]:g} "
                f"s of its time column, {rate:.2g} K/min: faster than a machine warms (at most "
                f"{FASTEST_K_PER_MIN:g} K/min): time in minutes or hours under t_s? give "
                f"seconds (or name the column t_min / t_h)")
        if len(runs) < 3:
            continue
        slip = (dt[i] * TIME_SLIP < mdt and span[i] * TIME_SLIP < mspan
                and drift[i] >= SLIP_CHANGE * np.median(drift)
                and heat[i] >= SLIP_CHANGE * np.median(heat))
        require(not slip, f"{r.name}: its time column spans {span[i]:g} s at {dt[i]:g} s "
                          f"steps where the runs' median is {mspan:g} s at {mdt:g} s steps "
                          f"({mspan / span[i]:.0f}x longer), while its drift and temperatures "
                          f"change as much: time in minutes or hours under t_s? give seconds "
                          f"(or name the column t_min / t_h)")


def left_out_line(left: list) -> str:
    """One console line naming the inputs :func:`read_runs` left out (empty: '')."""
    if not left:
        return ""
    from ...instruments.drift import fault_text, fault_where

    parts, const = [], {}
    for e in left:
        if e["reason"] == "missing":
            parts.append(f"{e['input']} (missing from {', '.join(e['files'])})")
            continue
        for x in e["faults"]:
            if x["fault"] == "constant":      # one phrase for the sensors constant in a run
                const.setdefault((fault_where(x), x["readings"]), []).append(x)
        if any(x["fault"] != "constant" for x in e["faults"]):
            parts.append("; ".join(fault_text(x) for x in e["faults"] if x["fault"] != "constant"))
    for (where, n), xs in const.items():
        parts.append(", ".join(f"{x['input']} (= {x['value']:g})" for x in xs)
                     + f" constant in {where} (all {n} readings: disconnected, stuck, or "
                       f"steadier than the sensor's resolution)")
    return ("note: left out of the model in every run: " + "; ".join(parts)
            + " (a model needs the inputs of every run; a faulty sensor would be fitted as "
              "physics)")


def stack_runs(runs, left_out=()) -> DriftSeries:
    """The runs one after the other as one :class:`DriftSeries` (no reading held out yet;
    ``left_out`` the inputs :func:`read_runs` left out)."""
    first = runs[0]
    cat = np.concatenate
    return DriftSeries(
        cat([r.t_s for r in runs]), cat([np.full(r.n, i) for i, r in enumerate(runs)]),
        [(r.file, r.run) for r in runs],
        {k: cat([r.inputs[k] for r in runs]) for k in first.inputs},
        {k: cat([r.channels[k] for r in runs]) for k in first.channels},
        dict(first.directions), dict(first.heights),
        environments=[r.environment for r in runs] if any(r.environment for r in runs) else [],
        left_out=list(left_out), labels=[r.label for r in runs])
