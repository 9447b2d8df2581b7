"""Benchmark: MB1 volumetric error at 10^6 and 10^7 points against hand-written numpy and
against the memory-bandwidth ceiling; the optional numba backend; (--all) the per-point loop,
lambdify and derive+generate times.

Ratios are against baselines run in this same process, interleaved, best of several runs:
* hand-written numpy of Pahk eq. (4) (the API must be >= 1.5x faster),
* the memory-bandwidth ceiling: one numpy pass that reads the same bytes the evaluation must
  read (the (N, 3) positions and the 21 (N,) error arrays: a sum of each) and writes the
  (N, 3) result (a fill) -- 216 B per point; the API's throughput is reported as a fraction
  of it (target >= 0.5),
* (--all) a per-point loop of 3x3 matrix products and ``sympy.lambdify`` of the exact chain.
CPU time (time.process_time) is printed next to the wall time.
Run: ``python benchmarks/bench_volumetric.py [--blocks] [--all] [--no-numba]``.
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))
from helpers.pahk_eq4 import hand_eq4  # noqa: E402

import volerr  # noqa: E402
from volerr.machine import fused  # noqa: E402
from volerr.machine import model as model_mod  # noqa: E402


def timed(fn, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def interleaved(fns: dict, repeat=9) -> tuple[dict, dict]:
    """Best wall and CPU time of each function, run in turns so that none pays more for cold
    memory or for another process' load."""
    best = {k: np.inf for k in fns}
    cpu = {k: np.inf for k in fns}
    for _ in range(repeat):
        for k, fn in fns.items():
            c, t = time.process_time(), time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t)
            cpu[k] = min(cpu[k], time.process_time() - c)
    return best, cpu


def loop_3x3(pos, e, probe):
    """Per-point evaluation of Pahk eq. (1) with 3x3 small-angle matrices."""
    def t(ex, ey, ez):
        return np.array([[1, -ez, ey], [ez, 1, -ex], [-ey, ex, 1]])

    out = np.empty_like(pos)
    p = np.asarray(probe)
    for i, (x, y, z) in enumerate(pos):
        g = {k: v[i] for k, v in e.items()}
        lx = np.array([x + g["EXX"], g["EYX"] - g["EC0Y"] * x, g["EZX"]])
        ly = np.array([g["EXY"], y + g["EYY"], g["EZY"]])
        lz = np.array([g["EXZ"] + g["EB0Z"] * z, g["EYZ"] - g["EA0Z"] * z, z + g["EZZ"]])
        tx = t(g["EAX"], g["EBX"], g["ECX"])
        ty = t(g["EAY"], g["EBY"], g["ECY"])
        tz = t(g["EAZ"], g["EBZ"], g["ECZ"])
        actual = ly + ty @ (lx + tx @ (lz + tz @ p))
        out[i] = actual - (np.array([x, y, z]) + p)
    return out


def problem(n, seed=0):
    rng = np.random.default_rng(seed)
    model = volerr.load("MB1")
    pos = rng.random((n, 3)) * [900, 575, 400]
    errs = {p: rng.normal(size=n) * (2e-5 if p[1] in "ABC" else 5e-3) for p in model.parameters}
    return model, pos, errs, (10.0, -20.0, -150.0)


def ceiling_fn(pos, errs, n):
    """One pass over the bytes the evaluation must move: read every input, write (N, 3)."""
    arrays = [pos, *errs.values()]
    dst = np.empty((n, 3))

    def ceiling():
        for a in arrays:
            a.sum()
        dst.fill(0.0)
    return ceiling, sum(a.nbytes for a in arrays) + dst.nbytes


def kernel_section(n, repeat):
    model, pos, errs, probe = problem(n)
    ref = model.volumetric_error(pos, errs, probe)
    assert np.allclose(ref, hand_eq4(pos, errs, probe), rtol=0, atol=1e-12)
    ceiling, nbytes = ceiling_fn(pos, errs, n)
    best, cpu = interleaved({
        "ceiling": ceiling,
        "api": lambda: model.volumetric_error(pos, errs, probe),
        "hand": lambda: hand_eq4(pos, errs, probe)}, repeat)
    mpts = {k: n / v / 1e6 for k, v in best.items()}
    print(f"MB1 volumetric error, {n:,} points ({nbytes / n:.0f} B/point; best of {repeat} "
          f"interleaved runs; load {os.getloadavg()[0]:.1f})")
    print(f"  bandwidth ceiling (read+write)  {best['ceiling']*1e3:8.1f} ms  cpu "
          f"{cpu['ceiling']*1e3:7.1f} ms  {mpts['ceiling']:6.1f} M points/s  "
          f"({nbytes / best['ceiling'] / 1e9:.1f} GB/s)")
    print(f"  Model.volumetric_error (API)    {best['api']*1e3:8.1f} ms  cpu "
          f"{cpu['api']*1e3:7.1f} ms  {mpts['api']:6.1f} M points/s  "
          f"= {best['ceiling'] / best['api']:.2f} of the ceiling")
    print(f"  hand-written eq. (4)            {best['hand']*1e3:8.1f} ms  cpu "
          f"{cpu['hand']*1e3:7.1f} ms  {mpts['hand']:6.1f} M points/s  "
          f"-> API {best['hand'] / best['api']:.2f}x faster")
    return model, pos, errs, probe


def block_sweep(n=1_000_000, repeat=5):
    model, pos, errs, probe = problem(n)
    old = model_mod.BLOCK
    fns = {}
    for b in (2048, 4096, 8192, 16384, 32768, 65536):
        def f(b=b):
            model_mod.BLOCK = b
            model.volumetric_error(pos, errs, probe)
        fns[b] = f
    best, _ = interleaved(fns, repeat)
    model_mod.BLOCK = old
    print(f"block size sweep, {n:,} points: " + ", ".join(
        f"{b} -> {t*1e3:.1f} ms" for b, t in best.items()) + f" (BLOCK = {old})")


def numba_section(model, pos, errs, probe, repeat):
    if not fused.numba_available():
        print("numba backend: numba not installed (pip install 'volerr[fast]'), skipped")
        return
    fn = model.module.volumetric_error
    n = pos.shape[0]
    cols = model.positions(pos)
    kw = {**cols, **dict(zip(("Xp", "Yp", "Zp"), probe)), **errs}
    with tempfile.TemporaryDirectory() as cache:  # a cold cache: the compile is measured
        env = {**os.environ, "VOLERR_CACHE_DIR": cache}
        code = ("import time; t = time.perf_counter(); import volerr; "
                "from volerr.machine import fused; m = volerr.load('MB1'); "
                "fused.numba_kernel(m.module.volumetric_error); "
                "print(time.perf_counter() - t)")
        t_cold = float(subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                      capture_output=True, text=True).stdout)
        t_warm = float(subprocess.run([sys.executable, "-c", code], env=env, check=True,
                                      capture_output=True, text=True).stdout)
    t0 = time.perf_counter()
    fused.numba_kernel(fn)
    t_here = time.perf_counter() - t0
    got = fused.evaluate_numba(fn, kw)
    ref = model.volumetric_error(pos, errs, probe)
    assert np.allclose(got, ref, rtol=1e-12, atol=0)
    ceiling, _ = ceiling_fn(pos, errs, n)
    best, _ = interleaved({"ceiling": ceiling, "numba": lambda: fused.evaluate_numba(fn, kw),
                           "api": lambda: model.volumetric_error(pos, errs, probe)}, repeat)
    print(f"  numba fused kernel              {best['numba']*1e3:8.1f} ms  "
          f"{n / best['numba'] / 1e6:6.1f} M points/s = {best['ceiling'] / best['numba']:.2f} "
          f"of the ceiling, {best['api'] / best['numba']:.2f}x the numpy API")
    print(f"  numba: import+load+compile in a fresh process {t_cold:.2f} s (cold cache), "
          f"{t_warm:.2f} s (cached); in this process {t_here:.2f} s")


def monte_carlo_section(model, repeat=5, samples=250, points=1000):
    """The Monte Carlo shape: (S, P) errors of S machines at P points, positions (P,)."""
    if not fused.numba_available():
        return
    rng = np.random.default_rng(1)
    fn = model.module.volumetric_error
    kw = {a: rng.random(points) * 500 for a in model.axes}
    kw.update(Xp=0.0, Yp=0.0, Zp=0.0)
    kw.update({p: rng.normal(size=(samples, points)) * 1e-5 for p in model.parameters})

    def numpy_path():
        return np.stack(np.broadcast_arrays(*fn(**kw)), axis=-1)
    assert np.allclose(fused.evaluate_numba(fn, kw), numpy_path(), rtol=1e-12, atol=1e-300)
    best, _ = interleaved({"numpy": numpy_path,
                           "numba": lambda: fused.evaluate_numba(fn, kw)}, repeat)
    m = samples * points
    print(f"Monte Carlo block ({samples} machines x {points} points): generated numpy "
          f"{best['numpy']*1e3:.1f} ms ({m / best['numpy'] / 1e6:.1f} M/s), numba "
          f"{best['numba']*1e3:.1f} ms ({m / best['numba'] / 1e6:.1f} M/s): "
          f"{best['numpy'] / best['numba']:.2f}x; pays for 10^8 evaluations when "
          f"{1e8 * (1 / (m / best['numpy']) - 1 / (m / best['numba'])):.1f} s saved > compile")


def legacy_section(n=1_000_000):
    model, pos, errs, probe = problem(n)
    cols = model.positions(pos)
    probe_kw = dict(zip(("Xp", "Yp", "Zp"), probe))

    def generated_module():  # the generated function, outputs stacked to (N, 3) like hand_eq4
        return np.stack(model.module.volumetric_error(**cols, **probe_kw, **errs), axis=-1)

    best, _ = interleaved({"module": generated_module, "api": lambda: model.volumetric_error(
        pos, errs, probe), "hand": lambda: hand_eq4(pos, errs, probe)}, 5)
    t_gen, t_api, t_hand = best["module"], best["api"], best["hand"]
    n_loop = 20_000
    sub = {k: v[:n_loop] for k, v in errs.items()}
    t_loop, loop = timed(lambda: loop_3x3(pos[:n_loop], sub, probe), repeat=1)
    t_loop *= n / n_loop
    assert np.allclose(loop, model.exact_error(pos[:n_loop], sub, probe), atol=1e-5)  # 2nd order

    import sympy as sp

    from volerr.derive.kinematics import PROBE, Chain
    from volerr.derive.volumetric import exact_error

    chain = Chain.from_layout(model.layout)
    t0 = time.perf_counter()
    f = sp.lambdify(list(chain.positions) + list(PROBE) + list(chain.parameters),
                    list(exact_error(chain)), "numpy")
    t_lambdify_build = time.perf_counter() - t0
    args = [pos[:, 0], pos[:, 1], pos[:, 2], *probe, *[errs[p] for p in model.parameters]]
    t_lam, _ = timed(lambda: f(*args), repeat=1)

    print(f"MB1 volumetric error, {n:,} points (best of interleaved runs)")
    print(f"  generated module         {t_gen:8.3f} s   generated/hand   = {t_gen / t_hand:6.2f}")
    print(f"  Model API (validation)   {t_api:8.3f} s   API/hand         = {t_api / t_hand:6.2f}")
    print(f"  hand-written eq. (4)     {t_hand:8.3f} s")
    print(f"  per-point 3x3 loop (est) {t_loop:8.1f} s   loop/generated   = {t_loop / t_gen:6.0f}x"
          f"   loop/API = {t_loop / t_api:4.0f}x")
    print(f"  lambdify exact chain     {t_lam:8.3f} s   lambdify/generated = {t_lam / t_gen:6.1f}x"
          f"  (+{t_lambdify_build:.2f} s to build)")

    from volerr.derive.generate import all_generated

    t0 = time.perf_counter()
    files = all_generated()
    print(f"derive + generate all {len(files)} modules: {time.perf_counter() - t0:.1f} s")


def main(argv):
    if "--blocks" in argv:
        block_sweep()
    for n, repeat in ((1_000_000, 9), (10_000_000, 5)):
        model, pos, errs, probe = kernel_section(n, repeat)
        if "--no-numba" not in argv:
            numba_section(model, pos, errs, probe, repeat)
        del pos, errs
    if "--no-numba" not in argv:
        monte_carlo_section(model)
    if "--all" in argv:
        legacy_section()


if __name__ == "__main__":
    main(sys.argv[1:])
