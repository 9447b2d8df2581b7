"""What the thinning (``tau_range.THIN_ABOVE``) does on ``bench_loop.py --drift``'s run
(75 000 training readings, the Gram on every 4th): each channel's ranges recomputed on every
training reading and compared.  Units: s.

usage: python benchmarks/research/tau_uncertainty/range_thinned.py   (from the root)
"""
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
import bench_loop                                   # noqa: E402
from volerr.loop.drift import tau_range             # noqa: E402

ORIG = tau_range.ranges


def both(ch, specs, fit):
    thin = ORIG(ch, specs, fit)
    keep = tau_range.THIN_ABOVE
    tau_range.THIN_ABOVE = 10 ** 9
    try:
        full = ORIG(ch, specs, fit)
    finally:
        tau_range.THIN_ABOVE = keep
    for sp, a, b in zip(specs, thin, full):
        if a is not None:
            print("  tau %.0f s: thinned %s, every reading %s" % (
                sp["tau_s"], ["%.1f" % v if v is not None else None for v in a],
                ["%.1f" % v if v is not None else None for v in b]), flush=True)
    return thin


tau_range.ranges = both
bench_loop.drift(100000)
