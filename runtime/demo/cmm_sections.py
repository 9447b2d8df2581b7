"""The demo's CMM sections: Pahk's CMMs A and B (map, diagonals), the audit of the printed
equations, the probe calibration, the laser-tracker identification and the task-specific
uncertainty.  Each takes the run's :class:`volerr.demo.work.Work` and returns its section
(``title``, ``value``: the headline, ``files``: what it wrote, relative to the folder)."""

from __future__ import annotations

from ..units import num
from .text import DEMO_AUDIT


def cmm(w, layout: str, label: str) -> dict:
    """Example error tables of ``layout``, the volumetric map and the space diagonals."""
    from ..cmm import diagonals as dg, volmap
    from ..cmm.api import diagonals, error_map
    from ..cmm.examples import write_example_errors
    from ..tables.functions import ErrorFunctions

    errors = w.out / f"errors_{layout}"
    write_example_errors(errors, layout)
    model = w.model(layout)
    funcs = ErrorFunctions.from_dir(errors, model)
    vmap = error_map(model, funcs).map
    w.later(f"map_{layout}.csv", lambda p: volmap.write_map_csv(p, vmap))
    w.later(f"map_{layout}.png", lambda p: volmap.plot_map(vmap, p))
    files = [f"errors_{layout}/", f"map_{layout}.csv", f"map_{layout}.png"]
    if funcs.has_random:
        rnd = volmap.random_plot_path(f"map_{layout}.png")
        w.later(str(rnd), lambda p: volmap.plot_random(vmap, p))
        files.append(str(rnd))
    res = diagonals(model, funcs)
    res.data["errors"] = str(errors)
    w.later(f"diagonals_{layout}.json", res.write_json)
    w.later(f"diagonals_{layout}.png", lambda p: dg.plot_lines(
        res.lines, p, f"{model.name}: length deviations ({errors})"))
    space = [ln for ln in res.to_dict()["lines"] if ln.get("kind") == "space"]
    # each diagonal named by its corners (x y z; 0 the start of travel, 1 its end): the bare
    # list "-10.9, +34.5, -8.1, +11.4 um" did not say which diagonal was which
    text = ", ".join(f"{ln['name']} {ln['deviation_um']:+.1f}" for ln in space)
    rand = [ln.get("random_um") for ln in space if ln.get("random_um") is not None]
    text += (" um (random " + ", ".join(f"{r:.1f}" for r in rand) + " um)") if rand else " um"
    text += "; diagonal from corner to corner, x y z: 0 the start of travel, 1 its end"
    return {"title": f"{label} ({layout}): space diagonals", "value": text,
            "files": files + [f"diagonals_{layout}.json", f"diagonals_{layout}.png"]}


def audit(w) -> dict:
    """The derived CMM models against Pahk's printed equations (``volerr audit``)."""
    from ..audit import render_html, run as audit_run
    from ..fileio import json_text
    from ..progress import progress

    _, verdicts = audit_run.collect(audit_run.resolve_layouts(list(DEMO_AUDIT)),
                                    progress=progress)
    entries = [v.as_dict() for v in verdicts]
    w.text("audit.json", json_text(entries, indent=1, ensure_ascii=False))
    w.later("audit.html", lambda p: w_text(p, render_html(entries)))
    equations = {}
    for v in entries:  # one verdict per component (dX, dY, the rule of dx(X) ...)
        key = (v["source"], v["equation"], v["layout"])
        equations[key] = equations.get(key, True) and v["verdict"] == "identical"
    bad = sum(1 for ok in equations.values() if not ok)
    wrong = sum(1 for v in entries if v["verdict"] != "identical")
    return {"title": "audit of Pahk's printed CMM equations (all sources: volerr audit)",
            "value": f"{len(equations)} printed equations: {len(equations) - bad} identical, "
                     f"{bad} with named errata ({wrong} of {len(entries)} components)",
            "files": ["audit.html", "audit.json"]}


def w_text(path, text: str) -> None:
    from ..fileio import write_text

    write_text(path, text)


def probe(w) -> dict:
    """A simulated 3-lobe probe on Pahk's 101-point plan (``volerr probe-cal``)."""
    from ..fileio import json_text
    from ..probe import calibration
    from ..probe.api import probe_cal
    from ..probe.plans import simulate_demo_sphere
    from ..probe.plots import plot_probe_calibration

    data = simulate_demo_sphere(w.out / "sphere_probing.csv")
    res = probe_cal(data["path"], data["sphere_radius_mm"])
    cal = res.calibration
    w.text("probe_map.csv", calibration.map_csv_text(cal))
    w.text("probe_cal.json", json_text(res.data))
    w.later("probe_map.png", lambda p: plot_probe_calibration(cal, p))
    s = res.to_dict()
    e = s["probe_error_um"]
    return {"title": "probe calibration (101-point plan, simulated 3-lobe probe)",
            "value": f"R_eff {s['r_eff_mm']:.4f} mm; probe error max {e['max']:+.1f}, "
                     f"min {e['min']:+.1f}, RMS {e['rms']:.1f} um",
            "files": ["sphere_probing.csv", "probe_map.csv", "probe_cal.json", "probe_map.png"]}


def identify(w) -> dict:
    """Shipped laser-tracker data of MB1: the error motions of X, Y, Z, the squareness from
    the straightness reference lines, the space diagonals of the measured machine."""
    from ..cmm.api import diagonals, squareness
    from ..fileio import write_text
    from ..identify.api import identify as identify_axis
    from ..identify.plots import plot_identification
    from ..identify.tracker_io import example_path
    from ..tables.errorfit import fit_table
    from ..tables.table import table_to_csv

    measured = w.out / "tracker_identified"
    measured.mkdir(parents=True, exist_ok=True)
    for axis in ("X", "Y", "Z"):
        res = identify_axis("MB1", axis, [example_path(axis)])
        table = res.errors
        fits = fit_table(table, "poly", weighted=table.std != {})
        write_text(measured / f"{axis}.csv", table_to_csv(table))
        w.later(f"identified_{axis}.png", lambda p, r=res.identification, f=fits:
                plot_identification(r, p, f))
    sq = squareness("MB1", measured)
    sq.write_dir(w.out / "tracker_errors")
    w.later("squareness.json", sq.write_json)
    doc = sq.to_dict()
    u = doc["u_urad"]
    text = ", ".join(f"{k} {v:+.1f} +/- {u[k]:.1f}" for k, v in doc["squareness_urad"].items())
    diag = diagonals(w.model("MB1"), w.out / "tracker_errors", method="poly",
                     volume="measured")
    diag.data["errors"] = str(w.out / "tracker_errors")
    w.later("diagonals_tracker.json", diag.write_json)
    space = [ln["deviation_um"] for ln in diag.to_dict()["lines"] if ln["kind"] == "space"]
    return {"title": "laser-tracker identification of MB1 X, Y, Z (shipped example data: 3 "
                     "points, 11 positions, 4 rounds) -> squareness -> space diagonals",
            "value": f"squareness {text} urad (k = 1; simulated truth EC0Y +20, EB0Z -15, "
                     "EA0Z +10); "
                     "space diagonals " + ", ".join(f"{d:+.1f}" for d in space) + " um",
            "files": ["tracker_identified/", "tracker_errors/", "squareness.json",
                      "identified_X.png", "identified_Y.png", "identified_Z.png",
                      "diagonals_tracker.json"]}


def uncertainty(w) -> dict:
    """Task-specific uncertainty of a 400 mm distance on MH2 (``volerr uncertainty``)."""
    from ..cmm.examples import write_example_errors
    from ..fileio import write_bytes, write_text
    from ..plotstyle import png
    from ..uncertainty.api import uncertainty as task_uncertainty

    errors = w.out / "errors_MH2_u"
    write_example_errors(errors, "MH2")
    write_text(w.out / "task_distance.csv", "X,Y,Z\n100,200,150\n500,200,150\n")
    res = task_uncertainty("MH2", w.out / "task_distance.csv", "distance", errors=errors,
                           repeatability=True, noise_um=0.5, samples=2000, seed=1)
    w.later("uncertainty.json", res.write_json)
    hist = w.once(lambda: png(res.figures()["histogram"]))      # the file and the page
    w.later("uncertainty.png", lambda p: write_bytes(p, hist()))
    w.later("uncertainty.html", lambda p: res.write_html(p, histogram=hist()))
    q = res.to_dict()["quantities"]["distance"]
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
