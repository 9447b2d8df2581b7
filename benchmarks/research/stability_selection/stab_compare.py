"""The named sets of RULE.md from stab_runs.py's out/<window>_<step>.json, and the two
agreement rules 15 s vs 60 s on them (and, as the baseline, on every reported term).

Our rule: tests/loop/test_drift_sampling.py's, its own functions (``_families_agree``,
``_group``, ``_half_step``, ``_agrees``) imported.  The tester's strict rule:
benchmarks/acceptance/issue44_independent/fl_decim.py's first count (``a44_scen5.matches``
imported).  Writes out/compare.json and prints the tables RESULTS.md quotes.

usage: python stab_compare.py
"""

from __future__ import annotations

import importlib.util
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
sys.path.insert(0, os.path.join(ROOT, "benchmarks", "acceptance", "issue44_independent"))
OUT = os.path.join(HERE, "out")

import a44_scen5 as scen5  # noqa: E402
from stab_runs import out_name  # noqa: E402


def _load_test_module():
    path = os.path.join(ROOT, "tests", "loop", "test_drift_sampling.py")
    spec = importlib.util.spec_from_file_location("test_drift_sampling_rule", path)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


rule = _load_test_module()
WINDOWS = ("0-20", "20-40", "40-60", "60-80", "80-100", "pub")
CHANNELS = rule.CHANNELS
#: RULE.md: 0.7; other values: sensitivity only
PI_THR = float(os.environ.get("STAB_PI_THR", "0.7"))
SCHEME = os.environ.get("STAB_SCHEME", "lofo")     # stab_runs.py's subsamples
SUFFIX = os.environ.get("STAB_SUFFIX", "")   # out/compare<SUFFIX>.json


def group_sources(e, t) -> set:
    """A reported term's group: its own source and its alternatives' (RULE.md)."""
    return {e["covariate"]} | {a["covariate"].split(" - ")[0] for a in t["alternatives"]}


def selected_count(e, t, subs) -> int:
    g = group_sources(e, t)
    return sum(bool(g & set(s)) for s in subs)


def named_flags(res) -> dict:
    """(channel, effect index, term index) -> named (bool) by RULE.md."""
    doc, out = res["doc"], {}
    for i, e in enumerate(doc["effects"]):
        ch = e["channel"]
        subs = res["channels"][ch]["subsamples"]
        need = math.ceil(PI_THR * len(subs) - 1e-12)
        for j, t in enumerate(e["terms"]):
            out[(ch, i, j)] = selected_count(e, t, subs) >= need
    return out


def restricted(res, flags, named_only: bool) -> dict:
    """The loop's JSON with, if ``named_only``, only the named terms in ``effects`` (an
    effect without a named term left out)."""
    doc = dict(res["doc"])
    effects = []
    for i, e in enumerate(res["doc"]["effects"]):
        terms = [t for j, t in enumerate(e["terms"])
                 if not named_only or flags[(e["channel"], i, j)]]
        if terms:
            effects.append({**e, "terms": terms})
    doc["effects"] = effects
    return doc


def ours(a, b, name, ch, family=True) -> bool:
    """tests/loop/test_drift_sampling.py's test body, as a verdict."""
    ca, cb = a["channels"][ch], b["channels"][ch]
    if family and not rule._families_agree(ca, cb):
        return False
    ha, hb = rule._half_step(1, name), rule._half_step(4, name)
    ta, tb = rule._terms(a, ch, ha), rule._terms(b, ch, hb)
    oa, ob = tb + rule._not_decided(b, ch, hb), ta + rule._not_decided(a, ch, ha)
    lost = [x for x, g in ta if not rule._agrees(g, oa)] + \
        [x for x, g in tb if not rule._agrees(g, ob)]
    return not lost


def _strict_terms(doc, ch):
    c = doc["channels"][ch]
    res = []
    for e in doc["effects"]:
        if e["channel"] != ch:
            continue
        for t in e["terms"]:
            lag = t.get("lag_s") or {}
            res.append(dict(src=tuple(e.get("covariates") or []), basis=t.get("basis"),
                            value=t.get("value"), std=t.get("std"), tau=lag.get("value"),
                            tau_u=lag.get("std"), eq=t.get("tau_equivalent_s"),
                            alts=t.get("alternatives") or []))
    return c.get("family"), [x["family"] for x in c.get("families_equivalent", [])], res


def strict(a, b, ch) -> bool:
    """fl_decim.py's first count, as a verdict."""
    fa, eqa, ta = _strict_terms(a, ch)
    fb, eqb, tb = _strict_terms(b, ch)
    fam_ok = fa == fb or fb in eqa or fa in eqb
    src_ok = {t["src"] for t in ta} == {t["src"] for t in tb}
    lag_a = [t for t in ta if t["tau"] is not None]
    lag_b = [t for t in tb if t["tau"] is not None]
    tau_ok = all(scen5.matches(t, ta) for t in lag_b) and all(scen5.matches(t, tb) for t in lag_a)
    return fam_ok and src_ok and tau_ok


def stable_unheld(res) -> int:
    """Sources selected in >= ceil(pi_thr K) subsamples that no reported term's group holds."""
    n = 0
    for ch, c in res["channels"].items():
        need = math.ceil(PI_THR * len(c["subsamples"]) - 1e-12)
        srcs = {x for s in c["subsamples"] for x in s}
        stable = {x for x in srcs if sum(x in s for s in c["subsamples"]) >= need}
        held = set()
        for e in res["doc"]["effects"]:
            if e["channel"] == ch:
                for t in e["terms"]:
                    held |= group_sources(e, t)
        n += len(stable - held)
    return n


def frequencies(subs) -> dict:
    """source -> in how many of the subsamples the selection took it."""
    return {x: sum(x in s for s in subs) for x in sorted({x for s in subs for x in s})}


def main():
    rows, totals = [], {"cpu_loop_s": {1: 0.0, 4: 0.0}, "cpu_subsamples_s": {1: 0.0, 4: 0.0}}
    counts = {"reported": {1: 0, 4: 0}, "named": {1: 0, 4: 0}, "zero_in_k2": 0,
              "stable_unheld": {1: 0, 4: 0}}
    for name in WINDOWS:
        res = {st: json.load(open(out_name(name, st, SCHEME))) for st in (1, 4)}
        flags = {st: named_flags(res[st]) for st in (1, 4)}
        docs = {(st, nm): restricted(res[st], flags[st], nm) for st in (1, 4)
                for nm in (False, True)}
        for st in (1, 4):
            totals["cpu_loop_s"][st] += res[st]["cpu_loop_s"]
            totals["cpu_subsamples_s"][st] += res[st]["cpu_subsamples_s"]
            counts["reported"][st] += len(flags[st])
            counts["named"][st] += sum(flags[st].values())
            counts["stable_unheld"][st] += stable_unheld(res[st])
            for e in docs[(st, True)]["effects"]:
                counts["zero_in_k2"] += sum(abs(t["value"]) < 2 * t["std"] for t in e["terms"])
        for ch in CHANNELS:
            a0, b0, a1, b1 = docs[(1, False)], docs[(4, False)], docs[(1, True)], docs[(4, True)]

            def names(d):
                return sorted(t["basis"] for e in d["effects"] if e["channel"] == ch
                              for t in e["terms"])
            rows.append({"window": name, "channel": ch,
                         "family": [a0["channels"][ch]["family"], b0["channels"][ch]["family"]],
                         "ours_reported": ours(a0, b0, name, ch),
                         "ours_named": ours(a1, b1, name, ch),
                         "ours_named_terms_only": ours(a1, b1, name, ch, family=False),
                         "ours_reported_terms_only": ours(a0, b0, name, ch, family=False),
                         "strict_reported": strict(a0, b0, ch),
                         "strict_named": strict(a1, b1, ch),
                         "named_15": names(a1), "named_60": names(b1),
                         "not_named_15": sorted(set(names(a0)) - set(names(a1))),
                         "not_named_60": sorted(set(names(b0)) - set(names(b1))),
                         "selected_15": frequencies(res[1]["channels"][ch]["subsamples"]),
                         "selected_60": frequencies(res[4]["channels"][ch]["subsamples"])})
    keys = ("ours_reported", "ours_named", "strict_reported", "strict_named",
            "ours_reported_terms_only", "ours_named_terms_only")
    summary = {k: sum(r[k] for r in rows) for k in keys}
    json.dump({"rows": rows, "summary": summary, "counts": counts, "cpu": totals},
              open(os.path.join(OUT, f"compare{SUFFIX}.json"), "w"), indent=1)
    for r in rows:
        print(f"{r['window']:>6} {r['channel']} fam {r['family'][0]}/{r['family'][1]} "
              f"ours {int(r['ours_reported'])}->{int(r['ours_named'])} "
              f"strict {int(r['strict_reported'])}->{int(r['strict_named'])} "
              f"terms-only {int(r['ours_reported_terms_only'])}->{int(r['ours_named_terms_only'])}"
              f"\n        not named 15 s: {r['not_named_15']}\n        not named 60 s: "
              f"{r['not_named_60']}")
    print(f"pi_thr {PI_THR} summary (of 30):", summary)
    print("terms reported / named:", counts["reported"], counts["named"],
          "named with k=2 including zero:", counts["zero_in_k2"],
          "stable sources no reported group holds:", counts["stable_unheld"])
    print("CPU s (sum of six windows) loop:", totals["cpu_loop_s"], "subsamples:",
          totals["cpu_subsamples_s"])


if __name__ == "__main__":
    main()
