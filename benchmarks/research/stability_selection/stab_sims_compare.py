"""RULE.md criterion 3 on the 77 simulator fits of stab_sims.py: per fit, does the channel
``z1`` name an irrelevant sensor, does it miss a planted source, with every reported term
(today) and with the named terms only (RULE.md, pi_thr 0.7).  The definitions (RESULTS.md,
"Simulators"; written before these figures):

* irrelevant: the sensors that carry nothing of the drift: ``T_x*`` (room swings and random
  walks; scenarios 1, 3, 4), ``T_cab`` (scenario 2); in scenario 4 (noise only) every source;
* planted, strict: the drift's own inputs: the heat input ``S_rpm`` (scenarios 1, 2),
  ``T_room`` (scenario 2), ``T_h2`` and ``T_h6`` (scenario 3); lenient: a planted input or a
  sensor that carries it (scenario 1: any ``T_h*`` for the heat input; scenario 2:
  ``T_spindle``, ``T_column``, ``T_bed`` for the heat and for the room).

usage: python stab_sims_compare.py   (after stab_sims.py)
"""

from __future__ import annotations

import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
OUT = os.path.join(HERE, "out", "sims")
PI_THR = 0.7
CH = "z1"


def sources(doc, stab, named_only: bool) -> set:
    subs = stab[CH]["subsamples"] if stab else []
    need = math.ceil(PI_THR * len(subs) - 1e-12)
    out = set()
    for e in doc["effects"]:
        if e["channel"] != CH:
            continue
        for t in e["terms"]:
            g = {e["covariate"]} | {a["covariate"].split(" - ")[0] for a in t["alternatives"]}
            if not named_only or sum(bool(g & set(s)) for s in subs) >= need:
                out.add(e["covariate"])
    return out


def planted(tag: str):
    """(strict, lenient): lists of sets, each a planted input and what counts as naming it."""
    if tag.startswith("s1s"):
        return [{"S_rpm"}], [{"S_rpm"}]
    if tag.startswith("s1"):
        return [{"S_rpm"}], [{"S_rpm"} | {f"T_h{k}" for k in range(1, 9)}]
    if tag.startswith("s2"):
        carriers = {"T_spindle", "T_column", "T_bed"}
        return [{"S_rpm"}, {"T_room"}], [{"S_rpm"} | carriers, {"T_room"} | carriers]
    if tag.startswith("s3"):
        return [{"T_h2"}, {"T_h6"}], [{"T_h2"}, {"T_h6"}]
    return [], []


def irrelevant(tag: str, src: set) -> set:
    if tag.startswith("s4"):
        return set(src)
    return {s for s in src if s.startswith("T_x") or s == "T_cab"}


def main():
    tags = json.load(open(os.path.join(OUT, "tags.json")))
    rows = []
    for tag in tags:
        path = os.path.join(OUT, tag + ".json")
        if not os.path.exists(path):
            rows.append({"tag": tag, "error": "no JSON"})
            continue
        doc = json.load(open(path))
        stab = json.load(open(path + ".stab.json")) if os.path.exists(path + ".stab.json") else None
        strict, lenient = planted(tag)
        row = {"tag": tag, "family": doc["channels"][CH].get("family"),
               "K": stab[CH]["K"] if stab else None}
        for kind, named in (("reported", False), ("named", True)):
            src = sources(doc, stab, named)
            row[kind] = sorted(src)
            row[kind + "_irrelevant"] = sorted(irrelevant(tag, src))
            row[kind + "_missed_strict"] = sum(not (p & src) for p in strict)
            row[kind + "_missed_lenient"] = sum(not (p & src) for p in lenient)
        rows.append(row)
    ok = [r for r in rows if "error" not in r]
    summ = {"fits": len(rows), "with_json": len(ok)}
    for kind in ("reported", "named"):
        summ[kind + "_fits_naming_irrelevant"] = sum(bool(r[kind + "_irrelevant"]) for r in ok)
        summ[kind + "_fits_missing_strict"] = sum(r[kind + "_missed_strict"] > 0 for r in ok)
        summ[kind + "_fits_missing_lenient"] = sum(r[kind + "_missed_lenient"] > 0 for r in ok)
    json.dump({"rows": rows, "summary": summ},
              open(os.path.join(HERE, "out", "sims_compare.json"), "w"), indent=1)
    for r in rows:
        if "error" in r:
            print(r)
            continue
        print(f"{r['tag']:<28} {r['family']:<11} K {r['K']} reported {r['reported']} "
              f"named {r['named']} irrelevant {r['reported_irrelevant']}->{r['named_irrelevant']}"
              f" missed strict {r['reported_missed_strict']}->{r['named_missed_strict']}"
              f" lenient {r['reported_missed_lenient']}->{r['named_missed_lenient']}")
    print(summ)


if __name__ == "__main__":
    main()
