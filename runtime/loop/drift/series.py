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
        """The zero of ``v`` (N,) in its run, at every reading (N,): its first reading, the
        value a run is predicted from where its zero is not fitted (a held-out run, a fold of
        whole runs), the same for the readings and every model column (each column is its
        change since it), in every family.  (The mean of the first readings before the
        spindle starts was measured and not adopted: docs/drift_loop.md.)"""
        return np.asarray(v, float)[self.firsts()][self.run]



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
