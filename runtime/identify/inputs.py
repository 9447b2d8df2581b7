"""The rounds of an identification from the files a user names (both tracker formats of
:mod:`volerr.identify.tracker_io`), with the checks on the list of files."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import require


def refuse_repeated_files(files) -> None:
    """Refuse a tracker file given twice: its rounds would be counted twice (understated
    Type A uncertainty)."""
    seen = []
    for f in files:
        p = Path(f)
        for q in seen:
            same = p.resolve() == q.resolve() or (
                p.exists() and q.exists() and os.path.samefile(p, q))
            require(not same, f"tracker file {f} is given twice (its rounds would be counted "
                              f"twice)")
        seen.append(p)


def read_rounds(files, fmt: str = "csv", positions: str | None = None,
                points: str | None = None) -> list:
    """The measured rounds of the tracker files ``files``.

    Parameters
    ----------
    files : sequence of path
        Tracker files: ``round,point,position,x,y,z`` CSV (``fmt="csv"``, any number of rounds
        per file) or the thesis' raw export (``fmt="thesis"``, one round per file).
    fmt : {"csv", "thesis"}
        File format.
    positions : str, optional
        Thesis format only: commanded positions, ``start:stop:count`` or a comma list (mm or
        deg).
    points : str, optional
        Thesis format only: labels of the point blocks in file order, comma-separated.

    Returns
    -------
    list of Round
        The rounds (:class:`volerr.identify.tracker_io.Round`), in file order.
    """
    from .tracker_io import parse_positions, read_thesis_export, read_tracker_csv

    rounds = []
    if fmt == "thesis":
        require(positions is not None, "--format thesis needs --positions start:stop:count")
        pos = parse_positions(positions)
        labels = [s.strip() for s in points.split(",") if s.strip()] if points else None
        for f in files:
            rounds.append(read_thesis_export(f, pos, labels))
    else:
        require(positions is None and points is None,
                "--positions and --labels apply to --format thesis only")
        for f in files:
            rounds.extend(read_tracker_csv(f))
    return rounds
