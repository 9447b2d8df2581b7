"""Benchmark: MB1 volumetric error on 10^6 points, and derive+generate time of all layouts.

Ratios are against baselines run in this same process:
* a per-point loop of 3x3 matrix products (how existing error-map tools evaluate),
* ``sympy.lambdify`` of the exact (non-linearised) chain,
* hand-written numpy of Pahk eq. (4).
Run: ``python benchmarks/bench_volumetric.py [n_points]``.
"""

from __future__ import annotations

import sys
import time

import numpy as np

import volerr


def timed(fn, repeat=3):
    best = np.inf
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return best, out


def interleaved(fns: dict, repeat=9) -> dict:
    """Best time of each function, run in turns so that none pays more for cold memory."""
    best = {k: np.inf for k in fns}
    for _ in range(repeat):
        for k, fn in fns.items():
            t = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - t)
    return best


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


def hand_eq4(pos, g, probe):
    """Pahk eq. (4) written by hand in numpy (EC0Y = alpha, EB0Z = -beta1, EA0Z = beta2)."""
    x, y, z = pos.T
    xp, yp, zp = probe
    ez = g["ECX"] + g["ECY"] + g["ECZ"]
    ey = g["EBX"] + g["EBY"] + g["EBZ"]
    ex = g["EAX"] + g["EAY"] + g["EAZ"]
    dx = (g["EXX"] + g["EXY"] + g["EXZ"] + z * (g["EB0Z"] + g["EBX"] + g["EBY"])
          - yp * ez + zp * ey)
    dy = (g["EYX"] + g["EYY"] + g["EYZ"] + x * (-g["EC0Y"] + g["ECY"])
          - z * (g["EA0Z"] + g["EAY"] + g["EAX"]) + xp * ez - zp * ex)
    dz = g["EZX"] + g["EZY"] + g["EZZ"] - x * g["EBY"] - xp * ey + yp * ex
    return np.stack([dx, dy, dz], axis=-1)


def main(n=1_000_000):
    rng = np.random.default_rng(0)
    model = volerr.load("MB1")
    pos = rng.random((n, 3)) * [900, 575, 400]
    errs = {p: rng.normal(size=n) * (2e-5 if p[1] in "ABC" else 5e-3) for p in model.parameters}
    probe = (10.0, -20.0, -150.0)
    ref = model.volumetric_error(pos, errs, probe)
    assert np.allclose(ref, hand_eq4(pos, errs, probe), atol=1e-12)
    cols = model.positions(pos)
    probe_kw = dict(zip(("Xp", "Yp", "Zp"), probe))

    def generated_module():  # the generated function, outputs stacked to (N, 3) like hand_eq4
        return np.stack(model.module.volumetric_error(**cols, **probe_kw, **errs), axis=-1)

    best = interleaved({"module": generated_module, "api": lambda: model.volumetric_error(
        pos, errs, probe), "hand": lambda: hand_eq4(pos, errs, probe)})
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


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 1_000_000)
