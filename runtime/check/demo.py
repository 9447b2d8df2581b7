"""The demo's weekly checks (``volerr demo``, section ``check``): a DMU 50 calibrated with an
R-test campaign, then checked every week for 20 weeks with the shortest check of
``volerr check plan`` (20 minutes at most), while the pivot of its C axis drifts
(``EX0C``, :data:`DRIFT_UM_PER_WEEK`) and a collision at week :data:`COLLISION_WEEK` tilts
its B axis (``EA0B`` by :data:`COLLISION_URAD`).  The machine is volerr's own first-order
model (:func:`volerr.plan.execute`, the demo's simulator; the tests use an independent
chain).  Writes the reference, the check plan, every check's file and JSON; the history page
is drawn by ``volerr history`` from these JSON files (the demo's command module)."""

from __future__ import annotations

import datetime
import shutil
from pathlib import Path

import numpy as np

#: the machine at the reference calibration (mm, rad)
TRUTH = {"EX0B": 12e-3, "EY0B": -8e-3, "EA0B": 35e-6, "EB0B": -20e-6, "EX0C": 15e-3,
         "EY0C": -10e-3, "EA0C": 25e-6, "EB0C": -40e-6}
DRIFT_UM_PER_WEEK = 0.25
COLLISION_WEEK, COLLISION_URAD = 12, 30.0
WEEKS = 20
REFERENCE_DATE = datetime.date(2026, 6, 1)
INSTRUMENT = "sphere:u_um=0.5"
#: the history page's tolerance: the drifting pivot leaves it about week 28 (mid December)
TOLERANCE = "EX0C=22 um"


def machine_at(week: int) -> dict:
    """The planted errors (mm, rad) in week ``week`` (0: the reference calibration)."""
    out = dict(TRUTH)
    out["EX0C"] += DRIFT_UM_PER_WEEK * 1e-3 * week
    if week >= COLLISION_WEEK:
        out["EA0B"] += COLLISION_URAD * 1e-6
    return out


def date_of(week: int) -> str:
    return (REFERENCE_DATE + datetime.timedelta(weeks=week)).isoformat()


def weekly(out: Path) -> dict:
    """Run the section into ``out``: ``{"reference", "checks": [path], "results": [dict],
    "plan": dict, "files": [...]}``."""
    from ..calibrate.run import calibrate
    from ..machine.model import load
    from ..plan import execute, plan
    from . import check, plan_check

    model = load("DMU50")
    rng = np.random.default_rng(37)
    ref_dir = out / "check_reference"
    plan(model, [INSTRUMENT], 80).write(ref_dir)
    execute(ref_dir / "sphere.csv", model, machine_at(0), rng)
    from ..fileio import json_text, write_text

    cal = calibrate(model, [ref_dir / "sphere.csv"])
    reference = out / "check_reference.json"
    # the calibration's JSON dated (the result itself is not changed)
    write_text(reference, json_text({**cal.to_dict(), "date": date_of(0)}))
    cp = plan_check(model, reference, [INSTRUMENT], minutes=20)
    cp.write(out / "check_plan", out / "check_plan.json")
    paths, results = [], []
    for week in range(1, WEEKS + 1):
        f = out / "check_plan" / f"week{week:02d}.csv"
        shutil.copy(out / "check_plan" / cp.plan.files[0].name, f)
        execute(f, model, machine_at(week), rng)
        res = check(model, [f], reference=reference, date=date_of(week))
        path = out / f"check_week{week:02d}.json"
        res.write_json(path)
        paths.append(path)
        results.append(res.to_dict())
    figure = out / "check_weekly.png"
    _figure(figure, results)
    files = ["check_reference.json", "check_plan.json", "check_plan/", "check_weekly.png"] + \
        [p.name for p in paths]
    return {"reference": reference, "checks": paths, "results": results,
            "plan": cp.to_dict(), "files": files}


def summary(run: dict) -> str:
    """One line: the plan, the weeks called changed and what changed in each."""
    changed = [(i + 1, r) for i, r in enumerate(run["results"]) if r["verdict"] == "changed"]
    p = run["plan"]
    text = "; ".join(f"week {w}: " + ", ".join(_change(c) for c in r["changed"])
                     for w, r in changed[:6])
    return (f"check plan {p['readings']} readings, {p['minutes']:g} min; {len(changed)} of "
            f"{len(run['results'])} weekly checks changed ({text}{' ...' if len(changed) > 6 else ''})"
            f"; planted: EX0C drifts {DRIFT_UM_PER_WEEK:g} um/week, EA0B +{COLLISION_URAD:g} urad "
            f"at week {COLLISION_WEEK}")


def _change(c: dict) -> str:
    """'EX0C +0.86 +- 0.16 um (or EB0C +3.3 +- 0.7 urad: not told apart)'."""
    alts = ", ".join(f"{a['parameter']} {a['change']:+.3g} +- {a['std']:.2g} {a['unit']}"
                     for a in c.get("alternatives", []))
    return (f"{c['parameter']} {c['change']:+.3g} +- {c['std']:.2g} {c['unit']}"
            + (f" (or {alts}: this check cannot tell them apart)" if alts else ""))


def _figure(path: Path, results: list) -> None:
    """EX0C and EA0B after each check (the reference updated by it) with 2 std bars."""
    from ..plotstyle import figure, label, save, styled

    @styled
    def draw():
        fig, axes = figure(1, 2, height=3.6)
        weeks = np.arange(1, len(results) + 1)
        for ax, name in zip(axes, ("EX0C", "EA0B")):
            v = np.array([r["parameters"][name]["value"] for r in results])
            s = np.array([r["parameters"][name]["std"] for r in results])
            ax.errorbar(weeks, v, yerr=2 * s, fmt="o", ms=3, capsize=2, label="after the check")
            hit = [i for i, r in enumerate(results)
                   if any(c["parameter"] == name for c in r["changed"])]
            ax.plot(weeks[hit], v[hit], "o", mfc="none", mec="C3", ms=8, label="named changed")
            ax.set_xlabel("week")
            ax.set_ylabel(label(name, results[0]["parameters"][name]["unit"]))
            ax.legend(loc="best")
        save(fig, path)

    draw()
