"""``volerr ballbar evaluate``: the ISO 230-4 evaluation of ballbar files and the diagnosis in
ISO 230-1 parameters (:mod:`volerr.ballbar.iso230_4`, :mod:`volerr.ballbar.diagnosis`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .. import instruments
from ..errors import require
from ..instruments import ballbar as reader
from ..machine.model import load
from ..results import ResultMixin
from . import diagnosis, iso230_4

#: the layout standing in for a Cartesian machine when none is given (its travel not enforced)
DEFAULT_LAYOUT = "MB1"


@dataclass(repr=False)
class Evaluation(ResultMixin):
    """``data`` the JSON report; ``traces`` the ISO 230-4 traces (for the polar plot).

    :meth:`summary` is what ``volerr ballbar evaluate`` prints; :meth:`table` the diagnosed
    parameters with their standard uncertainties (k = 1); :meth:`figures` the polar plot."""

    data: dict
    traces: list
    results: list
    quality: object = None     # the diagnosis fit's residual rule (volerr.fit_quality)

    def summary(self) -> str:
        """G, H and F per trace (um) and the diagnosis (value +- u, k = 1)."""
        out = []
        for r in self.data["traces"]:
            h = f", H {r['H_um']:.3f} um" if "H_um" in r else ""
            out.append(f"{r['file']} {r['placement']} {r['plane']} {r['direction']}: G "
                       f"{r['G_um']:.3f} um{h}, F {r['F_min_um']:.3f} .. {r['F_max_um']:.3f} um")
        for d in self.data["diagnosis"]:
            out.append(f"  {d['parameter']} = {d['value']:.4g} +- {d['std']:.2g} {d['unit']} "
                       f"(u, k = 1)")
        if self.data.get("diagnosis_note"):
            out.append(f"  no diagnosis: {self.data['diagnosis_note']}")
        if self.quality is not None:
            out.append("  diagnosis " + self.quality.line())
        return "\n".join(out)

    def _rows(self) -> list:
        from ..results import Row

        out = []
        for r in self.data["traces"]:      # ISO 230-4: G, F per trace; H once per placement
            for q in ("G", "F_max", "F_min") + (("H",) if r.get("direction") == "ccw" else ()):
                if f"{q}_um" in r:
                    out.append(Row(iso230_4.row_name(q, r), r[f"{q}_um"], r.get(f"u_{q}_um"),
                                   "um", 1.0))
        return out + [Row(d["parameter"], d["value"], d["std"], d["unit"], 1.0)
                      for d in self.data["diagnosis"]]

    def figures(self) -> dict:
        """``{"polar": Figure}``: the traces' polar plot."""
        from .plots import polar_figure

        return {"polar": polar_figure(self.traces, self.results)}

    def write_html(self, path, inputs=()):
        """The report page (polar plot, ISO 230-4 table, diagnosis)."""
        from .report import write_html

        return write_html(path, self, inputs=inputs)

    def write_json(self, path, inputs=()) -> Path:
        from ..fileio import json_text, write_text

        return write_text(path, json_text(self.data), inputs=list(inputs))

    def png(self) -> bytes:
        """The ``--plot`` PNG: the traces' polar plot (:meth:`figures`)."""
        from .plots import polar_png

        return polar_png(self.traces, self.results)


def judge(data: dict, quality, accept: bool, where: str):
    """The residual rule (:mod:`volerr.fit_quality`) on the diagnosis fit, applied to the
    JSON ``data`` before the result is built; returns the verdict (forced when accepted).
    The ISO 230-4 values (G, H, F) do not depend on any model and are always given; a
    diagnosis whose fit is far above the readings' declared uncertainty is withheld
    (``diagnosis`` empty, ``diagnosis_note`` says why, ``fit`` verdict ``refused``) unless
    ``accept`` (``--accept-residual``: given, marked forced in every output)."""
    from ..errors import InputError
    from ..fit_quality import gate

    try:
        return gate(data, quality, accept, where)
    except InputError as e:
        data["diagnosis"] = []
        data["diagnosis_note"] = (f"withheld: {str(e).split(': ', 1)[1]}"
                                  .replace("nothing written", "diagnosis withheld")
                                  .replace("writes it", "gives it"))
        data["fit"] = quality.to_dict()
        return quality


def evaluate(files, layout=None, diagnose: bool = True, accept_residual: bool = False,
             where: str = "ballbar evaluate") -> Evaluation:
    """Evaluate ballbar ``files`` (paths); ``layout`` None: :data:`DEFAULT_LAYOUT` for
    X, Y, Z traces (the travel of the generic layout is not enforced).  The diagnosis is
    judged by its residual (:func:`judge`; ``where`` names the run in its note)."""
    model = load(layout or DEFAULT_LAYOUT)
    instruments.refuse_duplicates(files)
    parts, trs = [], []
    for path in files:
        obs = reader.read(path, model, check_travel=layout is not None)
        obs.files = (instruments.FileInfo(Path(path).name, reader.KIND, "um", 1),)
        parts.append(obs)
        trs += iso230_4.traces(obs, model)
    results = iso230_4.evaluate_all(trs)
    gum = iso230_4.budgets(trs, results)
    data = {"layout": model.name, "traces": results, "diagnosis": [], "budgets": gum}
    if diagnose:
        stacked = instruments.stack(parts)
        planes = list(dict.fromkeys(t.plane for t in trs))
        swept = [a for a in model.rotary_axes if np.ptp(stacked.positions[a]) > 1.0]
        data["diagnosis"], note, quality = diagnosis.diagnose_fit(
            model, stacked, [] if swept else planes, swept)
        if note:
            data["diagnosis_note"] = note
        data["budgets"] = {**gum, **{e["parameter"]: e.pop("budget")
                                     for e in data["diagnosis"] if "budget" in e}}
        data["fit"] = quality.to_dict()
        quality = judge(data, quality, accept_residual, where)
        return Evaluation(data, trs, results, quality)
    return Evaluation(data, trs, results)


def check_layout_for(files, layout) -> None:
    """A trace with rotary-axis columns needs its layout (the default is Cartesian)."""
    if layout:
        return
    from ..instruments._csv import read_columns

    for f in files:
        cols = read_columns(f)
        names = {n.upper() for n in list(cols.numbers) + list(cols.text)}
        rot = sorted(names & {"A", "B", "C", "A_DEG", "B_DEG", "C_DEG"})
        require(not rot, f"{Path(f).name}: rotary axis column {rot[0] if rot else ''}: give "
                         f"the machine's layout (--layout)")
