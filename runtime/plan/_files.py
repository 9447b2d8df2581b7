"""A plan's set-ups as instrument files: columns (reading columns zero inside -- the nominal
distance for a tracking interferometer, from which its reader locates the station --, empty
when written), grouped into files, read back through the instruments' own readers into
:class:`volerr.instruments.Observations` -- the rows ``calibrate`` will build from the filled
files, so that the prediction and the calibration share one observation model.

Files: a ballbar circle is a file of its own (one test, as ballbar software saves it); every
sphere placement of one instrument goes into one file (one tool: one tool-length unknown,
``tool_dz``, shared by the placements), every station of one tracking interferometer into one
file (multilateration needs the stations together).
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..instruments import artifact, ballbar, distances, interferometer, sphere

#: reading columns of each kind: present and empty in a plan file
READINGS = {"ballbar": ("dr_um",), "sphere": ("dx_um", "dy_um", "dz_um"),
            "distances": ("d_mm",), "interferometer": ("deviation_um", "deviation_urad"),
            "artifact": ("x_mm", "y_mm", "z_mm")}
READERS = {"ballbar": ballbar, "sphere": sphere, "distances": distances, "artifact": artifact}
#: label columns (text) of each kind
LABELS = {"ballbar": ("placement",), "sphere": ("placement", "frame"),
          "distances": ("station",), "interferometer": ("placement", "cycle"),
          "artifact": ("placement", "ball")}
#: columns a plan keeps for its NC program and set-up sheet but does not write into the file
#: (an interferometer run gives its line in ``# axis:`` ... header lines)
HIDDEN = {"interferometer": ("placement", "Xp", "Yp", "Zp")}


@dataclass
class PlanFile:
    """One file of a plan: its ``name`` (relative to the plan folder, ``.csv``), ``kind``,
    the instrument index ``inst``, the set-ups in it ``[(SetUp, readings)]`` and its columns."""

    name: str
    kind: str
    inst: int
    setups: list
    columns: dict = field(default_factory=dict)

    @property
    def n(self) -> int:
        return len(next(iter(self.columns.values())))


def columns_of(inst, setups: list) -> dict:
    """Columns of one file holding ``setups`` [(SetUp, readings)], in order, with the
    instrument's declared uncertainties (``u_um``, ``tool_u_um``, ``length_u_um``)."""
    parts = [s.build(m) for s, m in setups]
    cols = {k: np.concatenate([p[k] for p in parts]) for k in parts[0]}
    n = len(next(iter(cols.values())))
    if inst.kind == "interferometer":       # one line a file; u in the header lines
        return cols
    if inst.kind == "artifact":     # readings: the nominal points (the reader poses on them)
        u = artifact.DEFAULT_U_UM if inst.u_um is None else inst.u_um
        cols["probe_u_um"] = np.full(n, float(u))
        cols["u_std_um"] = np.full(n, float(inst.cal_u_um))
        return cols
    for k in READINGS[inst.kind]:
        if inst.kind != "distances":    # a station is located from its nominal distances
            cols[k] = np.zeros(n)
    if inst.kind == "sphere" and inst.frame == "machine":
        cols["frame"] = np.full(n, "machine", dtype=object)
    cols["u_um"] = reading_u(inst, cols, n)
    if inst.kind == "sphere" and inst.tool_u_um is not None:
        cols["tool_u_um"] = np.full(n, float(inst.tool_u_um))
    if inst.kind == "ballbar" and inst.length_u_um is not None:
        cols["length_u_um"] = np.full(n, float(inst.length_u_um))
    return cols


#: the standard uncertainty of one reading the readers assume when a file declares none (um)
DEFAULT_U_UM = {"ballbar": ballbar.DEFAULT_U_UM, "sphere": sphere.DEFAULT_U_UM}


def reading_u(inst, cols: dict, n: int) -> np.ndarray:
    """(n,) um: the ``u_um`` the plan assumes for each reading -- the instrument's ``u_um=``,
    else the reader's default (distances: U0 + K x the nominal distance)."""
    if inst.u_um is not None:
        return np.full(n, float(inst.u_um))
    if inst.kind == "distances":
        return distances.DEFAULT_U0_UM + distances.DEFAULT_K_UM_PER_M * 1e-3 * cols["d_mm"]
    return np.full(n, float(DEFAULT_U_UM[inst.kind]))


def group(instruments: list, chosen: list) -> list:
    """[PlanFile] of the chosen ``[(instrument index, SetUp, readings)]`` (module docstring)."""
    files = []
    by_inst: dict = {}
    for i, s, m in chosen:
        if s.kind == "interferometer":      # whole ISO 230-2 cycles
            m = len(s.build(m)["target_mm"])
        by_inst.setdefault(i, []).append((s, m))
    many = {k: sum(1 for inst in instruments if inst.kind == k) > 1
            for k in READINGS}
    for i, sets in by_inst.items():
        kind = instruments[i].kind
        stem = f"{kind}{i + 1}" if many[kind] else kind
        if kind in ("ballbar", "interferometer"):
            for s, m in sets:
                files.append(PlanFile(f"{stem}_{s.label}.csv", kind, i, [(s, m)]))
        else:
            files.append(PlanFile(f"{stem}.csv", kind, i, sets))
    for f in files:
        f.columns = columns_of(instruments[f.inst], f.setups)
    return files


def observations(model, pf: PlanFile):
    """The file's rows as ``calibrate`` reads them (readings zero)."""
    if pf.kind == "interferometer":
        c, line = pf.columns, pf.setups[0][0].line
        return interferometer.observations(model, line, c["target_mm"], np.zeros(pf.n),
                                           c["direction"], pf.name, cycle=c["cycle"])
    hidden = hidden_columns(pf)
    numbers = {k: np.asarray(v, float) for k, v in pf.columns.items()
               if k not in LABELS[pf.kind] and k not in hidden}
    labels = {k: [str(x) for x in v] for k, v in pf.columns.items() if k in LABELS[pf.kind]}
    text = {k: None for k in labels}
    return READERS[pf.kind].columns_to_observations(numbers, text, labels, model, pf.name)


def csv_text(pf: PlanFile, header: list) -> str:
    """The file as text: ``#`` comment lines ``header``, the columns, reading columns empty
    (6 decimals for mm / deg; positions carry 4)."""
    names = [k for k in pf.columns if k not in hidden_columns(pf)]
    empty = set(READINGS[pf.kind])
    lines = [f"# {h}" for h in header] + [",".join(names)]
    cols = [pf.columns[k] for k in names]
    for i in range(pf.n):
        cells = []
        for k, c in zip(names, cols):
            if k in empty:
                cells.append("")
            elif k in LABELS[pf.kind]:
                cells.append(str(c[i]))
            elif k == "direction":
                cells.append(f"{c[i]:+.0f}" if pf.kind == "interferometer" else f"{c[i]:.0f}")
            else:
                cells.append(_number(float(c[i])))
        lines.append(",".join(cells))
    return "\n".join(lines) + "\n"


def _number(v: float) -> str:
    """Shortest fixed-point text of ``v`` with at most 6 decimals, no negative zero."""
    text = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text


def hidden_columns(pf: PlanFile) -> set:
    """Columns a plan keeps for its NC program and set-up sheet but does not write: an
    interferometer run's axis positions (its header lines give the line), an artifact's
    linear-axis positions (its reader refuses axis columns: the nominal ball positions are
    written as ``x_nom_mm, y_nom_mm, z_nom_mm``)."""
    out = set(HIDDEN.get(pf.kind, ()))
    for s, _ in pf.setups:
        out |= set(s.hidden)
        if s.line is not None:
            out |= {s.line.axis, *s.line.at}
    return out
