"""``volerr check plan``: the shortest check that detects what matters.

1. the reference (:mod:`volerr.check._reference`) and the instruments (``--instrument`` as
   ``volerr plan`` takes them);
2. the largest check the budget allows (``--readings N``, ``--minutes M``; neither: at most
   :data:`MAX_READINGS`), designed by :func:`volerr.plan.plan` (its candidates, information,
   I-optimal design), and the power of its readings (:mod:`volerr.check._power`): for every
   reference parameter the change that moves the volumetric error by ``D`` um somewhere in
   the working volume and the probability the check names it;
3. when the largest check detects all of them with :data:`volerr.check._power.POWER`, the
   readings a smaller check needs, from the standard uncertainties of the largest
   (``s^2 = s_ref^2 + s_check^2``, ``s_check^2`` ~ 1 / readings; at least :data:`MIN_ROWS`),
   planned again and grown by :data:`GROW` until it detects them too, then shrunk by the same
   factor while it still does: the shortest;
4. its files, NC programs and set-up sheet as ``volerr plan`` writes them
   (:meth:`volerr.plan.Plan.write`), and the JSON.
"""

from __future__ import annotations

import math
from dataclasses import dataclass


from .. import plan as planning
from ..errors import InputError, require
from ..machine.model import Model, load
from ..plan import _files, _spec
from . import _power, _reference, _system, _volume

#: default change of the volumetric error to detect, um
DEFAULT_DETECT_UM = 5.0
#: readings of the largest check when no budget is given
MAX_READINGS = 200
#: growth of the readings when a smaller check misses the power
GROW = 1.25
#: fewest rows (points) of a check: three held-out points in each fold of the
#: cross-validation that confirms a change (:data:`volerr.check._system.FOLDS` folds)
MIN_ROWS = 15


@dataclass
class CheckPlan:
    """A planned check: ``plan`` the :class:`volerr.plan.Plan` (files, NC programs),
    ``detectable`` {name: {"size", "unit", "power", "size_95", "std"}}, ``meets`` (every
    parameter detected with the power asked), ``detect_um``, ``reference``."""

    plan: object
    detectable: dict
    meets: bool
    detect_um: float
    reference: object

    def files(self) -> list:
        """The instrument files and their NC programs, as the plan names them."""
        return [n for f in self.plan.data()["files"] for n in (f["file"], f["nc"])]

    def to_dict(self) -> dict:
        return {"readings": int(sum(pf.n for pf in self.plan.files)),
                "minutes": round(self.plan.total_minutes, 1), "detectable": self.detectable,
                "files": self.files(), "layout": self.plan.model.name,
                "meets": self.meets, "detect_um": self.detect_um,
                "power_asked": _power.POWER, "false_alarm_at_most": 0.05,
                "reference": str(self.reference.path),
                "instruments": [i.text for i in self.plan.instruments],
                "note": "size: the change of the parameter that moves the volumetric error by "
                        "detect_um somewhere in the working volume; power: the probability "
                        "that 'volerr check' names it; size_95: the change it names with 95 % "
                        "probability; std: the standard uncertainty of the change (check and "
                        "reference)"}

    def summary(self) -> str:
        d = self.to_dict()
        head = (f"{d['layout']}: check of {d['readings']} readings, about {d['minutes']:g} min "
                f"({', '.join(d['files'])}); "
                + ("detects" if self.meets else "does NOT detect every")
                + f" {self.detect_um:g} um change of the volumetric error with "
                  f"{_power.POWER:.0%} probability")
        rows = [f"  {n}: {v['size']:.3g} {v['unit']} detected with probability {v['power']:.3f}"
                f" (95 %: {v['size_95']:.3g} {v['unit']})"
                for n, v in self.detectable.items()
                if v["power"] is not None and v["size"] is not None and v["size_95"] is not None]
        return "\n".join([head] + rows)

    def write_outputs(self, outs, options: dict, ident, inputs=(), title=None, roles=()):
        """``volerr check plan``'s outputs inside ``with outs:``: :meth:`write` into
        ``--out`` (and ``--json``, ``--html``), then the identification
        (:func:`volerr.report.stamp.finish`)."""
        from ..report.document import Document
        from ..report.stamp import finish

        self.write(outs.path("--out"), outs.path("--json"), outs.path("--html"), inputs)
        finish(outs, Document(self), ident, list(inputs))

    def write(self, folder, json_path=None, html_path=None, inputs=()) -> None:
        """The plan's files, NC programs and set-up sheet (:meth:`volerr.plan.Plan.write`),
        the sheet with the check's power table added (drawn once: the plan writes this page
        instead of its own), and the JSON."""
        from ..fileio import json_text, write_text

        self.plan.write(folder, None, html_path, inputs, sheet=self._sheet)
        if json_path:
            write_text(json_path, json_text(self.to_dict()), inputs=list(inputs))

    def _sheet(self, plan) -> str:
        """The plan's set-up sheet with the power table of the check."""
        from ..plan import _sheet
        from ..report.page import finish

        page = _sheet.html(plan).replace("</body>", self.power_html() + "</body>", 1)
        return finish(page)   # the power table aligned as the sheet's

    def power_html(self) -> str:
        """The power table of the check (an HTML section)."""
        from html import escape

        from ..plotstyle import unit

        rows = "".join(
            f"<tr><td>{escape(n)}</td><td>{_fmt(v['size'])}</td><td>{_fmt(v['power'])}</td>"
            f"<td>{_fmt(v['size_95'])}</td><td>{_fmt(v['std'])}</td><td>{escape(unit(v['unit']))}"
            f"</td></tr>" for n, v in self.detectable.items())
        verdict = "detects" if self.meets else "does NOT detect"
        return (f"<h2>What this check detects</h2><p>Against the reference "
                f"{escape(str(self.reference.path))}: it {verdict} a change of the volumetric "
                f"error by {self.detect_um:g} µm anywhere in the working volume with "
                f"{_power.POWER:.0%} probability (false alarms below 5 %).</p><table><tr>"
                f"<th>parameter</th><th>change moving the map by {self.detect_um:g} µm</th>"
                f"<th>power</th>"
                f"<th>detected with 95 %</th><th>u of a change (k = 1)</th><th>unit</th></tr>{rows}"
                f"</table>")


def _fmt(v) -> str:
    return "-" if v is None else f"{v:.3g}"


def check_plan_options(specs, readings: int | None = None, minutes: float | None = None,
                       detect_um: float | None = None, out=False, force: bool = False) -> None:
    """Refuse options of :func:`plan_check` (``volerr check plan``) out of range, one line:
    no instrument, ``readings`` outside 1 .. 100000, ``minutes`` or ``detect_um`` (um) not
    positive; then (unless ``out`` is False) no folder ``out`` (``--out DIR``), or one that
    holds the check's files already without ``force``
    (:func:`volerr.plan.api.check_plan_folder`)."""
    require(specs, "check plan: give at least one --instrument")
    require(readings is None or 1 <= readings <= 10 ** 5,
            "--readings must be between 1 and 100000")
    require(minutes is None or minutes > 0, "--minutes must be positive")
    require(detect_um is None or detect_um > 0, "--detect-um must be positive")
    if out is not False:
        from ..plan.api import check_plan_folder

        require(out, "check plan: give --out DIR")
        check_plan_folder(out, force, "check", (".csv", ".nc", ".html"))


def plan_check(layout, reference, specs, *, minutes: float | None = None,
               readings: int | None = None, detect_um: float = DEFAULT_DETECT_UM,
               seed: int = 0) -> CheckPlan:
    """The shortest check (module docstring) of ``layout`` against ``reference`` (a calibrate
    or check JSON) with the instruments ``specs``."""
    from threadpoolctl import threadpool_limits

    check_plan_options(specs, readings, minutes, detect_um)
    model = layout if isinstance(layout, Model) else load(layout)
    ref = _reference.load(reference, model)
    insts = [_spec.parse(s) for s in specs]
    require(insts, "give at least one --instrument")
    with threadpool_limits(limits=1, user_api="blas"):
        per_um = _volume.per_unit_max(_volume.grid_columns(model, ref, _tool(insts)))
        top = readings or _readings_for(insts, minutes)
        best = _evaluate(model, ref, specs, top, minutes, seed, per_um, detect_um)
        if not best.meets:
            return best
        n = max(_needed(best, top), MIN_ROWS)
        while n < top:
            trial = _try(model, ref, specs, n, minutes, seed, per_um, detect_um)
            if trial is not None and trial.meets:
                return _shrink(trial, n, model, ref, specs, minutes, seed, per_um, detect_um)
            n = max(n + 1, int(math.ceil(n * GROW)))
        return best


def _shrink(found, n, model, ref, specs, minutes, seed, per_um, detect_um) -> CheckPlan:
    """Fewer readings while the check still meets the power (at least :data:`MIN_ROWS`)."""
    while n > MIN_ROWS:
        m = max(MIN_ROWS, int(n / GROW))
        trial = _try(model, ref, specs, m, minutes, seed, per_um, detect_um)
        if trial is None or not trial.meets:
            break
        found, n = trial, m
    return found


def _tool(insts) -> tuple:
    from ..plan._information import tool_of

    return tool_of(insts)


def _readings_for(insts, minutes) -> int:
    """The most readings ``minutes`` allow (one set-up of the cheapest instrument, the rest
    readings), at most :data:`MAX_READINGS`; :data:`MAX_READINGS` without a time budget."""
    if minutes is None:
        return MAX_READINGS
    best = 0
    for inst in insts:
        per = _spec.READING_S[inst.kind] / 60.0
        left = minutes - _spec.SETUP_MIN[inst.kind]
        best = max(best, MAX_READINGS if per == 0 else int(left / per) if left > 0 else 0)
    require(best > 0, f"--minutes {minutes:g}: no set-up of these instruments fits that time")
    return min(best, MAX_READINGS)


def _try(model, ref, specs, n, minutes, seed, per_um, detect_um):
    try:
        return _evaluate(model, ref, specs, n, minutes, seed, per_um, detect_um)
    except InputError:
        return None            # too few readings for these instruments, or no plan fits


def _evaluate(model, ref, specs, n, minutes, seed, per_um, detect_um) -> CheckPlan:
    p = planning.plan(model, specs, n, None, minutes, "I", seed)
    obs = _stack([_files.observations(model, pf) for pf in p.files])
    system = _system.build(model, ref, obs)
    table = _power.detectable_table(system, ref, per_um, detect_um)
    meets = all(v["power"] >= _power.POWER for v in table.values() if v["power"] is not None)
    return CheckPlan(p, table, bool(meets), detect_um, ref)


def _stack(parts):
    from ..instruments import stack

    return stack(parts)


def _needed(cp: CheckPlan, n_top: int) -> int:
    """Readings a check needs so that every parameter's change of ``size`` is detected, from
    the standard uncertainties of the check of ``n_top`` readings (module docstring, 3)."""
    ref_std = dict(zip(cp.reference.names, cp.reference.std))
    need = 1.0
    for name, v in cp.detectable.items():
        if v["power"] is None or v["std"] is None:
            continue
        target = v["size"] / (v["size_95"] / v["std"])        # std that gives the power
        s_ref = float(ref_std[name])
        s_chk2 = max(v["std"] ** 2 - s_ref ** 2, 1e-300)
        room = target ** 2 - s_ref ** 2
        if room <= 0:
            return n_top
        need = max(need, n_top * s_chk2 / room)
    return max(int(math.ceil(need)), 1)
