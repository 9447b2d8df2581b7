"""An independent virtual CMM for acceptance tests of `volerr loop` (numpy only, no volerr code).

Exact rigid-body chain written directly (not from the layout files): stages of the tool chain
from the base, table axes moving opposite; component errors are smooth non-polynomial
functions (sines of up to two periods per travel plus a quadratic); squareness as tilted axis
directions; the instrument at an unknown rigid placement; noise.  Undeclared effects are planted
in its own way (thermal scale with T_C, drift with t_s, reversal with dir_X, coupling, periodic,
probe_direction with nx,ny,nz, setup per round, a non-polynomial higher-order shape).
"""
import numpy as np

LAYOUTS = {  # travel, tool chain (from base), workpiece chain (from base)
    "MB1": ({"X": (0, 900), "Y": (0, 575), "Z": (0, 400)}, ["Y", "X", "Z"], []),
    "FB1": ({"X": (0, 1000), "Y": (0, 800), "Z": (0, 600)}, ["X", "Z"], ["Y"]),
    "MH2": ({"X": (0, 1100), "Y": (0, 1100), "Z": (0, 1100)}, ["X", "Z", "Y"], []),
    "CY": ({"X": (0, 600), "Y": (0, 400), "Z": (0, 400)}, ["Z"], ["Y", "X"]),
}
U = {"X": np.array([1.0, 0, 0]), "Y": np.array([0, 1.0, 0]), "Z": np.array([0, 0, 1.0])}
COMP = ["EX", "EY", "EZ", "EA", "EB", "EC"]


def rot(a, b, c):
    """exact rotation (N,3,3) from angles about x, y, z"""
    a, b, c = np.broadcast_arrays(np.asarray(a, float), np.asarray(b, float), np.asarray(c, float))
    n = a.shape
    ca, sa, cb, sb, cc, sc = np.cos(a), np.sin(a), np.cos(b), np.sin(b), np.cos(c), np.sin(c)
    o, z = np.ones(n), np.zeros(n)
    Rx = np.stack([np.stack([o, z, z], -1), np.stack([z, ca, -sa], -1), np.stack([z, sa, ca], -1)], -2)
    Ry = np.stack([np.stack([cb, z, sb], -1), np.stack([z, o, z], -1), np.stack([-sb, z, cb], -1)], -2)
    Rz = np.stack([np.stack([cc, -sc, z], -1), np.stack([sc, cc, z], -1), np.stack([z, z, o], -1)], -2)
    return Rx @ Ry @ Rz


def smooth_fn(rng, lo, hi, amp):
    """smooth non-polynomial function of q, values ~amp, zero-ish mean"""
    k = rng.uniform(0.3, 2.0, 3)
    ph = rng.uniform(0, 2 * np.pi, 3)
    w = rng.normal(0, 1, 3)
    c2 = rng.normal(0, 1)
    def f(q):
        u = (np.asarray(q, float) - lo) / (hi - lo)
        return amp * (sum(w[i] * np.sin(2 * np.pi * k[i] * u + ph[i]) for i in range(3)) / 2 + c2 * (u - .5) ** 2)
    return f


class Machine:
    def __init__(self, layout="MB1", seed=0, trans_um=5.0, ang_urad=8.0, sq_urad=20.0):
        self.layout = layout
        self.travel, self.tool, self.work = LAYOUTS[layout]
        rng = np.random.default_rng(1000 + seed)
        self.fn = {}
        for a, (lo, hi) in self.travel.items():
            for cmp in COMP:
                amp = trans_um * 1e-3 if cmp[1] in "XYZ" else ang_urad * 1e-6
                self.fn[cmp + a] = smooth_fn(rng, lo, hi, amp)
        # squareness: direction tilts of Y (about z) and Z (about x and y)
        self.sq = rng.normal(0, sq_urad * 1e-6, 3)
        self.extra = {}   # name -> callable(pos, cov) -> dict of component additions

    def axis_dir(self, a, dsq=None):
        """direction of axis a, (3,) or (n, 3) when the squareness varies per point (dsq)"""
        sq = self.sq if dsq is None else self.sq[None, :] + dsq
        one = np.ones_like(sq[..., 0])
        if a == "Y":
            return np.stack([-sq[..., 0], one, 0 * one], -1)
        if a == "Z":
            return np.stack([sq[..., 1], -sq[..., 2], one], -1)
        return U[a] if dsq is None else np.broadcast_to(U[a], sq.shape)

    def stage(self, a, q, add):
        """(R, t) of one axis at positions q: nominal translation (with squareness) and errors."""
        e = {c: self.fn[c + a](q) + add.get(c + a, 0.0) for c in COMP}
        R = rot(e["EA"], e["EB"], e["EC"])
        d = self.axis_dir(a, add.get("dsq"))
        t = q[:, None] * (d if d.ndim == 2 else d[None, :]) + np.stack([e["EX"], e["EY"], e["EZ"]], -1)
        return R, t

    def tip(self, pos, probe, add, sign_work=-1):
        n = len(probe)
        R = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        t = np.zeros((n, 3))
        for a in self.tool:   # H = H_a1 H_a2 ... ; apply composition
            Ra, ta = self.stage(a, pos[a], add)
            t = t + np.einsum("nij,nj->ni", R, ta)
            R = R @ Ra
        p_tool = t + np.einsum("nij,nj->ni", R, probe)
        # workpiece chain: the table moves by -q (tool relative to workpiece is +q)
        Rw = np.broadcast_to(np.eye(3), (n, 3, 3)).copy()
        tw = np.zeros((n, 3))
        for a in self.work:
            Ra, ta = self.stage(a, pos[a], add)
            ta = -ta           # table motion opposite; errors of the table as they come
            Ra = np.transpose(Ra, (0, 2, 1))
            tw = tw + np.einsum("nij,nj->ni", Rw, ta)
            Rw = Rw @ Ra
        # tool tip in the workpiece frame
        return np.einsum("nji,nj->ni", Rw, p_tool - tw)


def plan(rng, travel, n, probes, grid=None):
    pos = {}
    for a, (lo, hi) in travel.items():
        if grid:
            pos[a] = rng.choice(np.linspace(lo, hi, grid), n)
        else:
            pos[a] = rng.uniform(lo, hi, n)
    pr = np.asarray(probes, float)[rng.integers(0, len(probes), n)]
    return pos, pr


PROBES5 = [(0, 0, -120), (90, 0, -120), (-90, 0, -120), (0, 90, -120), (0, -90, -120), (0, 0, -250)]


def campaign(layout="MB1", n=1000, seed=0, effects=(), noise_um=0.5, probes=PROBES5, grid=None,
             rounds=3, mseed=None, channels=False, truth=None, trans_um=5.0):
    """Return dict of columns (CSV names); ``truth`` (a dict) receives the noise (n, 3) mm.

    ``channels``: also two temperature channels ``T_top``, ``T_bottom`` (a vertical gradient
    that changes over the day, not a function of T_C)."""
    m = Machine(layout, seed if mseed is None else mseed, trans_um=trans_um)
    rng = np.random.default_rng(seed)
    pos, pr = plan(rng, m.travel, n, probes, grid)
    order = np.argsort(rng.uniform(size=n))  # measurement order
    t_s = np.empty(n); t_s[order] = np.linspace(0, 4 * 3600, n)
    T = 21.0 + 1.8 * np.sin(2 * np.pi * t_s / (3.1 * 3600) + 0.4) + rng.normal(0, .05, n)  # 19.2..22.8
    dirs = {f"dir_{a}": rng.choice([-1.0, 1.0], n) for a in m.travel}
    rnd = np.empty(n); rnd[order] = np.repeat(np.arange(1, rounds + 1), int(np.ceil(n / rounds)))[:n]
    nvec = rng.normal(size=(n, 3)); nvec /= np.linalg.norm(nvec, axis=1)[:, None]
    cov = {"T_C": T, "t_s": t_s, **dirs, "round": rnd, "nx": nvec[:, 0], "ny": nvec[:, 1], "nz": nvec[:, 2]}
    if channels:   # own stream: the other columns stay as without channels
        rc = np.random.default_rng(7000 + seed)
        grad = 0.8 * np.sin(2 * np.pi * t_s / (2.3 * 3600) + 1.9) + 0.3 * (t_s / 14400)
        cov["T_top"] = T + 0.5 * grad + rc.normal(0, .03, n)
        cov["T_bottom"] = T - 0.5 * grad + rc.normal(0, .03, n)
    add = {}
    extra_dev = np.zeros((n, 3))
    inst_t = np.tile(rng.normal(0, 5e-3, 3), (n, 1))
    inst_r = np.tile(rng.normal(0, 5e-6, 3), (n, 1))
    mid = {a: (lo + hi) / 2 for a, (lo, hi) in m.travel.items()}
    half = {a: (hi - lo) / 2 for a, (lo, hi) in m.travel.items()}
    probe_eff = pr.copy()
    for e in effects:
        k = e["kind"]
        if k == "thermal":   # positioning error along axis prop to q*(T-20)
            a = e.get("axis", "X")
            add["EX" + a if a == "X" else ("EY" + a if a == "Y" else "EZ" + a)] = \
                e.get("alpha", 11.5e-6) * (pos[a] - e.get("x0", 0.0)) * (T - 20.0)
        elif k == "drift":
            v = np.zeros(3); v["xyz".index(e.get("dir", "x"))] = e.get("um_per_h", 1.5) * 1e-3
            extra_dev += (t_s / 3600)[:, None] * v
        elif k == "reversal":
            a = e.get("axis", "X")
            c = {"X": "EXX", "Y": "EYY", "Z": "EZZ"}[a]
            add[c] = add.get(c, 0) + e.get("um", 4.0) * 1e-3 / 2 * dirs[f"dir_{a}"]
        elif k == "coupling":
            c, b = e.get("component", "EZX"), e.get("on", "Y")
            a = c[2]
            add[c] = add.get(c, 0) + e.get("um", 5.0) * 1e-3 * ((pos[a] - mid[a]) / half[a]) * ((pos[b] - mid[b]) / half[b])
        elif k == "periodic":
            c = e.get("component", "EYY")
            a = c[2]
            add[c] = add.get(c, 0) + e.get("um", 2.0) * 1e-3 * np.sin(2 * np.pi * pos[a] / e.get("pitch", 20.0) + 0.7)
        elif k == "probe_direction":   # tip sits off along the probing direction
            extra_dev += e.get("um", 1.5) * 1e-3 * nvec
        elif k == "setup":
            for r in range(2, rounds + 1):
                sel = rnd == r
                inst_t[sel] += rng.normal(0, e.get("um", 8.0) * 1e-3, 3)
                inst_r[sel] += rng.normal(0, e.get("urad", 15.0) * 1e-6, 3)
        elif k == "bump":
            c = e.get("component", "EYZ"); a = c[2]
            add[c] = add.get(c, 0) + e.get("um", 3.0) * 1e-3 * np.exp(-((pos[a] - e.get("at", mid[a] + 37)) / e.get("width", 20.0)) ** 2)
        elif k == "higher_order":
            c = e.get("component", "EYZ"); a = c[2]
            u = (pos[a] - mid[a]) / half[a]
            add[c] = add.get(c, 0) + e.get("um", 3.0) * 1e-3 * np.cos(7 * np.pi * u)
        elif k == "gradient":   # an angular error grows with the vertical temperature gradient
            c = e.get("component", "EBX")
            add[c] = add.get(c, 0) + e.get("urad_per_K", 12.0) * 1e-6 * (cov["T_top"] - cov["T_bottom"])
        elif k == "squareness_T":   # squareness i (0: Y about z) changes with temperature
            dsq = np.zeros((n, 3)); dsq[:, e.get("index", 0)] = e.get("urad_per_K", -8.0) * 1e-6 * (T - 20.0)
            add["dsq"] = dsq
        elif k == "warmup":   # the instrument drifts and settles: um (1 - exp(-t / tau))
            v = np.zeros(3); v["xyz".index(e.get("dir", "x"))] = e.get("um", 4.0) * 1e-3
            extra_dev += (1 - np.exp(-t_s / 3600 / e.get("tau_h", 1.5)))[:, None] * v
        elif k == "scale_step":   # a joint of the scale: the positioning error jumps at x0
            a = e.get("axis", "X"); c = {"X": "EXX", "Y": "EYY", "Z": "EZZ"}[a]
            add[c] = add.get(c, 0) + e.get("um", 3.0) * 1e-3 * (pos[a] > e.get("at", mid[a] + 0.23 * half[a]))
        else:
            raise ValueError(k)
    act = m.tip(pos, probe_eff, add)
    nom = np.column_stack([pos[a] for a in "XYZ"]) + pr
    Ri = rot(inst_r[:, 0], inst_r[:, 1], inst_r[:, 2])
    meas = np.einsum("nij,nj->ni", Ri, act) + inst_t
    noise = rng.normal(0, noise_um * 1e-3, (n, 3))
    dev = meas - nom + extra_dev + noise
    if truth is not None:
        truth["noise"] = noise
    cols = {**pos, "Xp": pr[:, 0], "Yp": pr[:, 1], "Zp": pr[:, 2],
            "dx_um": dev[:, 0] * 1e3, "dy_um": dev[:, 1] * 1e3, "dz_um": dev[:, 2] * 1e3, **cov}
    return cols


def write_csv(path, cols, order=None, fmt="%.6f", crlf=False, drop=(), rename=None, extra_text=None):
    names = [c for c in (order or list(cols)) if c not in drop]
    n = len(next(iter(cols.values())))
    lines = [",".join((rename or {}).get(c, c) for c in names) + ("," + extra_text[0] if extra_text else "")]
    for i in range(n):
        row = ",".join(fmt % cols[c][i] for c in names)
        if extra_text:
            row += "," + extra_text[1](i)
        lines.append(row)
    nl = "\r\n" if crlf else "\n"
    with open(path, "w", newline="") as fh:
        fh.write(nl.join(lines) + nl)
    return path
