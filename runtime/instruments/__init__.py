"""Instruments: each reads its measurement file into :class:`Observations` (rows of the
layout's linear model plus its set-up columns), the one type the estimator
(:mod:`volerr.estimate`), ``volerr calibrate`` and ``volerr loop`` work on.

One module per instrument kind (``deviations``, ``ballbar``, ``sphere`` ...), each with ``KIND``,
``detect(column names) -> bool`` and ``read(path, model) -> Observations``; they are found
here by their module, so a new instrument is a new module and a section of the formats.
"""

from __future__ import annotations

import importlib
import pkgutil
from dataclasses import replace
from pathlib import Path

from ..errors import require
from ._csv import read_directives
from .observations import FileInfo, Observations, Setup, stack

__all__ = ["FileInfo", "Observations", "Setup", "kinds", "read", "read_files", "read_parts",
           "stack"]

#: the fallback kind: a file of 3-D deviations
FALLBACK = "deviations"


def kinds() -> dict:
    """Instrument kind -> its module."""
    out = {}
    for info in pkgutil.iter_modules(__path__):
        if info.name.startswith("_") or info.name == "observations":
            continue
        mod = importlib.import_module(f"{__name__}.{info.name}")
        if hasattr(mod, "KIND") and hasattr(mod, "read"):
            out[mod.KIND] = mod
    return out


def split_spec(spec: str) -> tuple[str | None, str]:
    """``KIND:FILE`` -> (KIND, FILE); a plain path -> (None, path)."""
    text = str(spec)
    head, sep, rest = text.partition(":")
    if sep and head in kinds() and not Path(text).exists():
        return head, rest
    return None, text


#: the columns of laser-tracker three-point data (docs/formats.md "tracker"), the input of
#: ``volerr identify``, not of an instrument here: its ``position`` column would make it read
#: as an interferometer run asking for an ``# axis`` line, the wrong mistake named
TRACKER_COLUMNS = frozenset({"round", "point", "position", "x", "y", "z"})


def detect(path) -> str:
    """The instrument kind of a file, from its header (InputError when it cannot tell; a
    laser-tracker file, :data:`TRACKER_COLUMNS`, is refused naming ``volerr identify``)."""
    from ._csv import read_header

    names = read_header(path)       # the columns alone: the instrument reads the file once
    require(not TRACKER_COLUMNS <= {n.strip().lower() for n in names},
            f"{Path(path).name}: laser-tracker three-point data (round, point, position, x, y, "
            f"z), not an instrument file of calibrate or loop: identify it with 'volerr "
            f"identify LAYOUT --axis A {Path(path).name}'")
    hits = [k for k, m in kinds().items() if k != FALLBACK and hasattr(m, "detect")
            and m.detect(names)]
    require(len(hits) <= 1, f"{Path(path).name}: columns of several instruments "
            f"({', '.join(hits)}); name the kind as KIND:FILE")
    return hits[0] if hits else FALLBACK


def read(spec, model) -> Observations:
    """One file (``KIND:FILE`` or a path, its kind detected) -> :class:`Observations`."""
    kind, path = split_spec(spec)
    kind = kind or detect(path)
    obs = kinds()[kind].read(path, model)
    if not obs.files:
        obs.files = (FileInfo(Path(path).name, kind),)
    declared = read_directives(path).get("parameters")
    if declared:
        obs.files = tuple(replace(f, parameters=declared) for f in obs.files)
    return obs


def refuse_duplicates(paths) -> None:
    """Refuse (InputError, one line) the same file given twice: the same path, or two files
    with the same bytes (a copy would count its readings twice and halve every standard
    uncertainty it contributes)."""
    import hashlib

    seen: dict = {}
    for p in paths:
        path = Path(p)
        try:
            key = hashlib.sha256(path.read_bytes()).hexdigest() if path.is_file() \
                else str(path.resolve())
        except OSError:
            key = str(path.resolve())
        first = seen.setdefault(key, path)
        same = first.resolve() == path.resolve()
        require(first is path, f"{path.name}: the same file given twice" if same else
                f"{path.name} and {first.name} hold the same readings (the same file given "
                f"twice)")


def read_parts(specs, model) -> list:
    """Several files, each as its own :class:`Observations` (the same file twice refused:
    :func:`refuse_duplicates`)."""
    from . import distances

    refuse_duplicates([split_spec(s)[1] for s in specs])
    parts = [read(s, model) for s in specs]
    distances.require_stations(parts)
    return parts


def read_files(specs, model) -> Observations:
    """Several files, one campaign (each file its own set-up)."""
    return stack(read_parts(specs, model))
