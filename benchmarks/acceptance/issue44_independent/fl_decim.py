"""FL_THERMAL item 2: at 15 s and at 60 s, per window and channel, the same family, named
sources and time constants (scen5's rule), and no named term's k = 2 interval including zero.

usage: python fl_decim.py   (after fl.py)
"""
import json
import os
import a44_sim as sim
import a44_scen5 as scen5


def terms(path, ch):
    d = json.load(open(path))
    c = d["channels"][ch]
    res = []
    for e in sim.effects_of(d, ch):
        for t in e.get("terms", []):
            lag = t.get("lag_s") or {}
            res.append(dict(src=tuple(e.get("covariates") or []), basis=t.get("basis"),
                            value=t.get("value"), std=t.get("std"), tau=lag.get("value"),
                            tau_u=lag.get("std"), eq=t.get("tau_equivalent_s"),
                            alts=t.get("alternatives") or []))
    return c.get("family"), c.get("lag_terms_named"), [x["family"] for x in c.get("families_equivalent", [])], res


D = os.path.join(sim.OUT, "fl")
n_same = n = 0
zero_in, no_u = [], []
for w in ("w0", "w1", "w2", "w3", "w4", "pub"):
    for ch in ("ch1", "ch2", "ch3", "ch4", "ch5"):
        a = terms(os.path.join(D, "fl_%s_dt15.json" % w), ch)
        b = terms(os.path.join(D, "fl_%s_dt60.json" % w), ch)
        fam_ok = a[0] == b[0] or b[0] in a[2] or a[0] in b[2]
        src_ok = {t["src"] for t in a[3]} == {t["src"] for t in b[3]}
        lag_a = [t for t in a[3] if t["tau"] is not None]
        lag_b = [t for t in b[3] if t["tau"] is not None]
        tau_ok = all(scen5.matches(t, a[3]) for t in lag_b) and all(scen5.matches(t, b[3]) for t in lag_a)
        same = fam_ok and src_ok and tau_ok
        n += 1; n_same += same
        for t in a[3] + b[3]:
            if t["std"] is not None and abs(t["value"]) <= 2 * t["std"]:
                zero_in.append((w, ch, t["basis"], t["value"], t["std"]))
            if t["tau"] is not None and t["tau_u"] is None:
                no_u.append((w, ch, t["basis"]))
        print("%-4s %s fam %s/%s (eq %s/%s) named %s/%s src %s tau %s -> %s" % (
            w, ch, a[0], b[0], a[2], b[2], a[1], b[1], src_ok, tau_ok, "SAME" if same else "DIFFERENT"))
        if not same:
            print("     15:", [(t["basis"], t["tau_u"]) for t in a[3]])
            print("     60:", [(t["basis"], t["tau_u"]) for t in b[3]])
print("same diagnosis %d of %d" % (n_same, n))
print("named terms whose k=2 interval includes zero:", zero_in)
print("named lags without uncertainty:", no_u)

# the lenient reading (written after the strict figures were seen; stated as such)
n_len = 0
for w in ("w0", "w1", "w2", "w3", "w4", "pub"):
    for ch in ("ch1", "ch2", "ch3", "ch4", "ch5"):
        a = terms(os.path.join(D, "fl_%s_dt15.json" % w), ch)
        b = terms(os.path.join(D, "fl_%s_dt60.json" % w), ch)
        fam_ok = a[0] == b[0] or b[0] in a[2] or a[0] in b[2]
        ok = fam_ok and all(scen5.matches_lenient(t, a[3]) for t in b[3]) and \
            all(scen5.matches_lenient(t, b[3]) for t in a[3])
        n_len += ok
print("lenient (counterpart or listed alternative, family equal or CV-equivalent): %d of 30" % n_len)
