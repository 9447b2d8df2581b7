"""``volerr demo [--out DIR]``: the whole pipeline on built-in data; writes a report.

Sections (each runs the real command or API on built-in data and writes into DIR):

1. CMM A of Pahk (MB1): example error tables, volumetric error map, space diagonals;
2. CMM B of Pahk (MH2): map with the random component, diagonals with their random part;
3. audit of the derived models against the printed equations;
4. probe calibration on a simulated master-sphere run (Pahk's 101-point plan);
5. laser-tracker identification of a simulated three-point campaign, squareness, diagonals;
   ballbar circles (ISO 230-4 G, H, diagnosis) and the rotary axes of the DMU 50 from a
   simulated sphere probing cycle (``volerr calibrate``); a ball plate in four placements on
   MB1 and multilateration from four stations of a tracking interferometer on the DMU 50
   (``volerr calibrate``: parameters, poses, stations, consistency, map with its uncertainty);
6. five-axis DMU 50: a hemisphere finishing program compensated (full model and the thesis'
   strategy), tool-centre-point error over the (B, C) range;
7. closing the loop: a virtual MB1 with an undeclared effect, fit, diagnosis, augmented model;
8. ISO 230-2 evaluation of a simulated positioning run;
9. task-specific uncertainty of a distance (Monte Carlo);
10. measurement plans (``volerr plan``): an R-test campaign for the DMU 50 and a ballbar +
    tracking-interferometer campaign for MB1, executed on volerr's model and calibrated, the
    predicted against the realised standard uncertainties; weekly interim checks of a DMU 50
    (``volerr check``; the history page by ``volerr history`` when installed);
11. ``index.html`` with a section, figures and captions per step, and the headline figures
    printed.  Everything is written at the end, all or nothing.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from pathlib import Path

from ..errors import require
from ..fileio import json_text, write_text
from ..units import num

SECTIONS = ("cmm_a", "cmm_b", "audit", "probe", "identify", "ballbar", "rotary", "ballplate",
            "multilateration", "fiveaxis", "loop", "iso230_2", "uncertainty", "plan", "check")

#: one sentence per section of index.html: what it shows and how to read it
ABOUT = {
    "check": "A DMU 50 calibrated with an R-test campaign and then checked every week with "
             "the shortest check 'volerr check plan' designs (at most 20 minutes, 95 % power "
             "for a 5 um change of the volumetric error); its C-axis pivot drifts and a "
             "collision at week 12 tilts its B axis: each check names what changed with its "
             "uncertainty; the history page (volerr history) shows events and trends.",
    "plan": "Measurement plans made before any machine time (volerr plan): an R-test "
            "campaign for the DMU 50 and a ballbar + tracking-interferometer campaign for "
            "MB1, each executed on volerr's model with planted errors and calibrated with no "
            "options; the plan's predicted standard uncertainties beside the realised ones "
            "(equal up to the noise of the variance factor) and its map uncertainty beside "
            "the conventional plan's.",
    "cmm_a": "Pahk's CMM A (moving bridge MB1) with synthetic example error tables: the "
             "volumetric error over the working volume (nominal grid dashed, actual solid, "
             "magnified) and the length deviations of the space diagonals.",
    "cmm_b": "Pahk's CMM B (MH2): the same with repeatability columns in the tables, so the "
             "random component (1 sigma) is mapped and propagated to the diagonals separately.",
    "audit": "Every derived CMM equation against the one printed in Pahk 1995; differences are "
             "named errata with their evidence (audit.html, audit.json).",
    "probe": "A simulated 3-lobe kinematic probe measured on Pahk's 101-point plan: effective "
             "ball radius R_eff and the probe error map Probe(phi, theta).",
    "identify": "Shipped laser-tracker data (3 points, 11 positions, 4 rounds per axis): the six "
                "error motions of X, Y and Z identified, squareness from the straightness "
                "reference lines, then the space diagonals of the measured machine.",
    "ballbar": "Ballbar circles (ISO 230-4) in the three planes of MB1 with planted squareness "
               "and scale errors: circular deviation G and hysteresis H per trace, the polar "
               "plot, and the diagnosis in ISO 230-1 parameters computed from the layout's "
               "observation model (with an uncalibrated bar only the scale mismatch of two "
               "axes is determined).",
    "rotary": "A touch-probe kinematics cycle on the DMU 50 (two sphere placements, B and C "
              "over their travel) with planted location errors of both rotary axes: volerr "
              "calibrate identifies them with their uncertainties, names what this plan cannot "
              "separate from the sphere and tool unknowns, and the plan that would.",
    "ballplate": "A 5 x 5 ball plate measured by MB1 in four placements (XY at two heights, "
                 "XZ, YZ; the plate's pose in each unknown) with planted scale and squareness "
                 "errors: volerr calibrate identifies them with the poses, checks the file's "
                 "consistency with its stated 0.5 um, and maps the identified volumetric "
                 "error with its propagated uncertainty and the ISO 10360-2 length errors.",
    "multilateration": "A tracking interferometer at four stations on the table of the DMU 50 "
                       "measures the tool point at 200 poses of the five axes (relative "
                       "distances, 0.3 um + 0.3 um/m): volerr calibrate identifies the linear "
                       "axes' scales, the squareness and the location errors of B and C "
                       "together with the stations' positions and dead paths "
                       "(self-calibrating multilateration).",
    "fiveaxis": "A hemisphere finishing program on the DMU 50 compensated with the full model "
                "and with the thesis' strategy; the tool-tip error over the (B, C) range.",
    "loop": "A virtual MB1 whose X scale follows the X motor's temperature through a 20 min "
            "lag (four logged sensors, drives 2 h on then off): the loop fits the declared "
            "model, finds the missing effect with its sensor and time constant, augments the "
            "layout and compares before and after on held-out points.",
    "iso230_2": "A simulated laser-interferometer positioning run of X (9 targets, 5 cycles, "
                "both directions) evaluated as ISO 230-2: accuracy A, repeatability R, "
                "reversal B, systematic error E, each with its measurement uncertainty U "
                "(k = 2, ISO/TR 230-9) and a verdict against example tolerances (ISO 14253-1); "
                "the certificate is iso230_2.html.",
    "uncertainty": "Task-specific uncertainty of a 400 mm distance on MH2 by Monte Carlo "
                   "(virtual CMM, JCGM 101): the example tables' repeatability columns (_s, "
                   "drawn independently at every probing point, --repeatability) and 0.5 µm "
                   "probing noise; the result is corrected for the bias of the machine's known "
                   "errors (uncertainty.html).",
}

#: figure captions (file name -> sentence)
CAPTIONS = {
    "map_MB1.png": "MB1: volumetric error on the travel grid, nominal (dashed) and actual "
                   "(solid) grid, errors magnified by the factor in the title.",
    "map_MB1_random.png": "MB1: random component of the volumetric error, the standard "
                          "uncertainty (k = 1) for one reading from the tables' repeatability "
                          "columns; bars \u00b1 the magnified rx, ry, rz.",
    "map_MH2.png": "MH2: volumetric error on the travel grid (magnified).",
    "map_MH2_random.png": "MH2: random component (k = 1) of the volumetric error; bars \u00b1 "
                          "the magnified rx, ry, rz.",
    "diagonals_MB1.png": "MB1: length deviation along the space diagonals (top) and of every "
                         "line (below); bands and bars \u00b1 2 u (k = 2).",
    "diagonals_MH2.png": "MH2: length deviation along the space diagonals, bands \u00b1 2 u "
                         "(k = 2) of the random part, and of every line (bars \u00b1 2 u).",
    "probe_map.png": "Probe error: 3-D lobing map (top) and over (theta, phi) (below), µm.",
    "identified_X.png": "X axis: identified error motions, mean of 4 rounds; bars \u00b1 2 s, "
                        "s the standard deviation of one round (the table's _s; its _std is "
                        "s / \u221a4).",
    "identified_Y.png": "Y axis: identified error motions (bars \u00b1 2 s of one round).",
    "identified_Z.png": "Z axis: identified error motions (bars \u00b1 2 s of one round).",
    "ballbar_polar.png": "Ballbar polar plot: radial deviation about the least-squares circle "
                         "(magnified; CCW blue, CW red), G and H per trace.",
    "calibrate_rotary.png": "Identified location errors of B and C, bars \u00b1 2 u (k = 2), "
                            "beside the planted values (crosses).",
    "calibrate_ballplate.png": "Ball plate on MB1: identified scale (\u00b5m/mm) and squareness "
                               "(\u00b5rad), bars \u00b1 2 u (k = 2), beside the planted "
                               "values (crosses).",
    "calibrate_multilateration.png": "Multilateration on the DMU 50: identified parameters, "
                                     "bars \u00b1 2 u (k = 2), beside the planted values "
                                     "(crosses).",
    "compensate_full.png": "DMU 50 program, full model: predicted tool-tip error per block "
                           "before and after compensation.",
    "compensate_thesis.png": "DMU 50 program, thesis strategy (rotary, then linear).",
    "tcpmap_DMU50.png": "DMU 50: tool-tip error at one workpiece point over B and C (grey: "
                        "outside the travel or the tables).",
    "iso230_2.png": "ISO 230-2 plot: mean deviations per direction with bands \u00b1 2 S "
                    "(k = 2) of one reading; ringed: readings that decide a quantity that "
                    "fails or is undecided.",
    "check_weekly.png": "EX0C and EA0B after each weekly check (the reference updated by the "
                        "check, 2 std bars); ringed: the weeks the check names the parameter "
                        "changed.",
    "plan_predicted.png": "Standard uncertainty of each parameter: predicted by volerr plan "
                          "before the measurement (bars) and realised by volerr calibrate on "
                          "the executed plan (dots), k = 1.",
    "uncertainty.png": "Distribution of the Monte Carlo readings of the distance about their "
                       "mean: 95 % coverage interval (red) and \u00b1 U (k = 2, blue).",
}


def register(sub) -> None:
    p = sub.add_parser("demo", help="the whole pipeline on built-in data; writes a report",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="volerr-demo", help="output folder (default volerr-demo)")
    p.add_argument("--only", nargs="+", choices=SECTIONS, help="run only these sections")
    from ._common import add_force

    add_force(p)
    p.set_defaults(func=run)


def _cli(*argv) -> str:
    """Run a volerr command in-process; return what it printed. Non-zero exit is an error."""
    from . import main

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main([str(a) for a in argv])
    require(code == 0, f"demo step 'volerr {' '.join(map(str, argv))}' failed (exit {code})")
    return buf.getvalue()


def _cmm(out: Path, layout: str, label: str) -> dict:
    from ..cmm.examples import write_example_errors

    errors = out / f"errors_{layout}"
    write_example_errors(errors, layout)
    _cli("map", layout, "--errors", errors, "--out", out / f"map_{layout}.csv",
         "--plot", out / f"map_{layout}.png")
    _cli("diagonals", layout, "--errors", errors, "--json", out / f"diagonals_{layout}.json",
         "--plot", out / f"diagonals_{layout}.png")
    diag = json.loads((out / f"diagonals_{layout}.json").read_text())
    lines = diag["lines"] if isinstance(diag, dict) else diag
    space = [ln for ln in lines if ln.get("kind") == "space"]
    text = ", ".join(f"{ln['deviation_um']:+.1f}" for ln in space)
    rand = [ln.get("random_um") for ln in space if ln.get("random_um") is not None]
    if rand:
        text += " um (random " + ", ".join(f"{r:.1f}" for r in rand) + " um)"
    else:
        text += " um"
    files = [f"errors_{layout}/", f"map_{layout}.csv", f"map_{layout}.png"]
    if (out / f"map_{layout}_random.png").exists():
        files.append(f"map_{layout}_random.png")
    return {"title": f"{label} ({layout}): space diagonals", "value": text,
            "files": files + [f"diagonals_{layout}.json", f"diagonals_{layout}.png"]}


#: the example tolerances of the ISO 230-2 certificate, um
DEMO_TOLERANCE = "A=12,E=10,M=8,R=4,B=3"

#: the demo audits the CMM models (seconds); ``volerr audit`` alone audits everything
DEMO_AUDIT = ("MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY")


def _audit(out: Path) -> dict:
    _cli("audit", *DEMO_AUDIT, "--json", out / "audit.json", "--html", out / "audit.html")
    verdicts = json.loads((out / "audit.json").read_text())
    verdicts = verdicts["verdicts"] if isinstance(verdicts, dict) else verdicts
    equations = {}
    for v in verdicts:  # one verdict per component (dX, dY, the rule of dx(X) ...)
        key = (v["source"], v["equation"], v["layout"])
        equations[key] = equations.get(key, True) and v["verdict"] == "identical"
    bad = sum(1 for ok in equations.values() if not ok)
    wrong = sum(1 for v in verdicts if v["verdict"] != "identical")
    return {"title": "audit of Pahk's printed CMM equations (all sources: volerr audit)",
            "value": f"{len(equations)} printed equations: {len(equations) - bad} identical, "
                     f"{bad} with named errata ({wrong} of {len(verdicts)} components)",
            "files": ["audit.html", "audit.json"]}


def _probe(out: Path) -> dict:
    from ..probe.plans import simulate_demo_sphere

    data = simulate_demo_sphere(out / "sphere_probing.csv")
    _cli("probe-cal", data["path"], "--sphere-radius", data["sphere_radius_mm"],
         "--out", out / "probe_map.csv", "--json", out / "probe_cal.json",
         "--plot", out / "probe_map.png")
    cal = json.loads((out / "probe_cal.json").read_text())
    e = cal["probe_error_um"]
    return {"title": "probe calibration (101-point plan, simulated 3-lobe probe)",
            "value": f"R_eff {cal['r_eff_mm']:.4f} mm; probe error max {e['max']:+.1f}, "
                     f"min {e['min']:+.1f}, RMS {e['rms']:.1f} um",
            "files": ["sphere_probing.csv", "probe_map.csv", "probe_cal.json", "probe_map.png"]}


def _identify(out: Path) -> dict:
    from ..identify.tracker_io import example_path

    measured = out / "tracker_identified"
    for axis in ("X", "Y", "Z"):
        _cli("identify", "MB1", "--axis", axis, example_path(axis), "--fit", "poly",
             "--errors-out", measured, "--plot", out / f"identified_{axis}.png")
    _cli("squareness", "MB1", measured, "--out", out / "tracker_errors",
         "--json", out / "squareness.json")
    sq = json.loads((out / "squareness.json").read_text())
    u = sq["u_urad"]
    text = ", ".join(f"{k} {v:+.1f} +/- {u[k]:.1f}" for k, v in sq["squareness_urad"].items())
    _cli("diagonals", "MB1", "--errors", out / "tracker_errors", "--method", "poly",
         "--volume", "measured", "--json", out / "diagonals_tracker.json")
    diag = json.loads((out / "diagonals_tracker.json").read_text())
    space = [ln["deviation_um"] for ln in diag["lines"] if ln["kind"] == "space"]
    return {"title": "laser-tracker identification of MB1 X, Y, Z (shipped example data: 3 "
                     "points, 11 positions, 4 rounds) -> squareness -> space diagonals",
            "value": f"squareness {text} urad (k = 1; simulated truth EC0Y +20, EB0Z -15, "
                     "EA0Z +10); "
                     "space diagonals " + ", ".join(f"{d:+.1f}" for d in space) + " um",
            "files": ["tracker_identified/", "tracker_errors/", "squareness.json",
                      "identified_X.png", "identified_Y.png", "identified_Z.png",
                      "diagonals_tracker.json"]}


def _ballbar(out: Path) -> dict:
    from ..calibrate.examples import write_ballbar_example
    from ..units import num

    ex = write_ballbar_example(out / "ballbar")
    _cli("ballbar", "evaluate", *ex["files"], "--json", out / "ballbar.json",
         "--plot", out / "ballbar_polar.png", "--html", out / "ballbar.html")
    rep = json.loads((out / "ballbar.json").read_text())
    g = ", ".join(f"{t['plane']} {num(t['G_um'], '.2f')}" for t in rep["traces"]
                  if t["direction"] == "ccw")
    truth = ex["truth"]
    diag = []
    for d in rep["diagnosis"]:
        name = d["parameter"]
        if name in truth:
            diag.append(f"{name} {num(d['value'], '+.1f')} +/- {num(d['std'], '.1f')} urad "
                        f"(planted {num(truth[name], '+.1f')})")
        elif "-" in name:
            a, b = (n.split("@")[0] for n in name.split("-"))
            planted = 1e-3 * (truth[a] - truth[b])
            diag.append(f"{a}-{b} scale {num(d['value'], '+.4f')} +/- "
                        f"{num(d['std'], '.4f')} um/mm (planted {num(planted, '+.4f')})")
    return {"title": "ballbar circles in XY, YZ, ZX of MB1 (ISO 230-4) -> G, H, diagnosis",
            "value": f"G (CCW) {g} um; diagnosis: " + "; ".join(diag),
            "files": ["ballbar/", "ballbar.json", "ballbar.html", "ballbar_polar.png"]}


def _rotary(out: Path) -> dict:
    from ..calibrate.examples import write_sphere_example
    from ..units import num

    ex = write_sphere_example(out / "sphere_DMU50.csv", "DMU50")
    _cli("calibrate", "DMU50", ex["path"], "--json", out / "calibrate_rotary.json",
         "--html", out / "calibrate_rotary.html", "--errors-out", out / "errors_rotary")
    rep = json.loads((out / "calibrate_rotary.json").read_text())
    rows = []
    for name, v in rep["parameters"].items():
        rows.append(f"{name} {num(v['value'], '+.1f')} +/- {num(v['std'], '.1f')} (planted "
                    f"{num(ex['truth'].get(name, 0.0), '+.1f')}) {v['unit']}")
    plan = "; ".join(f"{p['adds']} -> {', '.join(p['makes_identifiable'])}"
                     for p in rep["plan"] if p["makes_identifiable"])
    _parameter_figure(out / "calibrate_rotary.png", rep, ex["truth"])
    return {"title": f"rotary axes of the DMU50 from a sphere probing cycle ({ex['n']} poses, "
                     f"2 placements)",
            "value": "; ".join(rows) + f"; not determined by this plan: "
                     f"{', '.join(rep['unidentifiable']) or 'none'}"
                     + "".join(f"; determined only in combination: {c['expression']} = "
                               f"{num(c['value'], '+.1f')} +/- {num(c['std'], '.1f')} "
                               f"{c['unit']} (written as {c['written_as']})"
                               for c in rep.get("combinations", []))
                     + (f" (would be by: {plan})" if plan else ""),
            "files": ["sphere_DMU50.csv", "calibrate_rotary.json", "calibrate_rotary.html",
                      "calibrate_rotary.png", "errors_rotary/"]}


def _ballplate(out: Path) -> dict:
    from ..calibrate.examples import write_ballplate_example
    from ..units import num

    ex = write_ballplate_example(out / "ballplate_MB1.csv", "MB1")
    _cli("calibrate", "MB1", ex["path"], "--parameters", "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z",
         "--degree", "1", "--json", out / "calibrate_ballplate.json",
         "--html", out / "calibrate_ballplate.html", "--map-out", out / "map_ballplate.csv")
    rep = json.loads((out / "calibrate_ballplate.json").read_text())
    rows = [f"{n} {num(v['value'], '+.4g')} +/- {num(v['std'], '.2g')} (planted {num(ex['truth'][n], '+.4g')}) "
            f"{v['unit']}" for n, v in rep["parameters"].items()]
    worst = max(abs(_largest_difference_um(rep["poses"][f"ballplate_MB1.csv#{k}"]["origin_mm"], o))
                for k, (_, o) in ex["poses"].items())
    m, c = rep["volumetric_map"], rep["consistency"]["files"][0]
    _parameter_figure(out / "calibrate_ballplate.png", rep, ex["truth"])
    return {"title": "ball plate (5 x 5) in four placements on MB1 -> volerr calibrate",
            "value": "; ".join(rows) + f"; poses within {num(worst, '.2f')} um of the planted ones; "
                     f"Birge ratio {num(c['birge_ratio'], '.2f')} (consistent: {c['consistent']}); "
                     f"map up to {num(m['max_length_um'], '.1f')} um, its standard uncertainty up to "
                     f"{num(m['u_max_um'], '.2f')} um; ISO 10360-2 max |E| of the identified model "
                     f"{num(rep['iso10360']['max_abs_E_um'], '.2f')} um",
            "files": ["ballplate_MB1.csv", "calibrate_ballplate.json",
                      "calibrate_ballplate.html", "map_ballplate.csv",
                      "calibrate_ballplate.png"]}


def _largest_difference_um(a, b) -> float:
    """Largest coordinate difference of two points, um."""
    return 1e3 * max(abs(float(x) - float(y)) for x, y in zip(a, b))


def _multilateration(out: Path) -> dict:
    from ..calibrate.examples import write_multilateration_example
    from ..units import num

    ex = write_multilateration_example(out / "multilateration_DMU50.csv", "DMU50")
    _cli("calibrate", "DMU50", ex["path"], "--parameters", ex["parameters"], "--degree", "1",
         "--json", out / "calibrate_multilateration.json",
         "--html", out / "calibrate_multilateration.html")
    rep = json.loads((out / "calibrate_multilateration.json").read_text())
    rows = [f"{n} {num(v['value'], '+.4g')} +/- {num(v['std'], '.2g')} (planted {num(ex['truth'].get(n, 0), '+.4g')})"
            f" {v['unit']}" for n, v in rep["parameters"].items()]
    found = {k.split("#")[1]: v["position_mm"] for k, v in rep["stations"].items()}
    st = "; ".join(f"{k} {num(_largest_difference_um(found[k], s), '.2f')} um"
                   for k, s in ex["stations"].items())
    _parameter_figure(out / "calibrate_multilateration.png", rep, ex["truth"])
    return {"title": "multilateration on the DMU50: 4 stations x 200 poses -> volerr calibrate",
            "value": "; ".join(rows) + f"; stations found within (largest coordinate "
                     f"difference): {st}; not determined: "
                     f"{', '.join(rep['unidentifiable']) or 'none'}",
            "files": ["multilateration_DMU50.csv", "calibrate_multilateration.json",
                      "calibrate_multilateration.html", "calibrate_multilateration.png"]}


def _parameter_figure(path: Path, rep: dict, truth: dict) -> None:
    """Identified values (k = 2 bars) beside the planted truth."""
    from ..calibrate.report import parameter_figure
    from ..plotstyle import save

    save(parameter_figure(rep["parameters"], truth), path)


def _fiveaxis(out: Path) -> dict:
    from ..fiveaxis.example import write_example

    ex = write_example(out / "dmu50", "DMU50")
    results = {}
    for strategy in ("full", "thesis"):
        _cli("compensate", "DMU50", "--errors", ex["errors"], ex["program"], "--strategy",
             strategy, "--out", out / "dmu50" / f"hemisphere_{strategy}.nc",
             "--json", out / "dmu50" / f"compensate_{strategy}.json",
             "--plot", out / f"compensate_{strategy}.png")
        results[strategy] = json.loads((out / "dmu50" / f"compensate_{strategy}.json").read_text())
    _cli("tcpmap", "DMU50", "--errors", ex["errors"], "--point", 30, 20, 60,
         "--out", out / "tcpmap_DMU50.png")
    f, t = results["full"], results["thesis"]
    return {"title": f"five-axis DMU50: hemisphere program ({f['motion_blocks']} blocks, "
                     "synthetic error tables) compensated",
            "value": f"predicted tool-tip error max {f['max_before_um']:.1f} -> "
                     f"{f['max_after_um']:.3f} um, RMS {f['rms_before_um']:.1f} -> "
                     f"{f['rms_after_um']:.3f} um (thesis strategy: max "
                     f"{t['max_after_um']:.1f}, RMS {t['rms_after_um']:.1f} um)",
            "files": ["dmu50/", "compensate_full.png", "compensate_thesis.png",
                      "tcpmap_DMU50.png"]}


def _loop(out: Path) -> dict:
    from ..loop.run import demo_campaign

    layout, data = demo_campaign(out / "loop_measured.csv", kind="thermal_lag")
    _cli("loop", layout, data, "--json", out / "loop.json", "--html", out / "loop.html",
         "--out-dir", out)
    rep = json.loads((out / "loop.json").read_text())
    found = ", ".join(f"{e['kind']} ({e['name']}" + (
        f", lag of {e['covariate']} {e['lag_s']['value'] / 60:.0f} min" if e.get("lag_s")
        else "") + ")" for e in rep["effects"]) or "none"
    return {"title": f"closed loop on a virtual {layout} ({rep['n_points']} points)",
            "value": f"held-out RMS {rep['rms_before_um']:.2f} -> {rep['rms_after_um']:.2f} um, "
                     f"max {rep['max_before_um']:.2f} -> {rep['max_after_um']:.2f} um; "
                     f"effect found: {found}",
            "files": ["loop_measured.csv", "loop.json", "loop.html"]}


def _iso230_2(out: Path) -> dict:
    from ..example_files import write_iso230_2_run

    write_iso230_2_run(out / "iso230_2_run_X.csv")
    _cli("iso230-2", out / "iso230_2_run_X.csv", "--axis", "X", "--json", out / "iso230_2.json",
         "--plot", out / "iso230_2.png", "--html", out / "iso230_2.html",
         "--tolerance", DEMO_TOLERANCE, "--machine", "virtual machine, axis X (demo)",
         "--cte-ppm-per-K", 11.5, "--material-temp-C", 20.0, "--eve-um", 0.3,
         "--instrument", "simulated laser interferometer", "--operator", "volerr demo")
    r = json.loads((out / "iso230_2.json").read_text())
    U = r["uncertainty_um"]
    return {"title": "ISO 230-2 evaluation of a simulated positioning run of X",
            "value": ", ".join(f"{q} {num(r[q + '_um'], '.2f')} \u00b1 {num(U[q], '.2f')}"
                               for q in "AERBM") + " \u00b5m (U, k = 2); verdict against "
                     f"{DEMO_TOLERANCE} \u00b5m: {r['verdict']}",
            "files": ["iso230_2_run_X.csv", "iso230_2.json", "iso230_2.html", "iso230_2.png"]}


def _uncertainty(out: Path) -> dict:
    from ..cmm.examples import write_example_errors

    errors = out / "errors_MH2_u"
    write_example_errors(errors, "MH2")
    write_text(out / "task_distance.csv", "X,Y,Z\n100,200,150\n500,200,150\n")
    _cli("uncertainty", "MH2", "--task", out / "task_distance.csv", "--evaluate", "distance",
         "--errors", errors, "--repeatability", "--noise-um", 0.5, "--samples", 2000,
         "--seed", 1, "--quiet", "--json", out / "uncertainty.json",
         "--plot", out / "uncertainty.png", "--html", out / "uncertainty.html")
    q = json.loads((out / "uncertainty.json").read_text())["quantities"]["distance"]
    lo, hi = q["result_interval_mm"]
    return {"title": "task-specific uncertainty of a 400 mm distance on MH2 (Monte Carlo, "
                     "2000 samples)",
            "value": f"corrected result {num(q['result_mm'], '.4f')} mm, U "
                     f"{num(q['expanded_uncertainty_um'], '.2f')} \u00b5m (k = 2), 95 % "
                     f"interval [{num(lo, '.4f')}, {num(hi, '.4f')}] mm (nominal "
                     f"{num(q['nominal_mm'], '.4f')} mm; the machine reads "
                     f"{num(q['estimate_mm'], '.4f')} mm, bias {num(q['bias_um'], '+.2f')} "
                     f"\u00b5m)",
            "files": ["uncertainty.html", "task_distance.csv", "errors_MH2_u/",
                      "uncertainty.json", "uncertainty.png"]}


#: the demo's planned campaigns: layout, instruments, readings, --parameters, planted errors
#: (mm / rad)
PLAN_CASES = (
    ("DMU50", ("sphere:tool=100:tool_u_um=0.5",), 300, None,
     {"EX0B": 20e-3, "EY0B": -10e-3, "EA0B": 30e-6, "EB0B": -20e-6, "EX0C": 5e-3,
      "EY0C": 7e-3, "EA0C": 10e-6, "EB0C": 15e-6}),
    ("MB1", ("ballbar:u_um=0.5:lengths=150,250", "distances:stations=4"), 600, "squareness",
     {"EC0Y": 25e-6, "EB0Z": -15e-6, "EA0Z": 10e-6}))


def _plan(out: Path) -> dict:
    import numpy as np

    from ..machine.model import load
    from ..plan import comparison_png, execute

    rows, files, values = [], [], []
    for layout, specs, n, params, truth in PLAN_CASES:
        folder, js, cj = out / f"plan_{layout}", out / f"plan_{layout}.json", \
            out / f"plan_{layout}_calibrate.json"
        inst = [a for s in specs for a in ("--instrument", s)]
        _cli("plan", layout, *inst, "--readings", n, "--out", folder, "--json", js,
             *(("--parameters", params) if params else ()))
        doc = json.loads(js.read_text())
        rng = np.random.default_rng(7)
        model = load(layout)
        for f in doc["files"]:
            execute(folder / f["file"], model, truth, rng)
        _cli("calibrate", layout, *[folder / f["file"] for f in doc["files"]], "--json", cj)
        cal = json.loads(cj.read_text())["parameters"]
        for name, v in doc["parameters"].items():
            rows.append((f"{layout} {name}", v["predicted_std"], cal[name]["std"], v["unit"]))
        ratio = [cal[k]["std"] / v["predicted_std"] for k, v in doc["parameters"].items()]
        values.append(f"{layout} ({' + '.join(sorted({f['kind'] for f in doc['files']}))}, "
                      f"{doc['readings']} readings, {len(doc['files'])} files): realised / "
                      f"predicted std {min(ratio):.2f}-{max(ratio):.2f}; map u RMS "
                      f"{doc['map_u_um']['rms']:.3g} um vs {doc['baseline']['map_u_um']['rms']:.3g}"
                      f" um for {doc['baseline']['name']}")
        files += [f"plan_{layout}/", f"plan_{layout}.json", f"plan_{layout}/plan.html",
                  f"plan_{layout}_calibrate.json"]
    write_bytes_png(out / "plan_predicted.png", comparison_png(rows))
    return {"title": "measurement plans before the machine time: DMU50 R-test, MB1 ballbar + "
                     "tracking interferometer, executed and calibrated",
            "value": "; ".join(values), "files": files + ["plan_predicted.png"]}


def _check(out: Path) -> dict:
    """Weekly interim checks of a DMU 50 (:mod:`volerr.check.demo`); the history page when
    ``volerr history`` is installed (its command module present)."""
    import importlib.util

    from ..check import demo

    from ..errors import InputError

    run = demo.weekly(out)
    files, note = list(run["files"]), ""
    if importlib.util.find_spec("volerr.cli.history") is not None:
        db = out / "check_history.sqlite"
        try:
            _cli("history", "add", "--db", db, "--machine", "DMU50 demo", run["reference"],
                 *run["checks"])
            _cli("history", "show", "--db", db, "--machine", "DMU50 demo", "--tolerance",
                 demo.TOLERANCE, "--json",
                 out / "check_history.json", "--html", out / "check_history.html")
            files += ["check_history.sqlite", "check_history.json", "check_history.html"]
        except InputError as exc:      # the history's own refusal, named on the page
            note = f"; history page not drawn: {exc}"
    return {"title": "between calibrations: a DMU 50 checked weekly (a drifting pivot, a "
                     "collision at week 12)", "value": demo.summary(run) + note,
            "files": files}


def write_bytes_png(path: Path, data: bytes) -> None:
    from ..fileio import write_bytes

    write_bytes(path, data)


def _index(out: Path, results: list) -> None:
    """index.html: a section per step with its figures (each shown at its own pixel width,
    :func:`volerr.plotstyle.img_tag`), captions, the result line, a link to every report page
    (HTML) the step wrote and to every file."""
    from html import escape

    from ..plotstyle import img_tag, png_size

    parts = []
    toc = []
    pages = []
    for i, r in enumerate(results, start=1):
        sid = f"s{i}"
        toc.append(f'<li><a href="#{sid}">{escape(r["title"])}</a></li>')
        files = " ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in r["files"])
        reports = [f for f in r["files"] if f.endswith(".html")]
        pages += reports
        figs = []
        for f in r["files"]:
            if f.endswith(".png"):
                cap = CAPTIONS.get(f, f)
                width = png_size((out / f).read_bytes()[:32])[0]
                figs.append(f'<figure>{img_tag(f, cap, width=width, link=f)}'
                            f'<figcaption>{escape(cap)} <span class="file">({escape(f)})'
                            f'</span></figcaption></figure>')
        report_links = (f'<p class="pages">Report page{"s" if len(reports) > 1 else ""}: '
                        + " ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in reports)
                        + "</p>") if reports else ""
        parts.append(
            f'<section id="{sid}"><h2>{i}. {escape(r["title"])}</h2>'
            f'<p>{escape(ABOUT.get(r.get("section", ""), ""))}</p>'
            f'<p class="result"><strong>Result:</strong> {escape(r["value"])} '
            f'<span class="file">[{r.get("seconds", 0)} s]</span></p>'
            + report_links + "".join(figs) + f'<p class="files">Files: {files}</p></section>')
    page_list = ", ".join(f'<a href="{escape(f)}">{escape(f)}</a>' for f in pages)
    html = ("<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">"
            "<title>volerr demo</title><style>"
            "body{font-family:system-ui,sans-serif;font-size:17px;line-height:1.5;"
            "max-width:1200px;margin:2em auto;padding:0 1em;color:#222}"
            "h1{font-size:1.9em}h2{font-size:1.35em;border-bottom:2px solid #ddd;"
            "padding-bottom:.2em;margin-top:2em}"
            "figure{margin:1.2em 0}img{max-width:100%;height:auto;border:1px solid #eee}"
            "figcaption{font-size:.95em;color:#444}.file{color:#777;font-size:.9em}"
            ".result{background:#f5f7fa;padding:.6em .9em;border-left:4px solid #4a7}"
            ".files a{margin-right:.8em}</style></head><body>"
            "<h1>volerr demo</h1><p>Every step below ran a real <code>volerr</code> command "
            "on built-in data; units µm and µrad unless stated.  Click a figure for full "
            "size; the files next to this page hold every number.  Report pages: "
            f"{page_list}.</p>"
            f"<ol>{''.join(toc)}</ol>{''.join(parts)}</body></html>\n")
    write_text(out / "index.html", html)


def _refuse_used_folder(folder: Path, force: bool) -> None:
    """Before any computing: the demo writes some hundred files whose names are known only
    once it has run, so a folder that holds any file already is refused without --force
    (a second run into the same folder would otherwise compute for 20 s and then refuse)."""
    if force or not folder.is_dir():
        return
    held = sorted(p.name for p in folder.iterdir() if not p.name.startswith(".volerr-"))
    require(not held, f"--out {folder}: the folder holds files already ({held[0]}"
                      f"{f' and {len(held) - 1} more' if len(held) > 1 else ''}); give "
                      f"--force to replace the demo's files, or a new or empty folder")


def run(args) -> int:
    import os

    from ..fileio import Outputs

    final = Path(args.out)
    outs = Outputs(force=args.force).folder("--out", final).check()
    _refuse_used_folder(final, args.force)
    results = []
    t0 = time.perf_counter()
    here = os.getcwd()
    with outs:
        staged = outs.path("--out")
        os.chdir(staged)  # relative paths: the reports name files as they will be found
        try:
            out = Path(".")
            steps = {
                "cmm_a": lambda: _cmm(out, "MB1", "CMM A of Pahk"),
                "cmm_b": lambda: _cmm(out, "MH2", "CMM B of Pahk"),
                "audit": lambda: _audit(out),
                "probe": lambda: _probe(out),
                "identify": lambda: _identify(out),
                "ballbar": lambda: _ballbar(out),
                "rotary": lambda: _rotary(out),
                "ballplate": lambda: _ballplate(out),
                "multilateration": lambda: _multilateration(out),
                "fiveaxis": lambda: _fiveaxis(out),
                "loop": lambda: _loop(out),
                "iso230_2": lambda: _iso230_2(out),
                "uncertainty": lambda: _uncertainty(out),
                "plan": lambda: _plan(out),
                "check": lambda: _check(out),
            }
            from ..progress import bar

            todo = args.only or SECTIONS
            progress = bar(len(todo), "volerr demo", unit="section")
            for name in todo:
                progress.set_postfix_str(name)
                t = time.perf_counter()
                r = steps[name]()
                progress.update()
                r["section"] = name
                r["seconds"] = round(time.perf_counter() - t, 1)
                results.append(r)
                print(f"{r['title']}: {r['value']}  [{r['seconds']} s]")
            progress.close()
            _index(out, results)
            write_text(out / "summary.json", json_text(results))
        finally:
            os.chdir(here)
    print(f"report: {final / 'index.html'}  ({time.perf_counter() - t0:.0f} s)")
    return 0
