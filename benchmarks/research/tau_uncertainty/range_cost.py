"""RULE.md addendum 4, bar 2: ``benchmarks/bench_loop.py --drift`` with the CPU of
``tau_range.ranges`` measured inside the run (``NO_RANGE=1``: the range disabled).  Run from
the repository's root; alternate it with the earlier code's bench for the A/B figure.

usage: python benchmarks/research/tau_uncertainty/range_cost.py
"""
import sys, time, runpy
sys.argv = ["bench_loop.py", "--drift"]
from volerr.loop.drift import tau_range, fit as fitmod
import os
orig = tau_range.ranges
T = [0.0]
def timed(ch, specs, fit):
    c0 = time.process_time()
    r = orig(ch, specs, fit)
    T[0] += time.process_time() - c0
    return r
if os.environ.get("NO_RANGE") == "1":
    tau_range.ranges = lambda ch, specs, fit: None
else:
    tau_range.ranges = timed
import atexit; atexit.register(lambda: print("ranges CPU %.3f s" % T[0], flush=True))
runpy.run_path("benchmarks/bench_loop.py", run_name="__main__")
print("ranges CPU %.3f s" % T[0])
