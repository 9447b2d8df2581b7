"""ISO 230-3 evaluation of a thermal drift test: drift per channel, tilts, stages, plots.

ISO 230-3:2020 (*Test code for machine tools -- Part 3: Determination of thermal effects*)
defines drift tests in which the relative displacement between the tool side and the workpiece
side is logged at one position while heat is put in: the environmental temperature variation
error (ETVE) test (clause 5: the machine idle, the room's temperature varying), the thermal
distortion caused by a rotating spindle (clause 6: a speed programme of runs and stops, five
sensors round a test mandrel -- two radial pairs at two heights, one axial), by moving linear
axes (clause 7) and by rotary motion of components (clause 8).  Its evaluation, which this
module implements for a run of any of them (a ``drift`` file, :mod:`volerr.instruments.drift`):

1. **drift of each channel** (the evaluation of clauses 5, 6 and 7: the displacement against time
   from the start of the test): ``d(t) = reading(t) - reading(t_0)`` um, its largest and
   smallest value (``max_um``, ``min_um``, with their times) and its range
   ``range_um = max - min`` -- in the ETVE test the ETVE of that direction; in the spindle
   test the thermal drift of that direction over the test;
2. **tilts** (clause 6: the angular deviations of the spindle from two sensors of one
   direction at two heights ``z1 < z2`` on the mandrel): ``(s(z2) - s(z1)) / (z2 - z1)``,
   ``s`` the channel's drift along the positive axis (a ``-X`` channel's sign turned), um/mm =
   1000 urad; a pair along X gives the tilt about +Y (``+ds_X/dz``), a pair along Y the tilt
   about +X (``-ds_Y/dz``): the tool side's rotation relative to the workpiece side, right
   hand;
3. **per stage of the programme** (clause 6: runs at constant speed, a spindle stop, a speed
   spectrum): a stage is a maximal stretch of readings whose stage value (``S_rpm``, or a
   declared column: a feed for clause 7) stays within :data:`STAGE_TOLERANCE` of the largest
   magnitude of the column of the value at the stage's first reading; per stage each channel's
   and tilt's drift at its start and end, its change and its range within the stage;
4. the logged temperatures' ranges beside them (clause 5: the temperature of the room and
   of the machine recorded with the displacements).

Units: time s (plots in h), displacements um, tilts urad, temperatures degC.  Sign: as the
sensor reads the tool side relative to the workpiece side (the drift file's convention).
The evaluation reads no tolerance: ISO 230-3 leaves the acceptance values to the machine's
test code; the range is the figure a tolerance applies to.  Clause numbers are those of the
2020 edition's scope (clause 7 the linear axes); the sub-clauses are not cited here (the text of
the standard was not at hand: the evaluation follows the drift test procedure the standard
refers to, ISO/TR 16015:2003, A.4.2).
"""

from __future__ import annotations

import html
from dataclasses import dataclass, field

import numpy as np

from ..certificate import html_table
from ..plotstyle import embedded_img, figure, label, png, styled
from ..report.page import document
from ..units import SENSOR_TILT as _TILT

STANDARD = "ISO 230-3:2020"
#: a stage ends where the stage value leaves its first value by more than this fraction of the
#: column's largest magnitude (a measured speed wanders by less; a speed step is far more)
STAGE_TOLERANCE = 0.02
#: unit vectors' axis and sign of the channel directions
_AXIS = {"X": ("X", 1.0), "-X": ("X", -1.0), "Y": ("Y", 1.0), "-Y": ("Y", -1.0),
         "Z": ("Z", 1.0), "-Z": ("Z", -1.0)}


@dataclass
class Extremes:
    """Largest and smallest value of a drift series and their times; ``range`` = max - min."""

    max: float
    min: float
    t_max_s: float
    t_min_s: float

    @property
    def range(self) -> float:
        return self.max - self.min

    @classmethod
    def of(cls, t: np.ndarray, v: np.ndarray) -> "Extremes":
        i, j = int(np.argmax(v)), int(np.argmin(v))      # first occurrence: a stated tie rule
        return cls(float(v[i]), float(v[j]), float(t[i]), float(t[j]))


@dataclass
class Tilt:
    """A tilt from two channels of one direction at two heights: ``channels`` (lower,
    upper), ``about`` the axis, ``lever_mm`` z2 - z1, ``series`` (N,) urad from the start."""

    name: str
    channels: tuple
    about: str
    lever_mm: float
    series: np.ndarray


@dataclass
class Stage:
    """One stage of the programme: readings ``start`` .. ``stop - 1``, its ``value`` (the
    stage column at the first reading, e.g. rpm)."""

    index: int
    start: int
    stop: int
    value: float


@dataclass
class DriftEvaluation:
    """The ISO 230-3 evaluation of one drift run (module docstring).  ``drift`` label -> (N,)
    um from the first reading; ``tilts``; ``stages`` with ``stage_column``; ``test`` the
    clause the run's heat input points to."""

    name: str
    t_s: np.ndarray
    drift: dict
    directions: dict
    heights: dict
    tilts: list
    stages: list
    stage_column: str | None
    inputs: dict
    test: str
    notes: list = field(default_factory=list)

    def channel_extremes(self) -> dict:
        return {k: Extremes.of(self.t_s, v) for k, v in self.drift.items()}

    def reading_u(self) -> dict:
        """label -> (noise, resolution) of a channel's readings, um: the noise (Type A) from
        the second differences of the series, s^2 = sum (x_i+1 - 2 x_i + x_i-1)^2 /
        (6 (N - 2)) (a drift that is locally linear over two intervals cancels), and the
        resolution as the readings are recorded (the last decimal that varies)."""
        out = {}
        for k, v in self.drift.items():
            d2 = np.diff(v, 2)
            noise = float(np.sqrt(np.sum(d2 ** 2) / (6 * len(d2)))) if len(d2) else 0.0
            out[k] = (noise, _resolution(v))
        return out

    def budgets(self, prefix: str = "") -> dict:
        """The GUM budget (:mod:`volerr.report.budget`) of every drift range, max and min
        (rows ``prefix + label:range`` ...) and every tilt's: each is a difference of two
        readings of a channel (a range: the largest and smallest; max and min: against the
        first reading), so each reading source enters with sensitivity sqrt(2) -- the noise
        and the resolution (rectangular, r / sqrt(12)); a tilt (s2 - s1) / lever adds both
        channels with sensitivity sqrt(2) / lever (urad per um: 1000 / lever_mm)."""
        from ..report.budget import budget, source

        ru = self.reading_u()
        out = {}

        def sources(k, c):
            n, r = ru[k]
            return [source(f"{k}: noise of the readings (Type A, second differences)", n,
                           "um", c),
                    source(f"{k}: resolution {r:g} \u00b5m as recorded (rectangular)",
                           r / np.sqrt(12.0), "um", c)]

        series = [(k, sources(k, np.sqrt(2.0)), "um") for k in self.drift]
        series += [(tl.name, sources(tl.channels[0], np.sqrt(2.0) * 1e3 / tl.lever_mm)
                    + sources(tl.channels[1], np.sqrt(2.0) * 1e3 / tl.lever_mm), "urad")
                   for tl in self.tilts]
        for k, srcs, unit in series:
            for what in ("range", "max", "min"):
                row = f"{prefix}{k}:{what}"
                out[row] = budget(row, unit, srcs, 2.0, notes=[NOT_IN_BUDGET] if what ==
                                  "range" else ())
        return out

    def tilt_extremes(self) -> dict:
        return {tl.name: Extremes.of(self.t_s, tl.series) for tl in self.tilts}

    def to_dict(self) -> dict:
        """The JSON of ``volerr iso230-3``: ``channels``, ``tilts``, ``stages`` (um, urad)."""
        chans = {k: {"direction": self.directions[k], "z_mm": self.heights[k],
                     **_extremes_dict(e, "um")} for k, e in self.channel_extremes().items()}
        tilts = {tl.name: {"channels": list(tl.channels), "about": tl.about,
                           "lever_mm": tl.lever_mm, **_extremes_dict(e, "urad")}
                 for tl, e in zip(self.tilts, self.tilt_extremes().values())}
        temps = {k: {"min_C": float(np.min(v)), "max_C": float(np.max(v)),
                     "range_K": float(np.ptp(v))} for k, v in self.inputs.items()
                 if k.startswith("T_")}
        return {"standard": STANDARD, "file": self.name, "test": self.test,
                "n_readings": int(len(self.t_s)),
                "duration_s": float(self.t_s[-1] - self.t_s[0]), "channels": chans,
                "tilts": tilts, "stage_column": self.stage_column,
                "stages": [self._stage_dict(s) for s in self.stages],
                "temperatures": temps, "notes": list(self.notes),
                "budgets": self.budgets()}

    def _stage_dict(self, s: Stage) -> dict:
        sl = slice(s.start, s.stop)
        t = self.t_s[sl]
        series = {**{k: (v, "um") for k, v in self.drift.items()},
                  **{tl.name: (tl.series, "urad") for tl in self.tilts}}
        out = {}
        for k, (v, unit) in series.items():
            e = Extremes.of(t, v[sl])
            out[k] = {f"start_{unit}": float(v[s.start]), f"end_{unit}": float(v[s.stop - 1]),
                      f"change_{unit}": float(v[s.stop - 1] - v[s.start]),
                      **_extremes_dict(e, unit)}
        return {"index": s.index, "t_start_s": float(t[0]), "t_end_s": float(t[-1]),
                "value": s.value, "channels": {k: out[k] for k in self.drift},
                "tilts": {tl.name: out[tl.name] for tl in self.tilts}}

    def summary_lines(self) -> list:
        """The table the command prints: a line per channel and tilt."""
        d = self.t_s[-1] - self.t_s[0]
        lines = [f"{self.name}: {STANDARD} {self.test}; {len(self.t_s)} readings over "
                 f"{d / 3600:.2f} h, {len(self.stages)} stage(s)"
                 f"{' of ' + self.stage_column if self.stage_column else ''}",
                 f"  {'channel':10s} {'dir':>4s} {'range':>9s} {'max':>9s} {'min':>9s}"]
        for k, e in self.channel_extremes().items():
            lines.append(f"  {k:10s} {self.directions[k]:>4s} {e.range:9.2f} {e.max:9.2f} "
                         f"{e.min:9.2f}  um")
        for tl, e in zip(self.tilts, self.tilt_extremes().values()):
            lines.append(f"  {tl.name:10s} {'a' + tl.about:>4s} {e.range:9.1f} {e.max:9.1f} "
                         f"{e.min:9.1f}  urad (tilt about {tl.about})")
        return lines

    def __repr__(self) -> str:
        return (f"DriftEvaluation({self.name!r}: {len(self.drift)} channels, {len(self.tilts)} "
                f"tilts, {len(self.stages)} stages)")


#: what the budgets of the drift leave out (not given to volerr)
NOT_IN_BUDGET = ("Not included (not given to volerr): the sensors' calibration (scale) and "
                 "the thermal expansion of the sensor fixture and the test mandrel.")


def _resolution(v: np.ndarray) -> float:
    """The resolution the readings ``v`` (um) are recorded with: 10^-k for the smallest k
    (0 .. 6) at which every value is a whole multiple (to 1e-6 of a step and the float's
    rounding), else 1e-6."""
    for k in range(7):
        x = np.asarray(v) * 10.0 ** k
        if np.all(np.abs(x - np.round(x)) <= 1e-6 + 1e-9 * np.abs(x)):
            return 10.0 ** -k
    return 1e-6


def _extremes_dict(e: Extremes, unit: str) -> dict:
    return {f"range_{unit}": e.range, f"max_{unit}": e.max, f"min_{unit}": e.min,
            "t_max_s": e.t_max_s, "t_min_s": e.t_min_s}


def tilts_of(drift: dict, directions: dict, heights: dict) -> list:
    """Every pair of channels along X (or along Y) at two different heights -> :class:`Tilt`
    (lower channel first; pairs in the channels' order)."""
    out = []
    labels = [k for k in drift if directions[k] in _AXIS and heights[k] is not None]
    for i, a in enumerate(labels):
        for b in labels[i + 1:]:
            (ax_a, sa), (ax_b, sb) = _AXIS[directions[a]], _AXIS[directions[b]]
            if ax_a != ax_b or ax_a not in _TILT or heights[a] == heights[b]:
                continue
            lo, hi = (a, b) if heights[a] < heights[b] else (b, a)
            s_lo = drift[lo] * _AXIS[directions[lo]][1]
            s_hi = drift[hi] * _AXIS[directions[hi]][1]
            about, sign = _TILT[ax_a]
            lever = float(heights[hi] - heights[lo])
            out.append(Tilt(f"{lo}-{hi}", (lo, hi), about, lever,
                            sign * (s_hi - s_lo) / lever * 1e3))     # um/mm -> urad
    return out


def stages_of(values: np.ndarray | None) -> list:
    """The stages of a programme column (module docstring, step 3); one stage without one."""
    if values is None:
        return []
    v = np.asarray(values, dtype=float)
    tol = STAGE_TOLERANCE * max(float(np.max(np.abs(v))), 1e-300)
    out, start = [], 0
    for k in range(1, len(v) + 1):
        if k == len(v) or abs(v[k] - v[start]) > tol:
            out.append(Stage(len(out) + 1, start, k, float(v[start])))
            start = k
    return out


def _test_kind(inputs: dict, stage_column: str | None) -> str:
    """The clause the heat input points to: a spindle speed that turns -> clause 6, a declared
    programme column other than the speed -> clause 7 (moving linear axes), none -> clause 5."""
    speed = inputs.get("S_rpm")
    if stage_column and stage_column != "S_rpm":
        return "thermal distortion caused by moving linear axes (clause 7)"
    if speed is not None and np.any(np.asarray(speed) != 0):
        return "thermal distortion caused by a rotating spindle (clause 6)"
    return "environmental temperature variation error, ETVE (clause 5)"


def evaluate(run, stage_column: str | None = None) -> DriftEvaluation:
    """Evaluate one drift run (a :class:`volerr.instruments.drift.DriftRun`: ``t_s``,
    ``channels`` um, ``directions``, ``heights`` mm, ``inputs``) by ISO 230-3.

    ``stage_column``: the programme column the stages follow (default ``stage`` when the run
    logs one, else ``S_rpm``, else no stages but the whole run)."""
    from ..errors import require

    t = np.asarray(run.t_s, dtype=float)
    drift = {k: np.asarray(v, dtype=float) - float(v[0]) for k, v in run.channels.items()}
    col = stage_column or next((c for c in ("stage", "S_rpm") if c in run.inputs), None)
    require(col is None or col in run.inputs, f"{run.name}: --stage-column {col}: no such "
            f"logged column ({', '.join(run.inputs) or 'none'})")
    stages = stages_of(run.inputs[col]) if col else [Stage(1, 0, len(t), float("nan"))]
    notes = []
    if not any(d in _AXIS for d in run.directions.values()):
        notes.append("no channel has a direction ('# channel d_<label>: DIR'): drifts are "
                     "reported per channel, no tilt")
    elif not tilts_of(drift, run.directions, run.heights):
        notes.append("no two channels of one radial direction at two heights ('at z='): no "
                     "tilt")
    return DriftEvaluation(run.name, t, drift, dict(run.directions), dict(run.heights),
                           tilts_of(drift, run.directions, run.heights), stages,
                           col, dict(run.inputs), _test_kind(run.inputs, col), notes)


def report_dict(evaluations: list) -> dict:
    """One run: its :meth:`DriftEvaluation.to_dict`; several: ``{"runs": [...]}``."""
    docs = [ev.to_dict() for ev in evaluations]
    if len(docs) > 1:       # the rows are named with the run there (Iso230_3._rows)
        for d, ev in zip(docs, evaluations):
            d["budgets"] = ev.budgets(f"{ev.name}:")
    return docs[0] if len(docs) == 1 else {"standard": STANDARD, "runs": docs}


@styled
def plot(ev: DriftEvaluation) -> bytes:
    """:func:`drift_figure` of ``ev`` as PNG bytes."""
    return png(drift_figure(ev))


@styled
def drift_figure(ev: DriftEvaluation):
    """Drift of every channel against time (h), the tilts below, then the spindle speed (or
    the stage column) and the temperatures: the figures of ISO 230-3 (displacement against
    time with the heat input beside it).  A matplotlib figure."""
    panels = 2 + bool(ev.tilts) + bool(ev.stage_column)
    fig, axes = figure(panels, 1, height=2.3 * panels + 0.6, sharex=True)
    th = (ev.t_s - ev.t_s[0]) / 3600.0
    ax = axes[0]
    for k, v in ev.drift.items():
        ax.plot(th, v, lw=0.9, label=f"{k} ({ev.directions[k]})")
    ax.set_ylabel(label("drift", "um"))
    _legend(ax)
    ax.set_title(f"{ev.name}: {STANDARD}, {ev.test}")
    i = 1
    if ev.tilts:
        for tl in ev.tilts:
            axes[i].plot(th, tl.series, lw=0.9, label=f"{tl.name} (about {tl.about})")
        axes[i].set_ylabel(label("tilt", "urad"))
        _legend(axes[i])
        i += 1
    if ev.stage_column:
        axes[i].plot(th, ev.inputs[ev.stage_column], lw=0.9, color="k")
        axes[i].set_ylabel("spindle speed / rpm" if ev.stage_column == "S_rpm"
                           else ev.stage_column)
        i += 1
    temps = [k for k in ev.inputs if k.startswith("T_")]
    for k in temps:
        axes[i].plot(th, ev.inputs[k], lw=0.7, label=k)
    axes[i].set_ylabel(label("temperature", "degC"))
    if temps:
        _legend(axes[i], ncols=1 + len(temps) // 9)
    axes[-1].set_xlabel(label("time from the start", "h"))
    return fig


def _legend(ax, ncols: int = 1) -> None:
    """A legend beside the panel (never over the data)."""
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), ncols=ncols, fontsize=9,
              borderaxespad=0.0)


def _rows(d: dict, unit: str) -> str:
    e = html.escape
    return "".join(
        f"<tr><th class='l'>{e(k)}</th><td>{e(str(v.get('direction', v.get('about', ''))))}</td>"
        f"<td>{v[f'range_{unit}']:.2f}</td><td>{v[f'max_{unit}']:.2f}</td>"
        f"<td>{v[f'min_{unit}']:.2f}</td><td>{v['t_max_s'] / 3600:.2f}</td>"
        f"<td>{v['t_min_s'] / 3600:.2f}</td></tr>" for k, v in d.items())


def _stage_rows(doc: dict) -> str:
    keys = list(doc["channels"]) + list(doc["tilts"])
    head = "".join(f"<th>{html.escape(k)}</th>" for k in keys)
    rows = []
    for s in doc["stages"]:
        vals = {**{k: (v["change_um"], v["range_um"]) for k, v in s["channels"].items()},
                **{k: (v["change_urad"], v["range_urad"]) for k, v in s["tilts"].items()}}
        cells = "".join(f"<td>{vals[k][0]:+.2f} / {vals[k][1]:.2f}</td>" for k in keys)
        rows.append(f"<tr><td>{s['index']}</td><td>{s['t_start_s'] / 3600:.2f} &ndash; "
                    f"{s['t_end_s'] / 3600:.2f}</td><td>{s['value']:g}</td>{cells}</tr>")
    return (f"<table><tr><th>stage</th><th>time / h</th><th>{html.escape(str(doc['stage_column']))}"
            f"</th>{head}</tr>{''.join(rows)}</table>")


def _run_html(ev: DriftEvaluation, img: bytes | None, head: str) -> str:
    """The part of the report of one run."""
    e = html.escape
    doc = ev.to_dict()
    temps = "".join(f"<tr><th class='l'>{e(k)}</th><td>{v['min_C']:.2f}</td>"
                    f"<td>{v['max_C']:.2f}</td><td>{v['range_K']:.2f}</td></tr>"
                    for k, v in doc["temperatures"].items())
    tilts = (f"<h3>Tilts / &micro;rad</h3><table>{head}{_rows(doc['tilts'], 'urad')}</table>"
             if doc["tilts"] else "")
    stages = _stage_rows(doc) if doc["stage_column"] else "<p>one stage: the whole run</p>"
    notes = ("<ul>" + "".join(f"<li>{e(n)}</li>" for n in ev.notes) + "</ul>"
             if ev.notes else "")
    plot = embedded_img(img, "drift against time") if img else ""
    return f"""<h2>{e(ev.name)}: {e(ev.test)}</h2>
<p>{doc['n_readings']} readings over {doc['duration_s'] / 3600:.2f} h.</p>
<h3>Drift per channel / &micro;m (from the first reading)</h3>
<table>{head}{_rows(doc['channels'], 'um')}</table>
{tilts}
<h3>Stages (change / range within the stage)</h3>{stages}
<h3>Temperatures / &deg;C</h3>
<table><tr><th></th><th>min</th><th>max</th><th>range / K</th></tr>{temps}</table>
<h3>Plot</h3>{plot}
{notes}"""


def report_html(evaluations: list, pngs: list, generated: str = "",
                identification=None) -> str:
    """A one-page test report per ISO 230-3 (identification, the test, per channel and tilt
    the drift range and extremes, the stages, the plot).  Plain HTML, no network."""
    from ..certificate import Identification

    e = html.escape
    ident = identification or Identification()
    parts = []
    head = ("<tr><th></th><th>direction</th><th>range</th><th>max</th><th>min</th>"
            "<th>t(max) / h</th><th>t(min) / h</th></tr>")
    for ev, img in zip(evaluations, pngs):
        parts.append(_run_html(ev, img, head))
    return document("ISO 230-3 thermal drift test", f"""<h1>Thermal effects &mdash; ISO 230-3</h1>
<p>Evaluation of a thermal drift test according to {e(STANDARD)}: the displacement of the tool
side relative to the workpiece side at one position, as the sensors read it, from the first
reading, in &micro;m; tilts in &micro;rad (right hand, tool side relative to workpiece side).
{e(generated)}</p>
<h2>Identification</h2>
{html_table(ident)}
{''.join(parts)}""")
