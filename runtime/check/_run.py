"""``volerr check``: the steps from a check's files to the verdict.

1. the reference (:mod:`volerr.check._reference`) and the check's files, read as calibrate
   reads them (:func:`volerr.instruments.read_parts`), the layout the same;
2. the system of the readings against the reference's prediction, the reference's covariance
   as a measurement (:mod:`volerr.check._system`);
3. the smallest set of parameters that explains the readings (:mod:`volerr.check._select`),
   the parameters this check cannot tell apart;
4. the residual test: ``chi2`` of the final fit against its degrees of freedom (scaled by the
   reference's variance factor when that exceeds 1); a misfit at ``P_UNEXPLAINED`` is a
   change no parameter of the reference explains;
5. the volumetric change over the working volume (:func:`volerr.check._volume.grid_columns`),
   the values and covariance after the check, the tolerance decisions
   (:mod:`volerr.check._tolerance`).
"""

from __future__ import annotations

import hashlib
import math
from pathlib import Path

import numpy as np

from .. import instruments
from ..errors import require
from ..fit_quality import judge
from ..machine.model import Model, load
from . import _reference, _select, _system, _volume
from ._result import CheckResult

#: options of one form of ``volerr check`` only (``check plan``; ``check LAYOUT FILE...``)
PLAN_ONLY = ("instrument", "minutes", "readings", "detect_um", "out")
CHECK_ONLY = ("tolerance", "date", "max_change")

#: p-value of the residual chi2 below which the readings hold a change nothing explains
P_UNEXPLAINED = 1e-3


def check(layout, files, *, reference, tolerance: str | None = None,
          date: str | None = None, accept_residual: bool = False, max_change=None,
          accept_change: bool = False) -> CheckResult:
    """What changed since the reference calibration (``volerr check LAYOUT --reference REF
    FILE...``; module docstring).

    Parameters
    ----------
    layout : str, path or volerr.Model
        Layout name or file (the reference's layout).
    files : str, path or list
        The check's measurement files (paths or ``KIND:FILE``, as ``volerr calibrate`` reads
        them: readings in um / urad, positions in mm / deg); one string is one file.
    reference : str or path
        The reference: a ``volerr calibrate --json`` or ``volerr check --json`` file with its
        ``covariance`` block (values and covariance in report units: um, urad, um/mm ...).
    tolerance : str, optional
        ``"NAME=VALUE [UNIT],...,map=VALUE"`` (``--tolerance``; ISO 14253-1 decisions,
        :mod:`volerr.check._tolerance`; ``map`` in um of the volumetric change).
    date : str, optional
        ``YYYY-MM-DD``, not after today (UTC), carried into the result (``--date``;
        :func:`volerr.units.parse_date`: a malformed or future date is an InputError).
    accept_residual : bool
        ``--accept-residual``: a fit far above the readings' declared uncertainty
        (:mod:`volerr.fit_quality`) is returned marked forced instead of refused.
    max_change : str or dict, optional
        ``--max-change``: ``"EX0C=20 um,map=30 um"`` (units required;
        :func:`volerr.fit_quality.parse_max_change`; ``map`` bounds the largest volumetric
        change, um); a parameter moved further than its limit against the reference is
        refused unless ``accept_change`` (``--accept-change``).

    Returns
    -------
    CheckResult
        ``to_dict()`` is ``--json`` (changes with standard uncertainties, k = 1, in the
        reference's units; the volumetric change in um).
    """
    from threadpoolctl import threadpool_limits

    from ..results import file_list

    from ..fit_quality import parse_max_change
    from ..units import parse_date

    date = None if date is None else parse_date(date)
    limits = parse_max_change(max_change) if isinstance(max_change, str) else max_change
    model = layout if isinstance(layout, Model) else load(layout)
    ref = _reference.load(reference, model)
    files = file_list(files)
    require(files, "give the check's files")
    tol = None
    if tolerance is not None:
        from ._tolerance import parse

        tol = parse(tolerance, ref, model)
    with threadpool_limits(limits=1, user_api="blas"):
        parts = instruments.read_parts(files, model)
        obs = instruments.stack(parts)
        system = _system.build(model, ref, obs)
        sel = _select.select(system, series=[j for j, n in enumerate(ref.names) if "@" in n])
        pairs, unseen = _select.indistinguishable(system, ref.names)
        tool = np.median(obs.probe, axis=0)
        J = _volume.grid_columns(model, ref, tool)
    misfit = _misfit(system, sel, ref)
    res = CheckResult(model, ref, sel, system, pairs, unseen, J, tool,
                      [_file_entry(s, p) for s, p in zip(files, parts)], date, misfit,
                      quality=judge(misfit["chi2"], misfit["dof"],
                                    "u of each reading as declared in its file, else its "
                                    "instrument's default, times the reference's Birge ratio "
                                    "when above 1"))
    if tol is not None:
        from dataclasses import replace

        from ._tolerance import decide

        # a new result with the decisions (the one without them is not changed)
        res = replace(res, tolerance=decide(tol, res))
    where = f"check {' '.join(instruments.split_spec(str(f))[1] for f in files)}"
    return res.gated(accept_residual, limits, accept_change, where)


def _misfit(system, sel, ref) -> dict:
    """The residual test of step 4: ``{"chi2", "dof", "birge_ratio", "p", "unexplained"}``."""
    from scipy.stats import chi2

    G, _, _ = system.normal()
    ns = system.ns
    S = G[:ns, :ns]
    rank = 0
    if ns:
        d = np.sqrt(np.maximum(np.diag(S), 0.0))
        d[d == 0] = 1.0
        w = np.linalg.eigvalsh(S / np.outer(d, d))
        rank = int(np.sum(w > _system.SOLVE_TOL * max(float(w[-1]), 1e-300)))
    dof = max(system.n_readings - rank - len(sel.changed), 1)
    vf = float(ref.data.get("variance_factor") or 1.0)
    x = sel.fit.chi2                       # the readings' u already scaled (_system.build)
    p = float(chi2.sf(x, dof))
    return {"chi2": round(x, 4), "dof": dof, "birge_ratio": round(math.sqrt(x / dof), 4),
            "reference_variance_factor": vf, "p": p, "unexplained": bool(p < P_UNEXPLAINED)}


def _file_entry(spec, part) -> dict:
    """``{"file", "kind", "sha256", "n_readings"}`` of one check file."""
    path = Path(instruments.split_spec(str(spec))[1])
    digest = hashlib.sha256(path.read_bytes()).hexdigest()
    kind = part.files[0].kind if part.files else "deviations"
    return {"file": path.name, "kind": kind, "sha256": digest,
            "n_readings": int(part.n_readings)}


def command_form(words, reference, options: dict) -> tuple:
    """The form of ``volerr check WORDS --reference CAL.json [FILE...]``: ``(plan, words,
    reference)``, ``plan`` when the first word is ``plan`` (then one LAYOUT follows), else
    LAYOUT and the check's files (those after ``CAL.json`` join them); an option of the other
    form (``options``: the run's options as a plain dict) refused, naming it."""
    from importlib.resources import files

    words, reference = list(words) + list(reference[1:]), reference[0]
    plan = words[0] == "plan"
    usage = (files("volerr") / "data" / "help" / "check.usage.txt").read_text(encoding="utf-8")
    require(not plan or len(words) == 2, "check plan: give one LAYOUT (usage: "
            + usage.split("\n")[0].strip() + ")")
    require(plan or len(words) >= 2, "give LAYOUT and the check's files (or 'check plan "
                                     "LAYOUT ...' to plan one)")
    form = "volerr check LAYOUT FILE..." if plan else "volerr check plan"
    for name in CHECK_ONLY if plan else PLAN_ONLY:
        require(options.get(name) is None, f"--{name.replace('_', '-')} belongs to '{form}'")
    return plan, words, reference
