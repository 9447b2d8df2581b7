"""Laser-tracker point data for the three-point identification: reading and validation.

Two input formats, both in mm in the measurement frame:

*Tracker CSV* (INTERFACE.md), header ``round,point,position,x,y,z`` (any column order; extra
columns are ignored; ``x_mm`` etc. are accepted; blank lines and ``#`` comments skipped)::

    round,point,position,x,y,z
    1,P,0,100.0012,50.0003,-20.0001
    1,Q,0,...

``point`` is any label (at least three distinct points), ``position`` the commanded axis
position (mm or deg).  Within a round every point is measured at every position exactly once.
The *first* position of a round, in file order, is its reference (errors zero there); a round
that starts elsewhere (e.g. measured backwards) is referred to the first round's reference, so
that all rounds average the same reference pose.  Rows of one round may be in any order
otherwise.  Several files are concatenated; rounds are keyed by
(file, round).

*Thesis export* (``format="thesis"``): the measuring software's export used by the thesis
scripts (Appendix C.1, D.1): one file per round, rows ``label,x,y,z`` without header, one block
of N consecutive rows per point (N = number of commanded positions, in order), e.g. the K block,
then P, then Q.  The commanded positions are not in the file and are given separately
(``positions``, e.g. ``numpy.linspace(0, 500, 11)``); the first one is the reference.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..units import parse_number
from ..errors import InputError, require
from ..fileio import MAX_ABS, check_header, check_magnitude, read_csv_rows

REQUIRED = ("round", "point", "position", "x", "y", "z")


@dataclass
class Round:
    """One round of measurements.

    ``positions``: shape (n_positions,), commanded positions in measurement order (the first is
    the reference); ``labels``: the point labels, shape (n_points,); ``points``: shape
    (n_positions, n_points, 3), measured coordinates, mm."""

    name: str
    positions: np.ndarray
    labels: tuple
    points: np.ndarray


def _open_rows(path: Path):
    return read_csv_rows(path, missing=f"tracker file not found: {path}", empty=f"{path}: no data")


def _num(path, lineno, what, text) -> float:
    where = f"{path}:{lineno}"
    return check_magnitude(parse_number(text, where, what), f"{where}: {what}")


def _header_index(path, header):
    check_header([{"x_mm": "x", "y_mm": "y", "z_mm": "z"}.get(h.strip().lower(), h)
                  for h in header], str(path))
    norm = [h.strip().lower() for h in header]
    alias = {"x_mm": "x", "y_mm": "y", "z_mm": "z"}
    norm = [alias.get(h, h) for h in norm]
    index = {}
    for col in REQUIRED:
        if col not in norm:
            if col == "position":
                cand = [h for h in norm if h.startswith("position")]
                if len(cand) == 1:
                    index[col] = norm.index(cand[0])
                    continue
            missing = [c for c in REQUIRED if c not in norm]
            raise InputError(f"{path}: missing column(s) {', '.join(missing)}; the tracker CSV "
                             f"needs the header {','.join(REQUIRED)}")
        index[col] = norm.index(col)
    return index


def read_tracker_csv(path) -> list[Round]:
    """Read one tracker CSV file -> its rounds (see the module docstring)."""
    path = Path(path)
    fast = _read_loadtxt(path)
    if fast is not None:
        return fast
    rows = _open_rows(path)
    (_, header), body = rows[0], rows[1:]
    idx = _header_index(path, header)
    require(body, f"{path}: header only, no measurements")
    fast = _read_regular(path, body, idx)
    if fast is not None:
        return fast
    return _read_by_row(path, body, idx)  # a file with a problem: its line is named


def _read_loadtxt(path: Path) -> list[Round] | None:
    """A plain file (no quotes, comments or blank lines; one header line) tokenised by numpy's
    C reader (``numpy.loadtxt``) and grouped by :func:`_group`; None for anything else, so that
    the csv-module readers handle it (and name the faulty line)."""
    try:
        text = path.read_text(encoding="utf-8-sig")
    except (OSError, UnicodeDecodeError):
        return None
    first, sep, rest = text.partition("\n")
    if not sep or '"' in text or "#" in text or "\n\n" in text or "\r" in text \
            or not rest.strip():
        return None
    header = [h.strip() for h in first.split(",")]
    try:
        idx = _header_index(path, header)
    except InputError:
        return None
    width = len(header)
    # every line has the header's number of cells (counted here: numpy reads only the
    # columns it is asked for and would not notice a short or long line)
    raw = np.frombuffer(rest.encode("utf-8"), dtype=np.uint8)
    ends = np.flatnonzero(raw == ord("\n"))
    if len(raw) and raw[-1] != ord("\n"):
        ends = np.append(ends, len(raw))
    commas = np.searchsorted(np.flatnonzero(raw == ord(",")), ends)   # commas before each end
    per_line = np.diff(commas, prepend=0)
    if len(ends) == 0 or np.any(per_line != width - 1):
        return None
    try:
        lines = rest.splitlines()
        num = np.loadtxt(lines, delimiter=",", dtype=float, ndmin=2,
                         usecols=[idx[c] for c in ("position", "x", "y", "z")])
        txt = np.loadtxt(lines, delimiter=",", dtype=str, ndmin=2,
                         usecols=[idx["round"], idx["point"]])
    except (ValueError, IndexError):
        return None
    if len(lines) != len(ends) or txt.shape != (len(lines), 2) or num.shape[0] != len(lines):
        return None
    rnd = np.char.strip(txt[:, 0])
    label = np.char.strip(txt[:, 1])
    return _group(path, rnd, label, num.T)


def _read_by_row(path: Path, body: list, idx: dict) -> list[Round]:
    """Row-by-row reader with a check and an exact message per line (slow)."""
    data: dict = {}
    width = max(idx.values()) + 1
    for lineno, cells in body:
        require(len(cells) >= width, f"{path}:{lineno}: expected at least {width} columns, "
                                     f"got {len(cells)}")
        rnd, label = cells[idx["round"]], cells[idx["point"]]
        require(rnd != "", f"{path}:{lineno}: empty round")
        require(label != "", f"{path}:{lineno}: empty point label")
        pos = _num(path, lineno, "position", cells[idx["position"]])
        xyz = tuple(_num(path, lineno, c, cells[idx[c]]) for c in ("x", "y", "z"))
        # dicts keep the file order: positions in measurement order, labels as first seen
        d = data.setdefault(rnd, {"positions": {}, "labels": {}, "values": {}})
        d["positions"].setdefault(pos, None)
        d["labels"].setdefault(label, None)
        key = (pos, label)
        require(key not in d["values"], f"{path}:{lineno}: round {rnd}: point {label} measured "
                                         f"twice at position {pos:g}")
        d["values"][key] = xyz
    rounds = []
    for rnd, d in data.items():
        pos, labels = list(d["positions"]), list(d["labels"])
        if len(d["values"]) != len(pos) * len(labels):
            for p in pos:
                for lab in labels:
                    require((p, lab) in d["values"], f"{path}: round {rnd}: point {lab} has no "
                                                     f"measurement at position {p:g}")
        pts = np.array([[d["values"][(p, lab)] for lab in labels] for p in pos], dtype=float)
        rounds.append(Round(f"{path.name}:{rnd}", np.array(pos, dtype=float), tuple(labels), pts))
    return rounds


def _first_seen(values: np.ndarray):
    """(distinct values in order of first appearance, index of each row's value in them)."""
    uniq, first, inv = np.unique(values, return_index=True, return_inverse=True)
    order = np.argsort(first, kind="stable")
    rank = np.empty(len(order), dtype=np.intp)
    rank[order] = np.arange(len(order))
    return uniq[order], rank[np.ravel(inv)]


def _read_regular(path: Path, body: list, idx: dict) -> list[Round] | None:
    """The rounds of a well-formed file, parsed column-wise (numbers converted by numpy, no
    per-row checks); None when anything is irregular, so that the row-by-row reader reports it
    with its line number."""
    width = max(idx.values()) + 1
    cells = [c for _, c in body]
    if min(map(len, cells)) < width or max(map(len, cells)) != min(map(len, cells)):
        return None
    table = np.array(cells)  # (n, columns) of text, one C-level conversion
    rnd, label = table[:, idx["round"]], table[:, idx["point"]]
    try:
        num = table[:, [idx[c] for c in ("position", "x", "y", "z")]].astype(float).T
    except ValueError:
        return None
    return _group(path, rnd, label, num)


def _group(path: Path, rnd: np.ndarray, label: np.ndarray, num: np.ndarray) -> list[Round] | None:
    """Rounds from the columns round, point (text, (n,)) and position, x, y, z ((4, n) float);
    None when anything is irregular (the row-by-row reader then reports it)."""
    if not np.isfinite(num).all() or np.abs(num).max(initial=0.0) > MAX_ABS \
            or (rnd == "").any() or (label == "").any():
        return None  # the row reader names the faulty line
    rnd_names, rnd_of = _first_seen(rnd)
    rounds = []
    for r, name in enumerate(rnd_names):
        rows = np.flatnonzero(rnd_of == r)
        pos, pos_of = _first_seen(num[0, rows])
        labels, lab_of = _first_seen(label[rows])
        key = pos_of * len(labels) + lab_of
        if len(rows) != len(pos) * len(labels) or \
                np.bincount(key, minlength=len(rows)).max(initial=0) > 1:
            return None  # a duplicate or a missing measurement
        pts = np.empty((len(pos), len(labels), 3))
        pts[pos_of, lab_of] = num[1:, rows].T
        rounds.append(Round(f"{path.name}:{name}", pos.astype(float),
                            tuple(str(v) for v in labels), pts))
    return rounds


def read_thesis_export(path, positions, labels=None) -> Round:
    """Read one round in the thesis' raw export format (blocks of ``label,x,y,z`` rows)."""
    path = Path(path)
    positions = np.asarray(positions, dtype=float)
    require(positions.ndim == 1 and positions.size >= 2,
            "the thesis format needs the commanded positions (at least two), e.g. "
            "--positions 0:500:11")
    rows = _open_rows(path)
    # a header line (non-numeric coordinates) is tolerated
    first = rows[0][1]
    if len(first) >= 4:
        try:
            [float(c) for c in first[1:4]]
        except ValueError:
            rows = rows[1:]
    n = positions.size
    require(len(rows) % n == 0,
            f"{path}: {len(rows)} rows is not a whole number of blocks of {n} positions "
            f"(one block of {n} rows per point)")
    n_points = len(rows) // n
    values = np.empty((n_points, n, 3))
    file_labels = []
    for k, (lineno, cells) in enumerate(rows):
        require(len(cells) >= 4, f"{path}:{lineno}: expected label,x,y,z, got {len(cells)} "
                                 f"column(s)")
        values[k // n, k % n] = [_num(path, lineno, c, cells[i + 1])
                                 for i, c in enumerate("xyz")]
        if k % n == 0:
            file_labels.append(cells[0] or f"point{k // n + 1}")
    if labels is None:
        labels = []
        for i, lab in enumerate(file_labels):
            labels.append(lab if lab not in labels else f"{lab}#{i + 1}")
    labels = tuple(labels)
    require(len(labels) == n_points, f"{path}: {n_points} blocks of {n} rows but "
                                     f"{len(labels)} point labels given ({','.join(labels)})")
    require(len(set(labels)) == len(labels), f"point labels must be distinct: {','.join(labels)}")
    return Round(path.name, positions, labels, np.transpose(values, (1, 0, 2)).copy())


def parse_positions(text: str) -> np.ndarray:
    """``start:stop:count`` (inclusive, like ``numpy.linspace``) or a comma list of numbers."""
    text = str(text).strip()
    try:
        if ":" in text:
            a, b, c = text.split(":")
            count = int(c)
            require(count >= 2, f"--positions {text}: count must be at least 2")
            return np.linspace(float(a), float(b), count)
        vals = np.array([float(v) for v in text.split(",") if v.strip() != ""])
    except ValueError:
        raise InputError(f"--positions {text!r}: use start:stop:count or a comma list") from None
    require(vals.size >= 2 and np.all(np.isfinite(vals)),
            f"--positions {text!r}: needs at least two finite numbers")
    return vals


def check_rounds(rounds: list[Round]) -> None:
    """Validate rounds for identification: three or more points, the same positions and the
    same points in every round, finite values.  Raises :class:`InputError`."""
    require(rounds, "no rounds of measurements")
    first = rounds[0]
    for r in rounds:
        require(len(r.labels) >= 3, f"round {r.name}: {len(r.labels)} point(s) "
                                    f"({','.join(r.labels)}); the method needs at least three "
                                    f"non-collinear points")
        require(r.positions.size >= 2, f"round {r.name}: needs at least two positions "
                                       f"(the first is the reference)")
        require(np.all(np.isfinite(r.points)), f"round {r.name}: NaN or infinite coordinates")
        require(set(r.labels) == set(first.labels),
                f"rounds {first.name} and {r.name} measure different points "
                f"({','.join(first.labels)} vs {','.join(r.labels)})")
        a, b = np.sort(first.positions), np.sort(r.positions)
        if a.shape != b.shape or not np.allclose(a, b, rtol=0, atol=1e-9):
            extra = sorted(set(b.tolist()) ^ set(a.tolist()))
            raise InputError(f"rounds {first.name} and {r.name} have different positions "
                             f"(e.g. {extra[0]:g} in one only); every round must visit the "
                             f"same commanded positions")
    _constant_coordinate(rounds)


def _constant_coordinate(rounds: list[Round]) -> None:
    """Refuse a coordinate column (x, y or z) that reads exactly 0 for every point of every
    round: no tracker reads points exactly in a coordinate plane through a whole axis' travel
    (a 2-D export, a zero-filled column).  One line naming the file and the column."""
    pts = np.concatenate([r.points.reshape(-1, 3) for r in rounds])
    for j, c in enumerate("xyz"):
        if pts.shape[0] > 1 and not np.any(pts[:, j]):
            raise InputError(f"{rounds[0].name.rsplit(':', 1)[0]}: column {c} is constant "
                             f"(every value 0 mm): a 2-D export or a zero-filled "
                             f"column? a tracker reads three coordinates of every point")


def example_path(axis: str):
    """Path of the shipped example tracker data of axis X, Y or Z (simulated: three spindle
    points, 11 positions, 4 rounds, 2 um noise, squareness EC0Y 20, EB0Z -15, EA0Z 10 urad;
    generated by ``tests/helpers/tracker_sim.py:example_set``)."""
    from importlib import resources

    require(axis in ("X", "Y", "Z"), f"no example tracker data for axis {axis!r} (X, Y, Z)")
    return resources.files("volerr") / "data" / f"tracker_example_{axis}.csv"
