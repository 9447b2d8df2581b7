"""Benchmark: three-point identification of 10^5 axis positions x 3 points.

Times ``volerr.identify.solve.identify`` (vectorised weighted least squares over all points, with
the closed-form cross-check, residuals and outlier flags) for a linear and a rotary axis, with
and without the tracker uncertainty model, against a baseline in the same process: a Python
loop calling ``numpy.linalg.lstsq`` per position (timed on a subset and scaled).

Run: ``python benchmarks/bench_identify.py [n_positions]``.  Target: well under 5 s.
"""

import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests" / "helpers"))
from tracker_sim import smooth_errors  # noqa: E402

from volerr.identify.solve import design, identify  # noqa: E402
from volerr.machine.layout import parse_layout  # noqa: E402
from volerr.identify.tracker_io import Round  # noqa: E402

REF = np.array([[60.0, 10.0, -150.0], [-40.0, 50.0, -100.0], [10.0, -60.0, -200.0]])
ROTARY = parse_layout("""
name = "RT"
[axes.X]
kind = "linear"
direction = [1, 0, 0]
travel = [0, 500]
[axes.C]
kind = "rotary"
direction = [0, 0, 1]
travel = [0, 360]
[chain]
tool = ["X"]
workpiece = ["C"]
""")


def _rot_batch(axis, a):
    """Rotation matrices about a frame axis (0, 1, 2) by angles a: (n, 3, 3)."""
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(a.shape + (3, 3))
    i, j = [(1, 2), (2, 0), (0, 1)][axis]
    R[..., axis, axis] = 1
    R[..., i, i], R[..., i, j], R[..., j, i], R[..., j, j] = c, -s, s, c
    return R


def _data(kind, n):
    """Exact rigid-body data, vectorised (same model as tests/helpers/tracker_sim.py)."""
    pos = np.linspace(0.0, 1000.0, n) if kind == "linear" else \
        np.linspace(0.0, 360.0, n, endpoint=False)
    e = smooth_errors(pos, seed=2)
    E = _rot_batch(2, e[:, 5]) @ _rot_batch(1, e[:, 4]) @ _rot_batch(0, e[:, 3])
    if kind == "linear":
        nominal = np.zeros((n, 3))
        nominal[:, 0] = pos - pos[0]
        lever = np.broadcast_to(REF, (n, 3, 3))
        pts = nominal[:, None, :] + e[:, None, :3] + np.einsum("kab,knb->kna", E, lever)
    else:
        lever = np.einsum("kab,nb->kna", _rot_batch(2, np.radians(pos - pos[0])), REF)
        pts = e[:, None, :3] + np.einsum("kab,knb->kna", E, lever)
    pts = pts + np.random.default_rng(0).normal(0, 0.001, pts.shape)
    return pos, pts


def baseline(pos, pts, sample=2000):
    """Per-position Python loop with numpy.linalg.lstsq (linear axis), scaled to all."""
    idx = np.linspace(0, len(pos) - 1, sample).astype(int)
    A = design(pts[0]).reshape(-1, 6)
    t = time.perf_counter()
    for k in idx:
        delta = (pts[k] - pts[0] - (pos[k] - pos[0]) * np.array([1.0, 0, 0])).ravel()
        np.linalg.lstsq(A, delta, rcond=None)
    return (time.perf_counter() - t) * len(pos) / sample


def main():
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 100_000
    print(f"three-point identification, {n} positions x 3 points")
    for kind, layout, axis in (("linear", "MB1", "X"), ("rotary", ROTARY, "C")):
        pos, pts = _data(kind, n)
        rnd = Round("bench", pos, ("P", "Q", "K"), pts)
        for tracker in (None, (-2500.0, 1500.0, 400.0)):
            t = time.perf_counter()
            res = identify([rnd], layout, axis, tracker=tracker)
            dt = time.perf_counter() - t
            label = "tracker-weighted" if tracker else "equal weights"
            print(f"  {kind:6s} {label:17s}: {dt:6.2f} s  "
                  f"({dt / n * 1e6:.1f} us/position, residual RMS "
                  f"{res.summary()['residual_rms_um']:.2f} um)")
        if kind == "linear":
            tb = baseline(pos, pts)
            t = time.perf_counter()
            identify([rnd], layout, axis, cross_check=False)
            dt = time.perf_counter() - t
            print(f"  baseline per-position lstsq loop: {tb:6.2f} s (scaled from 2000); "
                  f"vectorised lsq without cross-check {dt:.2f} s: {tb / dt:.0f}x faster")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):     # the usage is the docstring
        sys.exit(print(__doc__))
    main()
