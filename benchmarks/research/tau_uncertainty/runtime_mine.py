"""RULE.md addendum 4, bar 1, in two processes: the runtime's ranges at full precision on the
FL runs of one sampling (the loop alone, fast), compared with the P-block-prof ranges
tau_profile.py wrote (``records_fl.json`` of ``TAU_PROF=1 python tau_profile.py fl DIR``):
the loop is deterministic, so the same fit in two processes.  Units: s.

usage: python runtime_mine.py 15|60 RECORDS_DIR OUTDIR
"""
import json
import math
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "benchmarks", "acceptance", "issue44_independent"))

from volerr.cli import main as cli_main          # noqa: E402
from volerr.loop.drift import fit as fitmod      # noqa: E402

MINE = []
_orig = fitmod._channel


def _wrapped(ch, cols, Z, cands, cache):
    r = _orig(ch, cols, Z, cands, cache)
    MINE[-1].append([x for x, sp in zip(r["fit"]["tau_range"], r["terms"]) if sp["tau_s"] > 0])
    return r


fitmod._channel = _wrapped


def rel(a, b):
    if a is None or b is None:
        return 0.0 if a is b else math.inf
    return abs(a - b) / abs(b)


def main():
    import fl
    dt, rec_dir, out = int(sys.argv[1]), sys.argv[2], sys.argv[3]
    os.makedirs(out, exist_ok=True)
    fl.D = out
    fl.SRC = os.path.join(ROOT, "runtime", "data", "fl_thermal_spindle.csv")
    files, span = fl.make_files()
    wins = [("w%d" % k, "%gs:%s" % (k * 0.2 * span, "%gs" % ((k + 1) * 0.2 * span)
                                    if k < 4 else ""), files[("full", dt)]) for k in range(5)]
    wins.append(("pub", "100035s:", files[("pub", dt)]))
    recs = {f["tag"]: f for f in json.load(open(os.path.join(rec_dir, "records_fl.json")))}
    worst, n = 0.0, 0
    for name, hold, f in wins:
        tag = "fl_%s_dt%d" % (name, dt)
        if tag not in recs:
            print(tag, "not in the script's records (not run)")
            continue
        MINE.append([])
        try:
            cli_main(["loop", "DMU50", "drift:" + f, "--json", os.path.join(out, tag + ".json"),
                      "--holdout-time", hold])
        except SystemExit:
            pass
        for mine, rec in zip(MINE[-1], recs[tag]["records"]):
            ref = [(t["Pblockprof"]["lo"], t["Pblockprof"]["hi"]) for t in rec["terms"]]
            assert len(mine) == len(ref)
            for m, r in zip(mine, ref):
                worst = max(worst, rel(m[0], r[0]), rel(m[1], r[1]))
                n += 1
        print(tag, "terms so far", n, "worst relative difference", worst, flush=True)


if __name__ == "__main__":
    main()
