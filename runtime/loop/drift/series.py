"""The one data type of the loop on drift runs: :class:`DriftSeries`, the runs of one or
more drift files stacked (every run its own zero and its own lag start), and the reading of
drift files into it (:func:`load_series`; the files' format: :mod:`volerr.instruments.drift`).

Units: time s, displacements um, temperatures degC, speed rpm.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ...errors import require

#: a run's zero, where a series holds several runs: the mean of its readings within this many
#: seconds of its first (one run: its first reading)
ZERO_S = 300.0


@dataclass
class DriftSeries:
    """Drift runs stacked in time order within each run.

    ``t_s`` (N,) seconds; ``run`` (N,) run index into ``runs`` [(file, label)];
    ``inputs`` {name: (N,)} logged inputs (degC, rpm, ...); ``channels`` {label: (N,)} um;
    ``directions`` {label: "X".."-Z" or "?"}; ``heights`` {label: mm or None};
    ``test`` (N,) bool: held out; ``environments`` one label per run (the files'
    ``environment`` column; empty: none given)."""

    t_s: np.ndarray
    run: np.ndarray
    runs: list
    inputs: dict
    channels: dict
    directions: dict = field(default_factory=dict)
    heights: dict = field(default_factory=dict)
    test: np.ndarray | None = None
    environments: list = field(default_factory=list)
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

    def zero(self, v) -> np.ndarray:
        """The zero of ``v`` (N,) in its run, at every reading (N,): the value a run is
        predicted from where its zero is not fitted (a held-out run, a fold of whole runs),
        the same for the readings and every model column (each column is its change since
        it).  One run: its first reading.  Several: the mean of the run's first readings
        while the machine is still as at its first: within ``ZERO_S`` of it and before the
        spindle speed (``S_rpm``) first changes (at least the first reading).  A zero read
        from one reading carries that reading's noise into every prediction of the run
        (through every sensor's coefficient: of near-collinear sensors, magnified); over
        readings where nothing has started to move the mean is the same zero (readings and
        columns alike are changes since it) with the noise averaged, while readings after
        the spindle starts move for reasons a model need not capture exactly."""
        v = np.asarray(v, float)
        if "_zero" not in self.memo:
            window = ZERO_S if len(self.runs) > 1 else 0.0
            S = self.inputs.get("S_rpm")
            heads = []
            for r in range(len(self.runs)):
                i = np.flatnonzero(self.run == r)
                still = self.t_s[i] - self.t_s[i[0]] < window
                if S is not None:              # ... and the spindle as at the first reading
                    still &= np.asarray(S, float)[i] == float(S[i[0]])
                heads.append(i[:max(1, int(np.argmin(still)) if not still.all() else len(i))])
            self.memo["_zero"] = heads
        z = np.array([v[i].mean() if len(i) > 1 else v[i[0]] for i in self.memo["_zero"]])
        return z[self.run]



def load_series(paths) -> DriftSeries:
    """Drift files (paths) -> one :class:`DriftSeries` (every run its own zero and its own lag
    start); runs must log the same channels and inputs."""
    return stack_runs(read_runs(paths))


def read_runs(paths) -> list:
    """The runs (:class:`volerr.instruments.drift.DriftRun`) of the drift files ``paths``;
    every run must log the same channels and inputs as the first (one line names the run)."""
    from ...instruments.drift import read_runs as _read

    runs = [r for p in paths for r in _read(p)]
    first = runs[0]
    for r in runs[1:]:
        require(set(r.channels) == set(first.channels) and set(r.inputs) == set(first.inputs),
                f"{r.name}: its channels and logged inputs differ from {first.name}'s; the "
                f"runs of one loop log the same ones")
    return runs


def stack_runs(runs) -> DriftSeries:
    """The runs one after the other as one :class:`DriftSeries` (no reading held out yet)."""
    first = runs[0]
    cat = np.concatenate
    return DriftSeries(
        cat([r.t_s for r in runs]), cat([np.full(r.n, i) for i, r in enumerate(runs)]),
        [(r.file, r.run) for r in runs],
        {k: cat([r.inputs[k] for r in runs]) for k in first.inputs},
        {k: cat([r.channels[k] for r in runs]) for k in first.channels},
        dict(first.directions), dict(first.heights),
        environments=[r.environment for r in runs] if any(r.environment for r in runs) else [])
