"""The CSV reader shared by the instruments' files: UTF-8 (a BOM allowed), comma-separated (or
``;`` / tab by volerr's one delimiter rule, :func:`volerr.fileio.sniff_delimiter`), blank rows
and ``#`` comment rows skipped; numeric columns become float arrays, columns of labels are kept
as text, a column with a bad number in an otherwise numeric column is named with its row."""

from __future__ import annotations

import csv
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require, require_file
from ..fileio import sniff_delimiter


#: what the line of a column with a header and no value in any row says (the files of
#: ``volerr plan`` and ``volerr check plan`` before they are filled)
EMPTY_COLUMN = ("is empty in every row: no readings (a file of 'volerr plan' or 'volerr check "
                "plan' not filled in yet?)")


@dataclass
class Columns:
    """The columns of one file: ``numbers`` name -> float array, ``text`` name -> None (a
    label column) or the one-line message of its first bad cell, ``labels`` name -> the
    stripped cells of every non-numeric column, ``name`` the file name for messages."""

    numbers: dict
    text: dict
    labels: dict = field(default_factory=dict)
    name: str = "data"

    @property
    def n(self) -> int:
        for v in self.numbers.values():
            return len(v)
        for v in self.labels.values():
            return len(v)
        return 0


def _rows(path, header_only: bool = False) -> list:
    """The rows of a CSV file that are neither blank nor ``#`` comments (only the first with
    ``header_only``); InputError (one line) for a missing or unreadable file."""
    p = Path(path)
    require_file(p, f"data file not found: {path}")
    try:
        with open(p, newline="", encoding="utf-8-sig") as fh:
            delim = sniff_delimiter(fh.read(65536))
            fh.seek(0)
            # "".join(r).strip(): some cell holds more than white space (one call a row)
            rows = (r for r in csv.reader(fh, delimiter=delim) if "".join(r).strip()
                    and not r[0].lstrip().startswith("#"))
            return [next(rows, [])] if header_only else list(rows)
    except (UnicodeDecodeError, csv.Error) as exc:
        raise InputError(f"{p.name}: not a readable CSV ({exc})") from None


#: ``# key: value`` comment lines a file may carry above its header row that ``calibrate``
#: uses (``parameters``: the parameters the file was planned for, ``volerr plan --parameters``)
DIRECTIVES = ("parameters",)


def read_directives(path) -> dict:
    """``{key: value}`` of the ``# key: value`` comment lines above the header row whose key is
    one of :data:`DIRECTIVES` (other comments are ignored)."""
    out = {}
    try:
        with open(Path(path), encoding="utf-8-sig") as fh:
            for line in fh:
                text = line.strip()
                if text and not text.startswith("#"):
                    break
                key, sep, value = text.lstrip("#").partition(":")
                if sep and key.strip().lower() in DIRECTIVES and value.strip():
                    out[key.strip().lower()] = value.strip()
    except (OSError, UnicodeDecodeError):
        return {}
    return out


def read_header(path) -> list:
    """The column names of a CSV file (its first row that is neither blank nor a comment),
    without reading the rest: enough to tell an instrument's file by its columns."""
    return [h.strip() for h in _rows(path, header_only=True)[0]]


def read_columns(path) -> Columns:
    """Read a CSV file into :class:`Columns` (InputError, one line, on a defect)."""
    p = Path(path)
    rows = _rows(path)
    require(len(rows) >= 2, f"{p.name}: no data rows")
    header = [h.strip() for h in rows[0]]
    twice = next((h for j, h in enumerate(header) if h in header[:j]), None)
    require(twice is None, f"{p.name}: duplicate column names ({twice!r} appears "
                           f"{header.count(twice)} times; every column once)")
    body = rows[1:]
    for i, r in enumerate(body):
        require(len(r) == len(header), f"{p.name}: row {i + 2} has {len(r)} fields, "
                f"the header {len(header)}")
    cols, text, labels = {}, {}, {}
    for j, h in enumerate(header):
        raw = [r[j].strip() for r in body]
        vals, bad = _floats(raw)
        if body and not any(raw):      # a header over nothing: readings not filled in
            text[h] = f"{p.name}: column {h} {EMPTY_COLUMN}"
            labels[h] = raw
            continue
        if bad is not None and all(_not_number(s) for s in raw):
            comma = next((s for s in raw if re.fullmatch(r"[+-]?\d*,\d+([eE][+-]?\d+)?", s)),
                         None)
            require(comma is None, f"{p.name}: column {h}: {comma!r} has a decimal comma; "
                    f"write numbers with a decimal point")
            text[h] = None  # a label column (text)
            labels[h] = raw
            continue
        if bad is not None:
            text[h] = f"{p.name}: column {h} row {bad + 2}: {raw[bad]!r} is not a number"
            labels[h] = raw
            continue
        cols[h] = np.asarray(vals)
    return Columns(cols, text, labels, p.name)


def _floats(raw: list) -> tuple[list, int | None]:
    """(values, bad): ``float`` of every text of ``raw`` (nan where it is not a number) and
    the index of the first that is not (None: all are); one comprehension when all are."""
    try:
        return [float(s) for s in raw], None
    except ValueError:
        pass
    vals, bad = [], None
    for i, s in enumerate(raw):
        try:
            vals.append(float(s))
        except ValueError:
            bad = bad if bad is not None else i
            vals.append(math.nan)
    return vals, bad


def _not_number(s: str) -> bool:
    try:
        float(s)
        return False
    except ValueError:
        return True


