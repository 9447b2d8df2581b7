"""Executing a plan on volerr's own first-order model (the demo's simulator): the plan files'
empty reading columns filled with the instruments' documented reading models, planted errors,
set-up offsets and Gaussian noise of the files' ``u_um`` (else the instrument's default):

* ballbar ``dr = u . (e - dp) + dL`` (``u`` the bar direction, ``dp`` the pivot offset, ``dL``
  the bar-length offset of the placement);
* sphere ``d = t + e + dz_tool k_tool - (c + dc)`` (``k_tool`` the tool axis, ``dc`` the
  centre offset of the placement, ``dz_tool`` the tool-length error of the file);
* distances ``d = |t + e - (s + ds)| + dead`` per station.

Not an independent check (the tests use ``tests/helpers``' exact chain): it shows what a plan
gives when the machine is the model.  Units: errors mm / rad inside, readings as the files'
columns (um, mm).
"""

from __future__ import annotations

import csv
import io
from pathlib import Path

import numpy as np

from ..errors import require
from ..instruments._csv import read_columns

DEFAULT_U_UM = {"ballbar": 0.5, "sphere": 1.0}


def execute(path, model, errors: dict, rng, setup_um: float = 20.0,
            tool_dz_um: float = 0.5, dead_mm: float = 0.2) -> None:
    """Fill the plan file ``path`` in place (module docstring); ``errors`` {name: mm / rad}."""
    text = Path(path).read_text(encoding="utf-8")
    c = read_columns(path)
    cols, labels = c.numbers, c.labels
    pos = {a: cols[a] for a in model.axes}
    probe = np.column_stack([cols[k] for k in ("Xp", "Yp", "Zp")])
    n = len(probe)
    t = model.nominal_position(pos, probe)
    e = model.volumetric_error(pos, errors, probe=probe)
    u = cols.get("u_um")
    if "pivot_x" in cols:
        values = _ballbar(cols, labels, t, e, rng, setup_um, u)
    elif "sphere_x" in cols:
        k = model.tool_axis(pos)
        d = t + e + tool_dz_um * 1e-3 * k - _offsets(cols, labels["placement"], "sphere_",
                                                    rng, setup_um)
        noise = rng.normal(0, 1, (n, 3)) * (DEFAULT_U_UM["sphere"] if u is None else u[:, None])
        d = 1e3 * d + noise
        values = {"dx_um": d[:, 0], "dy_um": d[:, 1], "dz_um": d[:, 2]}
    else:
        s = _offsets(cols, labels["station"], "station_", rng, setup_um)
        dist = np.linalg.norm(t + e - s, axis=1)
        sig = (0.3 + 0.3e-3 * dist) if u is None else u
        dead = {k: dead_mm + rng.normal(0, 0.05) for k in sorted(set(labels["station"]))}
        values = {"d_mm": dist + np.array([dead[k] for k in labels["station"]])
                  + 1e-3 * sig * rng.normal(0, 1, n)}
    with open(path, "w", encoding="utf-8") as fh:
        fh.write(fill_text(text, values))


def _ballbar(cols, labels, t, e, rng, setup_um, u) -> dict:
    pivot = np.column_stack([cols[k] for k in ("pivot_x", "pivot_y", "pivot_z")])
    v = (t - pivot) / np.linalg.norm(t - pivot, axis=1)[:, None]
    dp = _offsets(cols, labels["placement"], None, rng, setup_um)
    dl = {k: rng.normal(0, setup_um * 1e-3) for k in sorted(set(labels["placement"]))}
    dr = np.sum(v * (e - dp), axis=1) + np.array([dl[k] for k in labels["placement"]])
    noise = rng.normal(0, 1, len(dr)) * (DEFAULT_U_UM["ballbar"] if u is None else u)
    return {"dr_um": 1e3 * dr + noise}


def _offsets(cols, label, prefix, rng, setup_um) -> np.ndarray:
    """(n, 3) nominal position (``prefix`` x/y/z columns; zero when None) plus a random offset
    per label (mm)."""
    n = len(label)
    base = (np.zeros((n, 3)) if prefix is None else
            np.column_stack([cols[prefix + a] for a in "xyz"]))
    off = {k: rng.normal(0, setup_um * 1e-3, 3) for k in sorted(set(label))}
    return base + np.array([off[k] for k in label])


def fill_text(text: str, values: dict) -> str:
    """The file text with the columns ``values`` {name: (n,)} written into its data rows
    (comment lines kept)."""
    lines = text.splitlines()
    data = [i for i, ln in enumerate(lines) if ln.strip() and not ln.startswith("#")]
    header = next(csv.reader([lines[data[0]]]))
    idx = {k: header.index(k) for k in values}
    rows = list(csv.reader(lines[i] for i in data[1:]))
    require(all(len(v) == len(rows) for v in values.values()), "plan file and readings "
                                                                "differ in length")
    for r, row in enumerate(rows):
        for k, j in idx.items():
            row[j] = f"{float(values[k][r]):.{8 if k.endswith('_mm') else 5}f}"
        buf = io.StringIO()
        csv.writer(buf, lineterminator="").writerow(row)
        lines[data[1 + r]] = buf.getvalue()
    return "\n".join(lines) + "\n"
