"""Scenario 6b: hostile twists in a many-run campaign (scenario 2's base runs, seed 1; run
scen2.py 1 first).  Cases: a 10-minute run added to the training runs; one run's time in
minutes under t_s; one run in hours under t_s; one run whose channel is in nm under _um;
one run whose temperatures are in degF; one run missing a sensor column; a run whose
environment label changes inside it; the held-out file also given as a training file.

Expected: one clear line, exit 2, nothing written; or correct handling (named in the
report).  usage: python scen6b.py
"""
import glob
import json
import os
import shutil
import a44_sim as sim
from a44_scen6 import run

D6 = os.path.join(sim.OUT, "s6b")


def rewrite(src, dst, fn_row, fn_header=lambda h: h, keep=None):
    lines = open(src).read().splitlines()
    hdr = lines[0].split(",")
    out = [",".join(fn_header(hdr))]
    body = lines[1:] if keep is None else lines[1:1 + keep]
    for i, l in enumerate(body):
        out.append(",".join(fn_row(hdr, l.split(","), i)))
    open(dst, "w").write("\n".join(out) + "\n")


def main():
    import scen6
    shutil.rmtree(D6, ignore_errors=True)
    os.makedirs(D6)
    scen6.D6 = D6
    files = sorted(glob.glob(os.path.join(sim.OUT, "s2_seed1_run*.csv")))
    test = [f for f in files if "varying" in f]
    train = [f for f in files if f not in test]
    res = [run("base", train, None, ["--holdout-files"] + test)]

    def case(name, src, fn_row=lambda h, r, i: r, fn_header=lambda h: h, keep=None,
             extra_test=()):
        dst = os.path.join(D6, name + "_" + os.path.basename(src))
        rewrite(src, dst, fn_row, fn_header, keep)
        tr = [f for f in train if f != src] + [dst]
        return run(name, tr, None, ["--holdout-files"] + test + list(extra_test))

    src = train[0]
    res.append(case("ten_minute_run", src, keep=11))
    ti = lambda h: h.index("t_s")

    def scale_t(f):
        def g(h, r, i):
            r = list(r)
            r[ti(h)] = "%.6g" % (float(r[ti(h)]) / f)
            return r
        return g
    res.append(case("run_in_minutes", src, scale_t(60.0)))
    res.append(case("run_in_hours", src, scale_t(3600.0)))

    def nm(h, r, i):
        r = list(r)
        k = h.index("d_z1_um")
        r[k] = "%.1f" % (1000 * float(r[k]))
        return r
    res.append(case("run_nm", src, nm))

    def degf(h, r, i):
        return [("%.2f" % (float(v) * 1.8 + 32) if c.startswith("T_") else v)
                for c, v in zip(h, r)]
    res.append(case("run_degF", src, degf))
    drop = lambda h, r, i: [v for c, v in zip(h, r) if c != "T_column"]
    res.append(case("run_missing_sensor", src, drop,
                    fn_header=lambda h: [c for c in h if c != "T_column"]))

    def envchange(h, r, i):
        r = list(r)
        if i > 200:
            r[h.index("environment")] = "varying"
        return r
    res.append(case("env_changes_in_run", src, envchange))
    res.append(run("heldout_also_trained", train + [test[0]], None,
                   ["--holdout-files"] + test))
    json.dump(res, open(os.path.join(D6, "results.json"), "w"), indent=1)
    for r in res:
        print("%-22s rc %s lines %s tb %s written %s ok %s | %s" % (
            r["case"], r["rc"], r["stderr_lines"], r["traceback"], r["written"], r["ok"],
            r["stderr"].replace("\n", " / ")[:400] if r["rc"] else
            json.dumps(r.get("channels")) + " left_out " + json.dumps(r.get("inputs_left_out"))[:300]))


if __name__ == "__main__":
    main()
