"""The result of the loop on drift runs (:class:`DriftReport`, built by
:func:`volerr.loop.drift.run.loop_drift`): JSON (INTERFACE.md "Thermal drift tests ... and
the loop on measured heat"), the console, the predictions CSV, the table of reported values
and the HTML page with one time-series figure per channel (:mod:`volerr.loop.drift.figure`).

Effects: the terms of one channel with the same covariate (the heat input, a sensor, a
difference of two sensors) form one effect ("two time constants where one is not enough");
each names its ``channels``, ``covariates``, ``basis``, ``lag_s`` ``{value, std,
range_k2}`` (its first term's; every term in ``terms``; ``range_k2``:
:mod:`volerr.loop.drift.tau_range`) and its coefficients with standard uncertainties (blocked
jackknife) in ``parameters``/``std``; uncertainties are printed with k = 2.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path


from ...results import ResultMixin, Row
from ...selection.rules import SIG_K
from . import basis
from .family import HELD_OUT_ABS_UM, HELD_OUT_REL, RIVAL
from .series import DriftSeries, left_out_line
from .split import extrapolation_line, kept_out_line, room_undecided_line

K_PRINT = 2.0      # coverage factor of the printed uncertainties (the loop's console, 3-D too)


@dataclass(repr=False)
class DriftReport(ResultMixin):
    """Result of the loop on drift runs (``volerr.loop(layout, ["drift:FILE"])``): ``data``
    the JSON of ``volerr loop --json`` (:meth:`to_dict`), ``summary()`` its console text,
    :meth:`table` every reported coefficient and time constant with its standard
    uncertainty (k = 1) and the per-channel held-out figures (um), :meth:`figures` one
    time-series figure per channel, ``write_json`` / ``write_html`` /
    :meth:`write_predictions`.  ``series`` (:class:`~volerr.loop.drift.series.DriftSeries`)
    and ``pred`` (per channel the predictions before, after and of the static regression,
    um) are what the figures and the predictions CSV need."""

    data: dict
    series: DriftSeries
    pred: dict = field(default_factory=dict)
    #: coverage factor of the printed uncertainties
    K_PRINT = K_PRINT

    def __getitem__(self, key):
        return self.data[key]

    @property
    def effects(self) -> list:
        return self.data["effects"]

    def write_predictions(self, path, inputs=()) -> Path:
        """CSV ``file,run,t_s,channel,measured_um,before_um,after_um,split,half_width_um``
        (every reading; ``run`` the run's label in its file, else the file name:
        :meth:`DriftSeries.row_label`; ``half_width_um`` the 95 % prediction interval's at the
        reading, :mod:`volerr.loop.drift.interval`)."""
        from ...fileio import write_text

        s = self.series
        lines = ["file,run,t_s,channel,measured_um,before_um,after_um,split,half_width_um"]
        for label, p in self.pred.items():
            y = s.channels[label]
            hw = p.get("half_width")
            for i in range(len(s.t_s)):
                f, r = s.runs[s.run[i]][0], s.row_label(s.run[i])
                band = "" if hw is None else format(hw[i], ".6g")
                lines.append(f"{f},{r},{s.t_s[i]:.10g},{label},{y[i]:.10g},{p['before'][i]:.10g},"
                             f"{p['after'][i]:.10g},{'test' if s.test[i] else 'train'},{band}")
        return write_text(path, "\n".join(lines) + "\n", inputs=list(inputs))

    def write_html(self, path, inputs=()) -> Path:
        """The page (the loop's template and style, :func:`volerr.loop.drift.figure.render_html`)."""
        from ...fileio import write_text
        from .figure import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def write_error_tables(self, directory, inputs=(), **_):
        """Not written for drift runs: their effects are per channel, not in the layout."""
        from ...errors import require

        require(False, "loop: --errors-out (write_error_tables) is not written for drift runs "
                       "(their effects are per channel, not in the layout)")

    def figures(self) -> dict:
        """``{"channel LABEL": matplotlib Figure}``: measured, before, after and the static
        regression against time, the residuals, the inputs the effects chose."""
        from .figure import channel_figure

        return {f"channel {k}": channel_figure(self, k) for k in self.data["channels"]}

    def summary(self) -> str:
        """The whole console text of ``volerr loop`` on drift runs."""
        return "\n".join(self.summary_lines())

    def _rows(self) -> list:
        out = []
        for e in self.data["effects"]:
            for j, t in enumerate(e["terms"]):
                name = f"{e['name']}_{j}"
                out.append(Row(name, t["value"], t["std"], t["unit"], 1.0))
                if t.get("lag_s"):
                    out.append(Row(f"{name}:tau", t["lag_s"]["value"], t["lag_s"]["std"], "s",
                                   1.0))
        for label, c in self.data["channels"].items():
            for key in ("mae_before_um", "mae_after_um", "mae_static_um"):
                out.append(Row(f"{label}:{key[:-3]}", c[key], None, "um", 1.0))
        return out

    def summary_lines(self) -> list:
        d = self.data
        out = [f"{d['layout']}: drift runs {', '.join(d['runs'])}; {d['split']}; "
               f"{d['n_train']} training, {d['n_test']} held-out readings; choices by blocked "
               f"cross-validation over {d['n_folds']} {d['fold_rule']}"
               + (f" ({', '.join(d['fold_environments'])})" if d.get("fold_environments")
                  else "")]
        if d.get("extrapolation"):
            out.insert(0, "  " + extrapolation_line(d["extrapolation"]))
        if d.get("room_undecided"):
            out.insert(0, "  " + room_undecided_line(d["room_undecided"]))
        if d.get("kept_out"):
            out.insert(0, "  " + kept_out_line(d["kept_out"]))
        if d.get("inputs_left_out"):
            out.insert(0, "  " + left_out_line(d["inputs_left_out"]))
        if d.get("time_origins_s"):
            out.insert(0, "  note: the time column of " + ", ".join(
                f"{f} holds timestamps (first {v:.10g} s)" for f, v in d["time_origins_s"].items())
                + ": read as seconds since the file's first reading (--holdout-time too)")
        for label, c in d["channels"].items():
            out.append(f"  channel {label}: held-out MAE {c['mae_before_um']:.3f} -> "
                       f"{c['mae_after_um']:.3f} um (static regression on all temperatures "
                       f"{c['mae_static_um']:.3f}), RMS {c['rms_before_um']:.3f} -> "
                       f"{c['rms_after_um']:.3f}, max {c['max_abs_before_um']:.3f} -> "
                       f"{c['max_abs_after_um']:.3f} um")
            out += _family_lines(c)
        for sym, q in d.get("quantities", {}).items():
            rows = ", ".join(f"{c} {w:+.4g}" for c, w in q["rows"].items())
            own = ", ".join(q["layout_parameters"]) or "none"
            out.append(f"  {sym} ({q['unit']}): {q['description']}, rows {rows}; the layout's "
                       f"parameters it is at this position: {own}")
        if any("held_out" in e and e["held_out"] is None for e in d["effects"]):
            out.append("  the effects are not judged on held-out readings: none are held out")
        said: dict = {}       # label -> its first effect not confirmed (the line said once)
        for e in d["effects"]:
            what = e["channel"] if not e.get("quantity") else \
                f"{e['quantity']} (channels {', '.join(e['channels'])})"
            out.append(f"  {e['kind']} {e['name']}: {what} varies with {e['basis']}")
            if e.get("held_out") and not e["held_out"]["confirmed"]:
                out.append("    " + (_not_confirmed_line(e["held_out"], bool(e.get("quantity")))
                                     if e["channel"] not in said else
                                     f"not confirmed on the held-out readings (as "
                                     f"{said[e['channel']]} above: the same lag model)"))
                said.setdefault(e["channel"], e["name"])
            for t in e["terms"]:
                out.append("    " + _term_line(t))
        for n in d.get("not_reported", []):
            out.append(f"  lag term not reported (the lag model does not beat both baselines): {n}")
        for n in d["not_significant"]:
            out.append(f"  not significant (|value| < {SIG_K:g} u), left out: {n}")
        return out


def _family_lines(c: dict) -> list:
    """A channel's model family, its baselines' held-out figures, why, its interval."""
    if "family" not in c:
        return []
    b = c.get("baselines", {})
    line = (f"    model: {c['family']}; held-out MAE of the baselines: static regression "
            f"{b['static']['mae_um']:.3f}, constant {b['constant']['mae_um']:.3f} um; lag model "
            f"{c['lag_model']['mae_um']:.3f} um"
            + (f", regularised fit over the lag bank {c['regularised']['mae_um']:.3f} um"
               if "regularised" in c else ""))
    out = [line]
    if c.get("verdict"):
        out.append(f"    {c['verdict']}")
    h = c.get("held_out_reported")
    if h and not h["within"]:
        out.append(f"    NOT HELD on the held-out readings: the reported model's held-out MAE "
                   f"{_over_bar(h['mae_um'], h)}: the choice the training readings made did not "
                   f"carry over here")
    if c.get("families_equivalent"):
        out.append("    the cross-validation cannot tell it from: " + ", ".join(
            f"{f['family']} (CV RMS {f['cv_rms_um']:.3f} um, paired t {f['paired_t']:.2f})"
            for f in c["families_equivalent"]))
    iv = c.get("interval")
    if iv:
        cov = "n/a" if iv["coverage_test"] is None else f"{100 * iv['coverage_test']:.1f} %"
        lo, hi = iv.get("half_width_um_range") or (iv["half_width_um"],) * 2
        out.append(f"    {100 * iv['level']:.0f} % prediction interval +- "
                   f"{iv['half_width_um']:.3f} um (median over the held-out readings; "
                   f"{lo:.3f}..{hi:.3f} um, wider where the inputs extrapolate; from the "
                   f"blocked-CV residuals); held-out readings inside it: {cov}")
        room = iv.get("room_undecided")
        if room and room["same_model"]:
            out.append("      not widened for the room: in this model the sensors' two readings "
                       "are one model (the room is a column of its own, or no sensor enters)")
        elif room:
            cov0 = room["coverage_test_unwidened"]
            out.append(f"      widened on the held-out readings by the difference to the "
                       f"{room['alternative']} reading of the sensors (median "
                       f"{room['difference_um'][0]:.3f}, max {room['difference_um'][1]:.3f} um;"
                       f" the training holds the room): without it +- "
                       f"{room['half_width_um_unwidened']:.3f} um, inside it "
                       + ("n/a" if cov0 is None else f"{100 * cov0:.1f} %"))
        kept = iv.get("kept_out_widening")
        if kept:
            cov0 = kept["coverage_test_unwidened"]
            names = ", ".join(f"{k['input']} ({k['coef_um_per_unit']:.3g} +- "
                              f"{2 * k['u']:.3g} um/unit, k = 2)" for k in kept["inputs"])
            out.append(f"      widened on the held-out readings for the inputs kept out, "
                       f"by their coefficients on the training residuals: {names} (median "
                       f"{kept['difference_um'][0]:.3f}, max {kept['difference_um'][1]:.3f} "
                       f"um): without it +- {kept['half_width_um_unwidened']:.3f} um, inside "
                       f"it " + ("n/a" if cov0 is None else f"{100 * cov0:.1f} %"))
    return out


def _not_confirmed_line(h: dict, quantity: bool) -> str:
    """The console line of an effect whose lag model does not hold on the held-out readings
    (:func:`volerr.loop.drift.family.held_out_verdict`; ``quantity``: judged on the channel
    ``h["channel"]`` of least margin)."""
    on = f" on channel {h['channel']}" if quantity else ""
    return (f"not confirmed on the held-out readings: the lag model's held-out MAE{on} "
            f"{_over_bar(h['lag_model_mae_um'], h)}: these terms describe the training "
            f"readings, not a transfer")


def _over_bar(mae: float, h: dict) -> str:
    """'MAE um > bound um = 1.05 x the baseline's B um + 0.2 um': a held-out MAE (um) above
    the bar of the verdict ``h`` (:func:`volerr.loop.drift.family.held_out_verdict`,
    :func:`~volerr.loop.drift.family.reported_held_out`)."""
    return (f"{mae:.2f} um > {h['bound_um']:.2f} um = {HELD_OUT_REL:g} x the "
            f"{RIVAL[h['baseline']]}'s {h['baseline_mae_um']:.2f} um + {HELD_OUT_ABS_UM:g} um")


def _term_line(t: dict) -> str:
    k = K_PRINT
    c = f"{t['value']:.4g} +- {k * t['std']:.2g} {t['unit']} (k = {k:g})"
    lag = t.get("lag_s")
    if lag:
        u = f" +- {k * lag['std']:.0f}" if lag.get("std") is not None else " (u not determined)"
        c += f", tau = {lag['value']:.0f}{u} s (k = {k:g}){_range_text(lag)}"
    if t.get("alternatives"):
        c += "; these data cannot tell it from " + _alternatives_text(t["alternatives"])
    if t.get("cv_decided") is False:
        c = (f"NOT DECIDED by these data (the model without it is CV-equivalent, paired t "
             f"{t['cv_without']['paired_t']:.2f}): " + c)
    return f"{t['basis']}: {c}"


def _range_text(lag: dict) -> str:
    """', range LO .. HI s' of a time constant's profile range (``lag_s.range_k2``,
    :mod:`volerr.loop.drift.tau_range`; an open end: 'above LO s', 'below HI s', both: 'not
    determined by these runs'); '' without one."""
    if "range_k2" not in lag:
        return ""
    lo, hi = lag["range_k2"]
    if lo is None and hi is None:
        return ", range not determined by these runs"
    if hi is None:
        text = f", range above {lo:.0f} s"
    elif lo is None:
        text = f", range below {hi:.0f} s"
    else:
        text = f", range {lo:.0f} .. {hi:.0f} s"
    if (lo or 0.0) <= lag["value"] <= (hi if hi is not None else float("inf")):
        return text
    # the range is where the least RSS lies with every other time constant free: two terms
    # of one source may trade their time constants, the reported one is the CV's choice
    return text + " (not this fit's tau: the profile's least RSS lies elsewhere)"


#: sources named on the console per term (all of them in the JSON)
ALT_PRINT = 5


def _alternatives_text(alts: list) -> str:
    """The alternatives by source, in the JSON's order (lowest CV RMS first): a source with
    the span of its lags (``plain`` for no lag), at most ``ALT_PRINT`` sources."""
    by: dict = {}
    for a in alts:
        by.setdefault(a["covariate"], []).append(a.get("lag_s") or 0.0)
    parts = []
    for src, lags in list(by.items())[:ALT_PRINT]:
        on = sorted(x for x in lags if x > 0)
        what = [] if not on else [f"{on[0]:.0f} s" if on[0] == on[-1] else
                                  f"{on[0]:.0f}..{on[-1]:.0f} s"]
        what += ["plain"] if len(on) < len(lags) else []
        parts.append(f"{src} ({', '.join(what)})")
    more = len(by) - ALT_PRINT
    return ", ".join(parts) + (f" and {more} other sources (JSON)" if more > 0 else "")


