"""The plan as data: the JSON report (INTERFACE.md "Planning", contracts), the console summary
and the header lines of the plan files."""

from __future__ import annotations

from . import _spec


def file_header(plan, pf) -> list:
    """``#`` comment lines of a plan file (what it is, how to fill it)."""
    inst = plan.instruments[pf.inst]
    reading = [k for k in _files_readings(pf.kind) if k in pf.columns]
    lines = [f"volerr plan: layout {plan.model.name}, {inst.kind} ({inst.text})",
             f"fill the reading columns ({', '.join(reading)}) and give the "
             f"filled files to: volerr calibrate {plan.model.name} FILES"]
    for s, m in pf.setups:
        lines.append(f"set-up {s.label}: {s.text}; {m} readings")
    if inst.kind == "interferometer":
        lines += line_header(pf.setups[0][0].line)
    elif inst.kind == "artifact":
        lines += [f"probe_u_um: {float(pf.columns['probe_u_um'][0]):g} (column probe_u_um: "
                  f"the standard uncertainty of one probed coordinate the plan assumes)",
                  f"u_std_um: {inst.cal_u_um:g} (column u_std_um: the plate's calibration)",
                  "x_nom_mm, y_nom_mm, z_nom_mm: where the plan puts each ball (machine "
                  "coordinates); fill x_mm, y_mm, z_mm with the centres the machine measures"]
    elif inst.u_um is not None or inst.kind != "distances":
        u = inst.u_um if inst.u_um is not None else float(pf.columns["u_um"][0])
        lines.append(f"u_um: {u:g} (column u_um: the standard uncertainty of one reading the "
                     f"plan assumes)")
    else:
        lines.append("u_um: 0.3 + 0.3 um/m x the distance (column u_um, per reading)")
    if inst.kind == "sphere" and inst.tool_u_um is not None:
        lines.append(f"tool_u_um: {inst.tool_u_um:g} (column tool_u_um)")
    if plan.parameters_text:
        lines.append(f"parameters: {plan.parameters_text}")
    return lines


def line_header(line) -> list:
    """The ``# key: value`` lines of an interferometer run (``volerr formats
    interferometer``): the line, its optics and the reading's standard uncertainty."""
    out = [f"axis: {line.axis}", f"mode: {line.mode}",
           "at: " + ", ".join(f"{a}={v:g}" for a, v in line.at.items()),
           "optics: " + ", ".join(f"{v:g}" for v in line.optics)]
    if line.sense is not None:
        out.append("sense: " + ", ".join(f"{v:g}" for v in line.sense))
    if line.mode == "angular":
        out += [f"separation: {line.separation:g}", f"u_urad: {line.u:g}"]
    else:
        out.append(f"u_um: {line.u:g}")
    return out


def _files_readings(kind: str):
    from ._files import READINGS

    return READINGS[kind]


def nc_name(pf, dialect: str = "iso") -> str:
    """The NC program's file name beside ``pf``: ``.nc`` (``.mpf`` SINUMERIK, ``.h``
    Heidenhain)."""
    from ._dialect import DIALECTS

    return pf.name[:-4] + DIALECTS[dialect].suffix


def _params(pred, alone=None) -> dict:
    out = {}
    for name, v in pred.parameters.items():
        entry = {"predicted_std": round(v["predicted_std"], 6), "unit": v["unit"]}
        if alone is not None:
            entry["determined_alone_by"] = [k for k, p in alone.items()
                                            if p is not None and name in p.determined]
        out[name] = entry
    return out


def _budgets(pred) -> dict:
    """The budget of every predicted std (:func:`volerr.calibrate.budget.budgets` on the
    plan's files, the variance factor at 1), restated for the rounded std of the JSON."""
    from ..report.budget import restated

    return {n: restated(b, round(pred.parameters[n]["predicted_std"], 6))
            for n, b in pred.budgets.items() if n in pred.parameters}


def data(plan) -> dict:
    """The JSON report of a plan."""
    pred, base = plan.prediction, plan.baseline["prediction"]
    files = []
    for pf, minutes in zip(plan.files, plan.minutes):
        files.append({"file": pf.name, "kind": pf.kind, "nc": nc_name(pf, plan.dialect),
                      "readings": pf.n,
                      "minutes": minutes,
                      "setups": [{"label": s.label, "text": s.text, "readings": int(m),
                                  **_geometry(s.geometry)} for s, m in pf.setups]})
    gain = ((1.0 - pred.map_u_um["rms"] / base.map_u_um["rms"]) if base.map_u_um["rms"]
            else None)
    return {
        "layout": plan.model.name,
        "readings": int(sum(pf.n for pf in plan.files)),
        "readings_requested": plan.readings,
        "criterion": {"I": "I-optimal (mean predicted variance of the volumetric error over "
                           "the map grid)", "D": "D-optimal (determinant of the information "
                                                 "matrix)"}[plan.criterion],
        "instruments": [{"spec": i.text, "kind": i.kind, "u_um": i.u_um} for i in
                        plan.instruments],
        "requested": list(plan.chosen),
        "parameters": _params(pred, plan.alone),
        "budgets": _budgets(pred),
        "unidentifiable": list(pred.unidentifiable),
        "why_unidentifiable": dict(pred.why),
        "only_combined": [n for n in pred.parameters
                          if not any(p is not None and n in p.determined
                                     for p in plan.alone.values())],
        "map_u_um": dict(pred.map_u_um),
        "map_grid": plan.map_grid,
        "baseline": {"name": plan.baseline["name"], "readings": plan.baseline["readings"],
                     "parameters": _params(base), "unidentifiable": list(base.unidentifiable),
                     "map_u_um": dict(base.map_u_um),
                     **({"why_none": plan.baseline["why"]} if "why" in plan.baseline else {})},
        "map_gain": None if gain is None else round(gain, 4),
        "minutes": round(plan.total_minutes, 1),
        "files": files,
        "nc_dialect": plan.dialect,
        "candidates": {"setups": plan.candidates, "readings": plan.candidate_readings},
        "time_model": {"setup_change_min": dict(_spec.SETUP_MIN),
                       "reading_s": dict(_spec.READING_S),
                       "ballbar_feed_mm_min": _spec.BALLBAR_FEED_MM_MIN,
                       "dwell_s": dict(_spec.DWELL_S)},
    }


def _geometry(g: dict) -> dict:
    out = {}
    for k, v in g.items():
        out[f"{k}_mm" if k in ("pivot", "centre", "station", "start") else
            ("length_mm" if k == "length" else k)] = (
            [round(float(x), 4) for x in v] if hasattr(v, "__len__") and not isinstance(v, str)
            else (round(float(v), 4) if not isinstance(v, str) else v))
    return out


#: parameters listed on the console (all of them in the JSON and plan.html)
SHOWN = 24


def summary(plan) -> str:
    """The console summary."""
    d = data(plan)
    lines = [f"{d['layout']}: plan of {d['readings']} readings in {len(plan.files)} files, "
             f"about {d['minutes']:g} min ({d['candidates']['setups']} candidate set-ups, "
             f"{d['candidates']['readings']} candidate readings)"]
    for f in d["files"]:
        for s in f["setups"]:
            lines.append(f"  {f['file']} {s['label']}: {s['text']}, {s['readings']} readings")
    lines.append("  predicted standard uncertainties (calibrate with no options):")
    shown = list(d["parameters"].items())
    for name, v in shown[:SHOWN]:
        alone = v["determined_alone_by"]
        tag = f"determined by {', '.join(alone)} alone" if alone else "only the combination " \
                                                                      "determines it"
        b = d["baseline"]["parameters"].get(name)
        base = f", baseline {b['predicted_std']:.3g}" if b else ", baseline: not determined"
        lines.append(f"    {name}: {v['predicted_std']:.3g} {v['unit']}{base} ({tag})")
    if len(shown) > SHOWN:
        lines.append(f"    ... {len(shown) - SHOWN} more (the JSON and plan.html list all)")
    if d["unidentifiable"]:
        lines.append("  not determined by this plan: " + "; ".join(
            f"{n} ({d['why_unidentifiable'][n]})" for n in d["unidentifiable"][:8]))
    m, b = d["map_u_um"], d["baseline"]["map_u_um"]
    gain = d["map_gain"]
    base = d["baseline"]
    if b["rms"] is None:
        lines.append(f"  map uncertainty over the working volume: RMS {m['rms']:.3g} um, max "
                     f"{m['max']:.3g} um; no baseline ({base['name']}: {base['why_none']})")
        return "\n".join(lines)
    lines.append(f"  map uncertainty over the working volume: RMS {m['rms']:.3g} um, max "
                 f"{m['max']:.3g} um; baseline ({base['name']}, {base['readings']} readings): "
                 f"RMS {b['rms']:.3g} um, max {b['max']:.3g} um"
                 + (f" -> {100 * gain:.0f} % lower" if gain is not None and gain >= 0 else
                    f" -> {-100 * gain:.0f} % higher" if gain is not None else ""))
    left = [n for n in base["unidentifiable"] if n in d["parameters"]]
    if left:
        lines.append(f"  (the baseline leaves {len(left)} of the plan's determined parameters "
                     f"undetermined -- {', '.join(left[:6])}{' ...' if len(left) > 6 else ''} --"
                     f" and its map holds only what it determines)")
    return "\n".join(lines)
