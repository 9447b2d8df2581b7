"""The demo's machine-tool sections: the five-axis DMU 50 (compensation, tool-tip map), the
closed loop, ISO 230-2 and the weekly interim checks with the history.  Each takes the run's
:class:`volerr.demo.work.Work` and returns its section (``title``, ``value``, ``files``)."""

from __future__ import annotations

from ..units import num
from .text import DEMO_TOLERANCE

#: the workpiece point of the demo's tool-tip map, mm
TCP_POINT = (30.0, 20.0, 60.0)


def fiveaxis(w) -> dict:
    """A hemisphere finishing program compensated (full model, thesis strategy) and the
    tool-tip error over the (B, C) range."""
    import json

    from ..fiveaxis.api import compensate
    from ..fiveaxis.example import write_example
    from ..fiveaxis.plots import plot_program_errors

    ex = write_example(w.out / "dmu50", "DMU50")
    with open(ex["program"], encoding="latin-1", newline="") as f:
        program = f.read()   # as written, line endings kept (the command streams it so)
    results = {}
    for strategy in ("full", "thesis"):
        res = compensate("DMU50", program, ex["errors"], strategy=strategy)
        results[strategy] = s = res.to_dict()
        w.later(f"dmu50/hemisphere_{strategy}.nc",
                lambda p, t=res.text: p.write_bytes(t.encode("latin-1")))
        w.later(f"dmu50/compensate_{strategy}.json",
                lambda p, s=s: p.write_text(json.dumps(s, indent=2) + "\n"))
        w.later(f"compensate_{strategy}.png", lambda p, b=res.blocks: plot_program_errors(
            b, p, title=f"DMU50: {ex['program']}"))
    _tcp_map(w, ex["errors"])
    f, t = results["full"], results["thesis"]
    return {"title": f"five-axis DMU50: hemisphere program ({f['motion_blocks']} blocks, "
                     "synthetic error tables) compensated",
            "value": f"predicted tool-tip error max {f['max_before_um']:.1f} -> "
                     f"{f['max_after_um']:.3f} um, RMS {f['rms_before_um']:.1f} -> "
                     f"{f['rms_after_um']:.3f} um (thesis strategy: max "
                     f"{t['max_after_um']:.1f}, RMS {t['rms_after_um']:.1f} um)",
            "files": ["dmu50/", "compensate_full.png", "compensate_thesis.png",
                      "tcpmap_DMU50.png"]}


def _tcp_map(w, errors) -> None:
    """``tcpmap_DMU50.png``: the tool-tip error at :data:`TCP_POINT` over B and C."""
    from ..fiveaxis.compensate import error_functions
    from ..fiveaxis.plots import plot_tcp_error_map
    from ..fiveaxis.tcpmap import tcp_map

    model = w.model("DMU50")
    funcs, _ = error_functions(errors, model)
    tmap = tcp_map(model, funcs, TCP_POINT, (0.0, 0.0, 0.0), 73, 73)
    w.later("tcpmap_DMU50.png", lambda p: plot_tcp_error_map(tmap, p))


def loop(w) -> dict:
    """A virtual MB1 with an undeclared thermal lag: fit, diagnosis, augmented model."""
    from ..loop.api import loop as close_loop
    from ..loop.run import demo_campaign

    layout, data = demo_campaign(w.out / "loop_measured.csv", kind="thermal_lag")
    report = close_loop(layout, data, out_dir=w.out)
    w.later("loop.json", report.write_json)
    w.later("loop.html", report.write_html)
    rep = report.to_dict()
    found = ", ".join(f"{e['kind']} ({e['name']}" + (
        f", lag of {e['covariate']} {e['lag_s']['value'] / 60:.0f} min" if e.get("lag_s")
        else "") + ")" for e in rep["effects"]) or "none"
    return {"title": f"closed loop on a virtual {layout} ({rep['n_points']} points)",
            "value": f"held-out RMS {rep['rms_before_um']:.2f} -> {rep['rms_after_um']:.2f} um, "
                     f"max {rep['max_before_um']:.2f} -> {rep['max_after_um']:.2f} um; "
                     f"effect found: {found}",
            "files": ["loop_measured.csv", "loop.json", "loop.html"]}


def iso230_2(w) -> dict:
    """A simulated positioning run of X evaluated as ISO 230-2, with its certificate."""
    from ..certificate import Identification
    from ..example_files import write_iso230_2_run
    from ..fileio import json_text
    from ..positioning.api import iso230_2 as evaluate

    run = w.out / "iso230_2_run_X.csv"
    write_iso230_2_run(run)
    ident = Identification("virtual machine, axis X (demo)", "simulated laser interferometer",
                           "volerr demo", conditions={
                               "expansion coefficient": "11.5 ppm/K (corrected to 20 \u00b0C)",
                               "material temperature": "20 \u00b0C"})
    res = evaluate([run], "X", tolerance=DEMO_TOLERANCE, eve_um=0.3, cte_ppm_per_K=11.5,
                   material_temp_C=20.0, identification=ident)
    r = res.to_dict()
    w.text("iso230_2.json", json_text(res.data))
    png = res.png()
    w.later("iso230_2.png", lambda p: _write_bytes(p, png))
    w.later("iso230_2.html", lambda p: res.write_html(p, inputs=[run], png=png))
    U = r["uncertainty_um"]
    return {"title": "ISO 230-2 evaluation of a simulated positioning run of X",
            "value": ", ".join(f"{q} {num(r[q + '_um'], '.2f')} \u00b1 {num(U[q], '.2f')}"
                               for q in "AERBM") + " \u00b5m (U, k = 2); verdict against "
                     f"{DEMO_TOLERANCE} \u00b5m: {r['verdict']}",
            "files": ["iso230_2_run_X.csv", "iso230_2.json", "iso230_2.html", "iso230_2.png"]}


def _write_bytes(path, data: bytes) -> None:
    from ..fileio import write_bytes

    write_bytes(path, data)


def check(w) -> dict:
    """Weekly interim checks of a DMU 50 (:mod:`volerr.check.demo`); the history page when
    :mod:`volerr.history` can store them (its refusal named on the page otherwise)."""
    import importlib.util

    from ..check import demo
    from ..errors import InputError

    run = demo.weekly(w.out)
    files, note = list(run["files"]), ""
    if importlib.util.find_spec("volerr.history") is not None:
        from .. import history

        db = str(w.out / "check_history.sqlite")
        try:
            history.add(db, "DMU50 demo", [str(p) for p in (run["reference"], *run["checks"])],
                        None, 10.0)
            h = history.show(db, "DMU50 demo", demo.TOLERANCE, 10.0)
            w.later("check_history.json", h.write_json)
            w.later("check_history.html", lambda p: _write_text(p, h.html()))
            files += ["check_history.sqlite", "check_history.json", "check_history.html"]
        except InputError as exc:      # the history's own refusal, named on the page
            note = f"; history page not drawn: {exc}"
    return {"title": "between calibrations: a DMU 50 checked weekly (a drifting pivot, a "
                     "collision at week 12)", "value": demo.summary(run) + note,
            "files": files}


def _write_text(path, text: str) -> None:
    from ..fileio import write_text

    write_text(path, text)
