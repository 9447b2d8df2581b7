"""The demo's calibration sections: ballbar circles, the rotary axes from a sphere probing
cycle, a ball plate, multilateration, and the planned campaigns executed and calibrated.
Each takes the run's :class:`volerr.demo.work.Work` and returns its section (``title``,
``value``, ``files``)."""

from __future__ import annotations

from ..units import num
from .text import PLAN_CASES


def _parameter_figure(w, name: str, rep: dict, truth: dict) -> None:
    """Identified values (k = 2 bars) beside the planted truth, kept for the end."""
    from ..calibrate.report import parameter_figure

    w.figure(name, parameter_figure(rep["parameters"], truth))


def _calibrated(w, stem: str, result, html: bool = True) -> dict:
    """The ``--json`` (and ``--html``) of a calibration, kept for the end; its document."""
    w.later(f"{stem}.json", result.write_json)
    doc = result.to_dict()
    if html:
        w.later(f"{stem}.html", result.write_html)
    return doc


def ballbar(w) -> dict:
    """ISO 230-4 circles of MB1 in three planes: G, H and the diagnosis."""
    from ..ballbar.api import ballbar_evaluate
    from ..ballbar.plots import polar_png
    from ..ballbar.report import write_html
    from ..calibrate.examples import write_ballbar_example

    ex = write_ballbar_example(w.out / "ballbar")
    ev = ballbar_evaluate(ex["files"])
    w.later("ballbar.json", ev.write_json)
    polar = w.once(lambda: polar_png(ev.traces, ev.results))   # the file and the page
    w.later("ballbar_polar.png", lambda p: _write_bytes(p, polar()))
    w.later("ballbar.html", lambda p: write_html(p, ev, polar=polar()))
    rep = ev.to_dict()
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


def rotary(w) -> dict:
    """Location errors of the DMU 50's rotary axes from a sphere probing cycle."""
    from ..calibrate.examples import write_sphere_example
    from ..calibrate.run import calibrate

    ex = write_sphere_example(w.out / "sphere_DMU50.csv", "DMU50")
    result = calibrate("DMU50", [ex["path"]])
    rep = _calibrated(w, "calibrate_rotary", result)
    w.later("errors_rotary", result.write_error_tables)
    rows = [f"{name} {num(v['value'], '+.1f')} +/- {num(v['std'], '.1f')} (planted "
            f"{num(ex['truth'].get(name, 0.0), '+.1f')}) {v['unit']}"
            for name, v in rep["parameters"].items()]
    plan = "; ".join(f"{p['adds']} -> {', '.join(p['makes_identifiable'])}"
                     for p in rep["plan"] if p["makes_identifiable"])
    _parameter_figure(w, "calibrate_rotary.png", rep, ex["truth"])
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


def ballplate(w) -> dict:
    """A 5 x 5 ball plate in four placements on MB1 (scale, squareness, poses, map)."""
    from ..calibrate.examples import write_ballplate_example
    from ..calibrate.mapping import write_csv
    from ..calibrate.run import calibrate

    ex = write_ballplate_example(w.out / "ballplate_MB1.csv", "MB1")
    result = calibrate("MB1", [ex["path"]], parameters="EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z", degree=1)
    rep = _calibrated(w, "calibrate_ballplate", result)
    w.later("map_ballplate.csv", lambda p: write_csv(p, result, (9,) * 3))
    rows = [f"{n} {num(v['value'], '+.4g')} +/- {num(v['std'], '.2g')} (planted "
            f"{num(ex['truth'][n], '+.4g')}) {v['unit']}" for n, v in rep["parameters"].items()]
    worst = max(abs(_largest_difference_um(rep["poses"][f"ballplate_MB1.csv#{k}"]["origin_mm"],
                                           o)) for k, (_, o) in ex["poses"].items())
    m, c = rep["volumetric_map"], rep["consistency"]["files"][0]
    _parameter_figure(w, "calibrate_ballplate.png", rep, ex["truth"])
    return {"title": "ball plate (5 x 5) in four placements on MB1 -> volerr calibrate",
            "value": "; ".join(rows) + f"; poses within {num(worst, '.2f')} um of the planted "
                     f"ones; Birge ratio {num(c['birge_ratio'], '.2f')} (consistent: "
                     f"{c['consistent']}); map up to {num(m['max_length_um'], '.1f')} um, its "
                     f"standard uncertainty up to {num(m['u_max_um'], '.2f')} um; ISO 10360-2 "
                     f"max |E| of the identified model "
                     f"{num(rep['iso10360']['max_abs_E_um'], '.2f')} um",
            "files": ["ballplate_MB1.csv", "calibrate_ballplate.json",
                      "calibrate_ballplate.html", "map_ballplate.csv",
                      "calibrate_ballplate.png"]}


def _largest_difference_um(a, b) -> float:
    """Largest coordinate difference of two points, um."""
    return 1e3 * max(abs(float(x) - float(y)) for x, y in zip(a, b))


def multilateration(w) -> dict:
    """A tracking interferometer at four stations on the DMU 50 (self-calibrating)."""
    from ..calibrate.examples import write_multilateration_example
    from ..calibrate.run import calibrate

    ex = write_multilateration_example(w.out / "multilateration_DMU50.csv", "DMU50")
    result = calibrate("DMU50", [ex["path"]], parameters=ex["parameters"], degree=1)
    rep = _calibrated(w, "calibrate_multilateration", result)
    rows = [f"{n} {num(v['value'], '+.4g')} +/- {num(v['std'], '.2g')} (planted "
            f"{num(ex['truth'].get(n, 0), '+.4g')}) {v['unit']}"
            for n, v in rep["parameters"].items()]
    found = {k.split("#")[1]: v["position_mm"] for k, v in rep["stations"].items()}
    st = "; ".join(f"{k} {num(_largest_difference_um(found[k], s), '.2f')} um"
                   for k, s in ex["stations"].items())
    _parameter_figure(w, "calibrate_multilateration.png", rep, ex["truth"])
    return {"title": "multilateration on the DMU50: 4 stations x 200 poses -> volerr calibrate",
            "value": "; ".join(rows) + f"; stations found within (largest coordinate "
                     f"difference): {st}; not determined: "
                     f"{', '.join(rep['unidentifiable']) or 'none'}",
            "files": ["multilateration_DMU50.csv", "calibrate_multilateration.json",
                      "calibrate_multilateration.html", "calibrate_multilateration.png"]}


def plan(w) -> dict:
    """The planned campaigns (``volerr plan``) executed on the model and calibrated: the
    predicted against the realised standard uncertainties."""
    import numpy as np

    from ..calibrate.run import calibrate
    from ..machine.model import load
    from ..plan import comparison_png, execute, plan as make_plan

    rows, files, values = [], [], []
    for layout, specs, n, params, truth in PLAN_CASES:
        folder = w.out / f"plan_{layout}"
        result = make_plan(layout, list(specs), n, parameters=params)
        result.write(folder, w.out / f"plan_{layout}.json", None, (), "iso")
        doc = result.to_dict()
        rng = np.random.default_rng(7)
        model = load(layout)   # a fresh model: the executed readings as a new run has them
        for f in doc["files"]:
            execute(folder / f["file"], model, truth, rng)
        cal_result = calibrate(layout, [folder / f["file"] for f in doc["files"]])
        cal = _calibrated(w, f"plan_{layout}_calibrate", cal_result, html=False)["parameters"]
        for name, v in doc["parameters"].items():
            rows.append((f"{layout} {name}", v["predicted_std"], cal[name]["std"], v["unit"]))
        ratio = [cal[k]["std"] / v["predicted_std"] for k, v in doc["parameters"].items()]
        values.append(f"{layout} ({' + '.join(sorted({f['kind'] for f in doc['files']}))}, "
                      f"{doc['readings']} readings, {len(doc['files'])} files): realised / "
                      f"predicted std {min(ratio):.2f}-{max(ratio):.2f}; map u RMS "
                      f"{doc['map_u_um']['rms']:.3g} um vs "
                      f"{doc['baseline']['map_u_um']['rms']:.3g} um for "
                      f"{doc['baseline']['name']}")
        files += [f"plan_{layout}/", f"plan_{layout}.json", f"plan_{layout}/plan.html",
                  f"plan_{layout}_calibrate.json"]
    w.later("plan_predicted.png", lambda p: _write_bytes(p, comparison_png(rows)))
    return {"title": "measurement plans before the machine time: DMU50 R-test, MB1 ballbar + "
                     "tracking interferometer, executed and calibrated",
            "value": "; ".join(values), "files": files + ["plan_predicted.png"]}


def _write_bytes(path, data: bytes) -> None:
    from ..fileio import write_bytes

    write_bytes(path, data)
