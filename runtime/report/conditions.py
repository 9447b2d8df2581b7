"""The test conditions of each standard's test, as a certificate states them (Renishaw's
ballbar reports and ISO 230-4 clause 6, ISO 230-2 clause 5, ISO 230-3 clause 5, ISO 10360-2
clause 6): the list of conditions per standard (:data:`FIELDS`), each filled from the
result's JSON where volerr measured or was told it, else from the ``[conditions]`` table of
the identification file (``feed = "1000 mm/min"``, ``compensation = "on (controller table
2026-03)"`` ...), else shown as "not stated" -- so a page never hides that a condition is
missing.

:func:`of` tells the test from the command (the identification's method) or the JSON's
keys, and returns ``{"standard": name, label: text, ...}``."""

from __future__ import annotations

NOT_STATED = "not stated"

#: the conditions each standard asks to be stated, in the order they are printed
FIELDS = {
    "ISO 230-4 (circular test, ballbar)": (
        "radius", "feed", "direction", "plane", "data capture arc", "overrun arcs",
        "readings", "ballbar calibration", "compensation", "machine temperature"),
    "ISO 230-2 (positioning, linear axis)": (
        "axis", "targets", "cycles", "approach", "overrun", "dwell", "feed",
        "compensation", "temperature correction"),
    "ISO 230-3 (thermal effects)": (
        "test", "programme stages", "sensor positions", "duration", "readings",
        "temperatures", "compensation"),
    "ISO 10360-2 (CMM length measurement)": (
        "lengths", "positions", "repetitions", "probe offset", "artefact",
        "artefact temperature", "compensation"),
    "sphere / R-test set-up": (
        "sphere radius", "readings", "positions", "probe / stylus", "compensation"),
    "ball / hole plate set-up": (
        "plate", "placements", "features", "readings", "plate calibration",
        "plate temperature", "compensation"),
}


def _join(values, unit: str = "") -> str:
    vals = sorted({f"{v:g}" if isinstance(v, (int, float)) else str(v) for v in values})
    return ", ".join(vals) + (f" {unit}" if unit and vals else "")


def _ballbar(doc: dict) -> dict:
    tr = [t for t in doc.get("traces") or [] if isinstance(t, dict)]
    return {"radius": _join((t.get("radius_mm") for t in tr), "mm"),
            "direction": _join(t.get("direction", "") for t in tr),
            "plane": _join(t.get("plane", "") for t in tr),
            "readings": _join((t.get("n") for t in tr), "per trace")}


def _iso230_2(doc: dict) -> dict:
    t = doc.get("targets_mm") or []
    out = {"axis": doc.get("axis"), "cycles": f"{doc.get('n_cycles')} per direction"}
    if t:
        out["targets"] = f"{len(t)} targets, {min(t):g} to {max(t):g} mm"
    if doc.get("mean_bwd_um") is not None:
        out["approach"] = "both directions (standard test cycle, linear)"
    tc = doc.get("temperature_correction")
    out["temperature correction"] = ("none (not corrected to 20 \u00b0C)"
                                     if not (tc or {}).get("applied") else
                                     f"to 20 \u00b0C, {tc.get('cte_ppm_per_K', '?')} ppm/K")
    return out


def _iso230_3(doc: dict) -> dict:
    ch = doc.get("channels") or {}
    return {"test": doc.get("test"), "readings": doc.get("n_readings"),
            "duration": (f"{doc['duration_s'] / 3600:.2f} h" if doc.get("duration_s")
                         else None),
            "programme stages": f"{len(doc.get('stages') or [])} stages"
                                + (f" by {doc['stage_column']}" if doc.get("stage_column") else ""),
            "sensor positions": "; ".join(_sensor(k, v) for k, v in ch.items()),
            "temperatures": ", ".join(doc.get("temperatures") or {}) or None}


def _sensor(name: str, d: dict) -> str:
    """``ch1 (X, z 120 mm)``; what the file does not give is said so."""
    parts = [str(d["direction"]) if d.get("direction") else "direction not given",
             f"z {d['z_mm']:g} mm" if isinstance(d.get("z_mm"), (int, float)) else
             "height not given"]
    return f"{name} ({', '.join(parts)})"


def _iso10360(doc: dict) -> dict:
    pos = [p for p in doc.get("positions") or [] if isinstance(p, dict)]
    lengths = [x for p in pos for x in p.get("lengths_mm") or []]
    return {"probe offset": _join(doc.get("probe_mm") or [], "mm"),
            "positions": "; ".join(p.get("line", "") for p in pos) or None,
            "lengths": (f"{len(lengths) // max(len(pos), 1)} per position, "
                        f"{min(lengths):.1f} to {max(lengths):.1f} mm" if lengths else None),
            "repetitions": doc.get("repetitions"),
            "artefact": (doc.get("test_uncertainty") or {}).get("formula")}


def _sphere(doc: dict) -> dict:
    if "r_eff_mm" not in doc:          # a calibration from sphere / R-test files
        files = _files_of(doc, "sphere")
        return {"readings": sum(i.get("n_readings", 0) for i in files),
                "positions": _placements(doc, files)}
    return {"sphere radius": doc.get("sphere_radius_mm"), "readings": doc.get("n_points")}


def _plate(doc: dict) -> dict:
    files = _files_of(doc, "artifact")
    return {"plate": ", ".join(i.get("file", "") for i in files),
            "placements": _placements(doc, files),
            "features": f"{sum(i.get('n', 0) for i in files)} probed in all",
            "readings": sum(i.get("n_readings", 0) for i in files)}


def _files_of(doc: dict, kind: str) -> list:
    """The ``instruments`` entries of a calibration of the instrument ``kind``."""
    return [i for i in doc.get("instruments") or [] if isinstance(i, dict)
            and i.get("kind") == kind]


def _placements(doc: dict, files: list) -> str:
    """``4 (XYhigh, XYlow, XZ, YZ)``: the files' placements (their set-up keys ``F#P``)."""
    names = [k.split("#", 1)[1] for k in doc.get("setup") or {} if "#" in k
             and k.split("#", 1)[0] in {i.get("file") for i in files}]
    return f"{len(names)} ({', '.join(names)})" if names else "1"


_TESTS = (("ballbar", "ISO 230-4 (circular test, ballbar)", _ballbar, "traces"),
          ("iso230-2", "ISO 230-2 (positioning, linear axis)", _iso230_2, "targets_mm"),
          ("iso230-3", "ISO 230-3 (thermal effects)", _iso230_3, "stages"),
          ("iso10360", "ISO 10360-2 (CMM length measurement)", _iso10360, "max_abs_E_um"),
          ("probe-cal", "sphere / R-test set-up", _sphere, "r_eff_mm"),
          ("probe-cal", "sphere / R-test set-up", _sphere, "instrument:sphere"),
          ("probe-cal", "ball / hole plate set-up", _plate, "instrument:artifact"))


def _has(doc: dict, key: str) -> bool:
    """``key`` in the document, or ``instrument:KIND``: a calibration with a file of KIND."""
    if key.startswith("instrument:"):
        return bool(_files_of(doc, key.split(":", 1)[1]))
    return key in doc


def of(doc: dict, stated: dict | None = None) -> dict:
    """The test conditions of ``doc`` (empty when it is no standard's test): the standard and
    every field of :data:`FIELDS`, from the data, else ``stated`` (the identification file's
    ``[conditions]``), else "not stated"."""
    command = ((doc.get("identification") or {}).get("method") or {}).get("command", "")
    stated = {str(k).lower(): v for k, v in (stated or {}).items()}
    for word, standard, fill, key in _TESTS:
        runs = doc.get("runs") if isinstance(doc.get("runs"), list) else None
        probe = runs[0] if runs and isinstance(runs[0], dict) else doc
        if word in command or _has(probe, key):
            found = {k: v for k, v in fill(probe).items() if v not in (None, "")}
            cal = [i for i in (doc.get("identification") or {}).get("instruments") or []
                   if i.get("certificate")]
            if cal and word == "ballbar":
                found["ballbar calibration"] = "; ".join(
                    f"{i.get('id', '')} certificate {i['certificate']}" for i in cal)
            out = {"standard": standard}
            for name in FIELDS[standard]:
                value = found.get(name, stated.get(name, NOT_STATED))
                out[name] = value if isinstance(value, str) else f"{value:g}"
            return out
    return {}


def measured(doc: dict) -> list:
    """The standard's own results beside the result rows, as (heading, table rows): the
    ISO 230-4 G, H and F of every ballbar trace (µm; their U in the result rows, their
    budgets from :func:`volerr.ballbar.iso230_4.budgets`), nothing for the other tests."""
    from .fmt import number

    tr = [t for t in doc.get("traces") or [] if isinstance(t, dict) and "G_um" in t]
    if not tr:
        return []
    rows = [["file", "plane", "direction", "radius / mm", "G / \u00b5m", "H / \u00b5m",
             "F min / \u00b5m", "F max / \u00b5m"]]
    rows += [[t.get("file", ""), t.get("plane", ""), t.get("direction", ""),
              number(t.get("radius_mm")), number(t["G_um"]), number(t.get("H_um")),
              number(t.get("F_min_um")), number(t.get("F_max_um"))] for t in tr]
    return [("ISO 230-4 results per trace", "table", rows),
            (None, "text", "G: circular deviation, H: circular hysteresis, F: radial "
                           "deviation (ISO 230-4). Their u, k and U are in the results, "
                           "their uncertainty budgets below.")]
