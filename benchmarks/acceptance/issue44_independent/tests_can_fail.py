"""Shows that each assertion of tests/acceptance/test_acceptance44_independent.py can fail:
the same checks applied to inputs where the loop (or the truth) differs.
usage: ACCEPT44_OUT=/tmp/x python benchmarks/acceptance/issue44_independent/tests_can_fail.py"""
import os
import sys
import tempfile
HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "tests", "acceptance"))
import a44_sim as sim
sim.OUT = tempfile.mkdtemp()
import a44_scen1 as scen1, a44_scen2 as scen2, a44_scen34 as scen34, a44_scen6 as scen6
import test_acceptance44_independent as T


def expect_fail(name, fn):
    try:
        fn()
    except AssertionError as e:
        print("%-40s fails as it should: %s" % (name, str(e)[:160].replace("\n", " ")))
        return
    print("%-40s DID NOT FAIL" % name)


scen1.VARIANT = "speedonly"
expect_fail("floor/interval (speed-only seed 3, 15 s)",
            lambda: T._judge_floor_and_interval(scen1.evaluate(3, 15.0, (("f", (0.8, 1.0)),))[0]))
scen2.VARIANT = "constonly"
expect_fail("floor/interval (room, constant-only train)",
            lambda: T._judge_floor_and_interval(scen2.evaluate(1)))


def static_on_lag_truth():
    scen1.VARIANT = "hard"
    r = scen1.evaluate(1, 60.0, (("m", (0.4, 0.6)),))[0]
    assert r["family"] == "static", r["family"]
expect_fail("static-truth check on a lag truth", static_on_lag_truth)


def noise_on_static_truth():
    scen1.VARIANT = "easy"
    r = scen34.evaluate(3, 1, (("m", (0.4, 0.6)),))[0]
    assert r["family"] == "constant" and r["effects"] == [], r["family"]
expect_fail("noise check on a static truth", noise_on_static_truth)


def hostile_small_nm():
    scen1.VARIANT = "hard"
    scen6.D6 = sim.OUT
    m = scen6.base()
    c = dict(scen6.rows_of(m), d_z1_um=["%.1f" % (30 * x) for x in m["d"]])
    p = os.path.join(sim.OUT, "nm_small.csv")
    scen6.write_cols(p, c)
    r = scen6.run("nm_small", [p], "129600s:")
    assert r["rc"] == 2 and r["ok"], (r["rc"], r["written"])
expect_fail("hostile check on a 0.6 mm 'um' channel", hostile_small_nm)
