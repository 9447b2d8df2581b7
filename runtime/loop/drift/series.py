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

    def firsts(self) -> np.ndarray:
        """Index (n_runs,) of every run's first reading."""
        return np.array([int(np.flatnonzero(self.run == r)[0]) for r in range(len(self.runs))])

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

    runs = [r for p in paths for r in _read(p)]
    first = runs[0]
    for r in runs[1:]:
        require(set(r.channels) == set(first.channels),
                f"{r.name}: its channels ({', '.join(r.channels)}) differ from {first.name}'s "
                f"({', '.join(first.channels)}); the runs of one loop log the same channels")
    _refuse_twice(runs)
    _refuse_unit_slip(runs)
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
    require(any(k not in gone for k in names),
            f"{first.name}: no logged input is left for the model (every one is missing from "
            f"a file or faulty: {', '.join(sorted(gone))})")
    for r in runs:
        r.inputs = {k: v for k, v in r.inputs.items() if k not in gone}
    return runs, left


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


def left_out_line(left: list) -> str:
    """One console line naming the inputs :func:`read_runs` left out (empty: '')."""
    if not left:
        return ""
    from ...instruments.drift import fault_text

    parts = []
    for e in left:
        if e["reason"] == "missing":
            parts.append(f"{e['input']} (missing from {', '.join(e['files'])})")
        else:
            parts.append("; ".join(fault_text(x) for x in e["faults"]))
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
        left_out=list(left_out))
