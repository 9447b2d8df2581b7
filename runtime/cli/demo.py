"""``volerr demo [--out DIR]``: the whole pipeline on built-in data; writes a report.

Sections (each runs the real command or API on built-in data and writes into DIR):

1. CMM A of Pahk (MB1): example error tables, volumetric error map, space diagonals;
2. CMM B of Pahk (MH2): map with the random component, diagonals with their random part;
3. audit of the derived models against the printed equations;
4. probe calibration on a simulated master-sphere run (Pahk's 101-point plan);
5. laser-tracker identification of a simulated three-point campaign, squareness, diagonals;
6. five-axis DMU 50: a hemisphere finishing program compensated (full model and the thesis'
   strategy), tool-centre-point error over the (B, C) range;
7. closing the loop: a virtual MB1 with an undeclared effect, fit, diagnosis, augmented model;
8. ``index.html`` linking everything, and the headline figures printed.
"""

from __future__ import annotations

import contextlib
import io
import json
import time
from pathlib import Path

from volerr.errors import require
from volerr.fileio import write_text

SECTIONS = ("cmm_a", "cmm_b", "audit", "probe", "identify", "fiveaxis", "loop")


def register(sub) -> None:
    p = sub.add_parser("demo", help="the whole pipeline on built-in data; writes a report",
                       description=__doc__.split("\n\n")[0])
    p.add_argument("--out", default="volerr-demo", help="output folder (default volerr-demo)")
    p.add_argument("--only", nargs="+", choices=SECTIONS, help="run only these sections")
    p.set_defaults(func=run)


def _cli(*argv) -> str:
    """Run a volerr command in-process; return what it printed. Non-zero exit is an error."""
    from volerr.cli import main

    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        code = main([str(a) for a in argv])
    require(code == 0, f"demo step 'volerr {' '.join(map(str, argv))}' failed (exit {code})")
    return buf.getvalue()


def _cmm(out: Path, layout: str, label: str) -> dict:
    from volerr.cmm.examples import write_example_errors

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
    return {"title": f"{label} ({layout}): space diagonals", "value": text,
            "files": [f"errors_{layout}/", f"map_{layout}.csv", f"map_{layout}.png",
                      f"diagonals_{layout}.json", f"diagonals_{layout}.png"]}


#: the demo audits the CMM models (seconds); ``volerr audit`` alone audits everything
DEMO_AUDIT = ("MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY")


def _audit(out: Path) -> dict:
    _cli("audit", *DEMO_AUDIT, "--json", out / "audit.json")
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
            "files": ["audit.json"]}


def _probe(out: Path) -> dict:
    from volerr.probe.plans import simulate_demo_sphere

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
    from volerr.identify.tracker_io import example_path

    measured = out / "tracker_identified"
    for axis in ("X", "Y", "Z"):
        _cli("identify", "MB1", "--axis", axis, example_path(axis), "--fit", "poly",
             "--out", measured / f"{axis}.csv", "--plot", out / f"identified_{axis}.png")
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


def _fiveaxis(out: Path) -> dict:
    from volerr.fiveaxis.example import write_example

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
    from volerr.loop.run import demo_campaign

    layout, data = demo_campaign(out / "loop_measured.csv")
    _cli("loop", layout, data, "--json", out / "loop.json", "--html", out / "loop.html")
    rep = json.loads((out / "loop.json").read_text())
    found = ", ".join(f"{e['kind']} ({e['name']})" for e in rep["effects"]) or "none"
    return {"title": f"closed loop on a virtual {layout} ({rep['n_points']} points)",
            "value": f"held-out RMS {rep['rms_before_um']:.2f} -> {rep['rms_after_um']:.2f} um, "
                     f"max {rep['max_before_um']:.2f} -> {rep['max_after_um']:.2f} um; "
                     f"effect found: {found}",
            "files": ["loop_measured.csv", "loop.json", "loop.html"]}


def _index(out: Path, results: list) -> None:
    rows = "\n".join(
        f"<tr><td>{r['title']}</td><td>{r['value']}</td><td>"
        + " ".join(f'<a href="{f}">{f}</a>' for f in r["files"]) + "</td></tr>"
        for r in results)
    pngs = "\n".join(f'<figure><img src="{f}" width="640"><figcaption>{f}</figcaption></figure>'
                     for r in results for f in r["files"] if f.endswith(".png"))
    html = ("<!doctype html><html><head><meta charset='utf-8'><title>volerr demo</title>"
            "<style>body{font-family:sans-serif;margin:2em}td{padding:4px 10px;"
            "border-bottom:1px solid #ddd;vertical-align:top}</style></head><body>"
            "<h1>volerr demo</h1><table><tr><th>step</th><th>result</th><th>files</th></tr>"
            f"{rows}</table>{pngs}</body></html>\n")
    write_text(out / "index.html", html)


def run(args) -> int:
    import os

    from volerr.fileio import Outputs

    final = Path(args.out)
    outs = Outputs().folder("--out", final).check()
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
                "fiveaxis": lambda: _fiveaxis(out),
                "loop": lambda: _loop(out),
            }
            for name in args.only or SECTIONS:
                t = time.perf_counter()
                r = steps[name]()
                r["section"] = name
                r["seconds"] = round(time.perf_counter() - t, 1)
                results.append(r)
                print(f"{r['title']}: {r['value']}  [{r['seconds']} s]")
            _index(out, results)
            write_text(out / "summary.json", json.dumps(results, indent=2) + "\n")
        finally:
            os.chdir(here)
    print(f"report: {final / 'index.html'}  ({time.perf_counter() - t0:.0f} s)")
    return 0
