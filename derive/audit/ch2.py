"""Audit of Ellingsdalen (2021), ch. 2: Rodrigues' formula and its worked example (eq. 2.34-2.38,
numbers recomputed), the squareness of eq. 2.39, the infinitesimal rotation of eq. 2.40-2.41,
the straightedge reversal of eq. 2.43-2.44, the Type A statistics of eq. 2.45-2.49 and the
standard deviation of the appendix C.2 script (sympy / numpy, no file I/O).

The printed material is the parsed ``data/printed_ch2.toml``.  Printed numbers are
compared with the exact value first; a number with k decimals stands for its rounding interval
(+-0.5e-k).  Where only the rounded intermediates printed in the text reproduce a result, the
verdict is a convention (``rounding:``), with both values in the evidence.
"""

from __future__ import annotations

import math
from decimal import Decimal

import numpy as np
import sympy as sp

from .framework import Verdict, category_of

DATA_FILE = "printed_ch2.toml"
SOURCE = "Ellingsdalen 2021"
LAYOUT = "-"


def _v(eq, comp, category, erratum, evidence, printed, derived, tried=(), used=(),
       **fields) -> Verdict:
    same = category == "identical"
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used),
                   **fields)


def interval(text: str) -> tuple[float, float]:
    """Rounding interval of a printed number ("0.899" -> (0.8985, 0.8995))."""
    d = Decimal(text)
    half = Decimal(5) * Decimal(10) ** (d.as_tuple().exponent - 1)
    return float(d - half), float(d + half)


def _within(text: str, value: float) -> bool:
    lo, hi = interval(text)
    return lo - 1e-12 <= value <= hi + 1e-12


def _skew(w):
    return np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])


def _expm(a: np.ndarray) -> np.ndarray:
    """Matrix exponential by its Taylor series (40 terms; |a| <= pi here)."""
    out, term = np.eye(3), np.eye(3)
    for k in range(1, 40):
        term = term @ a / k
        out = out + term
    return out


# --------------------------------------------------------------------------- Rodrigues
def audit_rodrigues(item: dict) -> Verdict:
    th = sp.Symbol("theta", real=True)
    rng = np.random.default_rng(234)
    worst = 0.0
    k_sym = sp.MatrixSymbol("K", 3, 3)
    f = sp.lambdify((th, k_sym), sp.sympify(item["formula"], locals={
        "theta": th, "K": k_sym, "I": sp.Identity(3)}), "numpy")
    for _ in range(5):
        w = rng.normal(size=3)
        w /= np.linalg.norm(w)
        t = rng.uniform(0, math.pi)
        k = _skew(w)
        worst = max(worst, float(np.max(np.abs(np.asarray(f(t, k), float) - _expm(k * t)))))
    same = worst < 1e-12
    return _v(f"eq. {item['id']}", "", "identical" if same else "printing_error",
              "differs from exp([w] theta)",
              f"for a unit axis w, [w]^3 = -[w], so the series of exp([w] theta) sums to "
              f"I + sin(theta) [w] + (1 - cos(theta)) [w]^2; checked against the matrix "
              f"exponential (Taylor series) at 5 random unit axes and angles: max |difference| "
              f"{worst:.2g}", item["text"], "exp([w] theta)")


def audit_example(item: dict) -> list[Verdict]:
    out = []
    eq = f"eq. {item['id']}"
    theta = math.radians(float(item["theta_deg"]))
    w_exact = np.array([0.0, math.sqrt(3) / 2, 0.5])
    w_pr = [float(x) for x in item["axis"]]
    ok_axis = all(_within(t, v) for t, v in zip(item["axis"], w_exact))
    ok_rad = _within(item["theta_rad"], theta)
    ok_sin = _within(item["sin"], math.sin(theta))
    ok_c = _within(item["one_minus_cos"], 1 - math.cos(theta))
    skew_pr = np.array([[float(x) for x in r] for r in item["skew"]])
    ok_skew = bool(np.allclose(skew_pr, _skew(w_pr)))
    ok = ok_axis and ok_rad and ok_sin and ok_c and ok_skew
    out.append(_v(f"{eq} (2.35-2.37)", "inputs", "identical" if ok else "printing_error",
                  "an input number differs",
                  f"30 deg = {theta:.5f} rad (printed {item['theta_rad']}: "
                  f"{'within' if ok_rad else 'outside'} its rounding interval); the unit axis "
                  f"(0, sqrt(3)/2, 1/2) = (0, {w_exact[1]:.5f}, 0.5) (printed "
                  f"({', '.join(item['axis'])}): {'within' if ok_axis else 'outside'}); "
                  f"sin 30 deg = 0.5 (printed {item['sin']}); 1 - cos 30 deg = "
                  f"{1 - math.cos(theta):.5f} (printed {item['one_minus_cos']}: "
                  f"{'within' if ok_c else 'outside'}); [w] of the printed axis = "
                  f"{_skew(w_pr).round(3).tolist()} ({'as' if ok_skew else 'not as'} printed)",
                  item["text"], "theta = pi/6, w = (0, sqrt(3)/2, 1/2)"))
    k = _skew(w_exact)
    r_exact = np.eye(3) + math.sin(theta) * k + (1 - math.cos(theta)) * k @ k
    assert np.allclose(r_exact, _expm(k * theta))
    r_pr = item["R"]
    off = [(i, j) for i in range(3) for j in range(3) if not _within(r_pr[i][j], r_exact[i, j])]
    tried = [f"the exact R (theta = pi/6, unit axis): {len(off)} of 9 printed entries outside "
             f"their rounding interval" + (": " + ", ".join(
                 f"({i + 1},{j + 1}) printed {r_pr[i][j]}, exact {r_exact[i, j]:.6f}"
                 for i, j in off) if off else "")]
    if not off:
        out.append(_v(f"{eq} (2.38)", "R", "identical", "", "every entry of the exact R = "
                      f"{r_exact.round(6).tolist()} lies in the rounding interval of the printed "
                      f"entry", str(r_pr), str(r_exact.round(4).tolist()), tried))
    else:
        # the same entries from the rounded intermediates printed in eq. 2.37: interval
        # arithmetic over the 3-decimal inputs (0 and 0.5 are exact values)
        c_lo, c_hi = interval(item["one_minus_cos"])
        w_lo, w_hi = interval(item["axis"][1])
        ranges = []
        for i, j in off:
            vals = []
            for cc in np.linspace(c_lo, c_hi, 5):
                for w2 in np.linspace(w_lo, w_hi, 5):
                    w = np.array([0.0, w2, 0.5])
                    kk = _skew(w)
                    vals.append((np.eye(3) + 0.5 * kk + cc * kk @ kk)[i, j])
            ranges.append((min(vals), max(vals)))
        meets = all(lo <= interval(r_pr[i][j])[1] and interval(r_pr[i][j])[0] <= hi
                    for (i, j), (lo, hi) in zip(off, ranges))
        tried.append("from the rounded intermediates of eq. 2.37 (1 - cos = "
                     f"{item['one_minus_cos']}, axis component {item['axis'][1]}, each within "
                     "its rounding interval): " + ", ".join(
                         f"({i + 1},{j + 1}) in {lo:.5f} .. {hi:.5f}"
                         for (i, j), (lo, hi) in zip(off, ranges))
                     + (": meets the printed interval" if meets else ": does not meet"))
        used = ["rounding:eq. 2.38 from the rounded intermediates of eq. 2.37"] if meets else \
            ["inconsistent:eq. 2.38 entry"]
        bad = ", ".join(f"({i + 1},{j + 1})" for i, j in off)
        out.append(_v(f"{eq} (2.38)", "R", category_of(used), f"entry {bad} rounded from the "
                      f"rounded intermediates, not from the exact value",
                      f"R = I + sin(theta) [w] + (1 - cos(theta)) [w]^2 with theta = pi/6 and "
                      f"the unit axis (0, sqrt(3)/2, 1/2) is {r_exact.round(6).tolist()}; 8 "
                      f"entries lie in the rounding intervals of the printed ones, entry {bad} "
                      f"does not: " + "; ".join(
                          f"exact {r_exact[i, j]:.6f} rounds to {r_exact[i, j]:.3f}, printed "
                          f"{r_pr[i][j]} stands for {interval(r_pr[i][j])[0]:g} .. "
                          f"{interval(r_pr[i][j])[1]:g}" for i, j in off)
                      + ". Computed from the rounded numbers printed in eq. 2.37 ("
                      f"{item['one_minus_cos']} and {item['axis'][1]}, each anywhere in its "
                      "rounding interval) the entry ranges over " + "; ".join(
                          f"{lo:.5f} .. {hi:.5f}" for lo, hi in ranges)
                      + (", which meets the printed value's interval: the printed matrix is "
                         "the product of the printed, rounded intermediates" if meets else ""),
                      str(r_pr), str(r_exact.round(6).tolist()), tried, used,
                      statement="results computed from the rounded intermediates printed in "
                                "eq. 2.37"))
    wt = w_exact * theta
    ok = all(_within(t, v) for t, v in zip(item["exp_coords"], wt))
    out.append(_v(f"{eq} (exponential coordinates)", "w theta",
                  "identical" if ok else "printing_error", "differs",
                  f"w theta = (0, sqrt(3)/2, 1/2) * pi/6 = ({wt[0]:g}, {wt[1]:.5f}, "
                  f"{wt[2]:.5f}); each within the rounding interval of the printed "
                  f"({', '.join(item['exp_coords'])})" if ok else "outside", str(item["exp_coords"]),
                  f"({wt[0]:g}, {wt[1]:.4f}, {wt[2]:.4f})"))
    return out


# ---------------------------------------------------------------------------- eq. 2.39
def audit_squareness(item: dict) -> Verdict:
    """The X motion follows the line (1, 0, k_ZX) (E_ZX = k_ZX x), the Z motion (k_XZ, 0, 1);
    inclinations measured as right-handed rotations about +Y (B)."""
    kzx, kxz = sp.symbols("k_ZX k_XZ", real=True)
    u_x = sp.Matrix([1, 0, kzx])
    u_z = sp.Matrix([kxz, 0, 1])
    theta_x = -kzx                # Ry(t) e_x = (cos t, 0, -sin t): first order t = -k_ZX
    theta_z = kxz                 # Ry(t) e_z = (sin t, 0, cos t): t = k_XZ
    cos_phi = (u_x.dot(u_z) / (u_x.norm() * u_z.norm()))
    eps = sp.Symbol("eps")
    phi = sp.acos(cos_phi.subs({kzx: eps * kzx, kxz: eps * kxz}))
    excess = sp.expand(sp.series(phi, eps, 0, 2).removeO().subs(eps, 1) - sp.pi / 2)
    same = sp.expand(excess - (theta_x - theta_z)) == 0
    return _v(f"eq. {item['id']}", "", "identical" if same else "printing_error", "differs",
              f"with E_ZX = k_ZX x and E_XZ = k_XZ z the X motion follows (1, 0, k_ZX) and the "
              f"Z motion (k_XZ, 0, 1); measured as rotations about +Y (B, the same sense for "
              f"both), theta_X,ZX = {sp.sstr(theta_x)} and theta_Z,ZX = {sp.sstr(theta_z)}; the "
              f"angle between the two lines is 90 deg + ({sp.sstr(excess)}) to first order, so "
              f"theta_X,ZX - theta_Z,ZX = {sp.sstr(theta_x - theta_z)} is the excess over 90 deg, "
              f"positive for an angle larger than 90 deg as the text says: the squareness of X "
              f"relative to Z, E_B(0Z)X (= -E_B(0X)Z)", item["text"],
              "theta_X,ZX - theta_Z,ZX")


def audit_infinitesimal(item: dict) -> Verdict:
    d, e = sp.symbols("dtheta dphi", real=True)
    lx = sp.Matrix([[0, 0, 0], [0, 0, -1], [0, 1, 0]])      # [e_x]: the generator of Rx
    ly = sp.Matrix([[0, 0, 1], [0, 0, 0], [-1, 0, 0]])
    derived = sp.eye(3) + lx * d
    printed = sp.Matrix([[sp.sympify(c, locals={"dtheta": d}) for c in r] for r in item["rows"]])
    exact = sp.Matrix([[1, 0, 0], [0, sp.cos(d), -sp.sin(d)], [0, sp.sin(d), sp.cos(d)]])
    first = exact.applyfunc(lambda v: sp.series(v, d, 0, 2).removeO())
    comm = sp.expand((sp.eye(3) + lx * d) * (sp.eye(3) + ly * e)
                     - (sp.eye(3) + ly * e) * (sp.eye(3) + lx * d))
    order2 = all(sp.Poly(v, d, e).total_degree() >= 2 for v in comm if v != 0)
    same = printed == derived == first and order2
    return _v(f"eq. {item['id']}", "", "identical" if same else "printing_error", "differs",
              f"I + [e_x] dtheta with [e_x] = {lx.tolist()} (the generator of rotations about "
              f"x); equal to the first-order series of Rx(dtheta); two infinitesimal rotations "
              f"commute up to {sp.sstr(comm)} (second order), as the text states",
              item["text"], sp.sstr(derived.tolist()))


def audit_reversal(item: dict) -> Verdict:
    e1, e2, m, s = sp.symbols("E1 E2 M S", real=True)
    # normal set-up: the sensor reads the straightedge's deviation M and the axis' S; reversed
    # (straightedge turned over, sensor on the other side): M with the same sign (the same
    # surface faces the sensor), the axis' S with the opposite sign
    sol = sp.solve([sp.Eq(e1, m + s), sp.Eq(e2, m - s)], [m, s], dict=True)[0]
    pm, ps = (sp.sympify(item[k], locals={"E1": e1, "E2": e2}) for k in ("M", "S"))
    same = sp.simplify(sol[m] - pm) == 0 and sp.simplify(sol[s] - ps) == 0
    other = sp.solve([sp.Eq(e1, m + s), sp.Eq(e2, s - m)], [m, s], dict=True)[0]
    return _v(f"eq. {item['id']}", "", "identical" if same else "printing_error", "differs",
              f"reversal: E1 = M + S (normal), E2 = M - S (straightedge turned over and the "
              f"sensor on its other side: the same surface faces the sensor, the axis' "
              f"deviation changes sign); solved: M = {sp.sstr(sol[m])}, S = {sp.sstr(sol[s])}, "
              f"as printed. The other sign model (E2 = S - M) would give M = "
              f"{sp.sstr(other[m])}: the roles exchanged", item["text"],
              f"M = {sp.sstr(sol[m])}, S = {sp.sstr(sol[s])}",
              ["E2 = M - S (ISO 230-1 reversal): exact", "E2 = S - M: M and S exchanged"])


# --------------------------------------------------------------------------- statistics
def audit_statistics(items: list) -> list[Verdict]:
    out = []
    mu, sig = sp.symbols("mu sigma", positive=True)
    for it in items:
        verdicts = []
        for n in (3, 4):
            e = sp.symbols(f"e1:{n + 1}", real=True)
            q = [mu + x for x in e]
            qbar = sum(q) / n
            qi = sp.IndexedBase("q")
            k, j = sp.symbols("k j", integer=True)
            expr = sp.sympify(it["formula"], locals={"q": qi, "n": n, "k": k, "j": j,
                                                     "qbar": qbar, "Sum": sp.Sum})
            expr = expr.doit().xreplace({qi[i + 1]: q[i] for i in range(n)})
            expr = sp.expand(expr)

            def expect(v):
                """E[v] for independent e_i with mean 0 and variance sigma^2."""
                v = sp.expand(v)
                tot = 0
                for t in sp.Add.make_args(v):
                    powers = {s: p for s, p in t.as_powers_dict().items() if s in e}
                    if any(p == 1 for p in powers.values()):
                        continue
                    coeff = t / sp.Mul(*(s ** p for s, p in powers.items()))
                    tot += coeff * sp.Mul(*(sig ** p if p == 2 else sp.Integer(3) * sig ** 4
                                            if p == 4 else sp.Symbol("m%d" % p) for p in
                                            powers.values()))
                return sp.expand(tot)
            name = it["name"]
            if name == "mean":
                ok = sp.expand(expr - qbar) == 0 and sp.expand(expect(expr) - mu) == 0
            elif name == "variance":
                ok = sp.expand(expect(expr) - sig ** 2) == 0
            elif name == "variance_of_mean":
                ok = sp.expand(expect(expr) - expect((qbar - mu) ** 2)) == 0
            elif name in ("std", "std_of_mean"):
                target = sig ** 2 if name == "std" else sig ** 2 / n
                ok = sp.expand(expect(sp.expand(expr ** 2)) - target) == 0 and \
                    expr.subs({x: 1 for x in e}).is_nonnegative is not False
            verdicts.append(ok)
        what = {"mean": "the arithmetic mean (GUM 4.2.1), whose expectation is the mean of the "
                        "distribution",
                "variance": "the experimental variance with divisor n - 1 (GUM 4.2.2): its "
                            "expectation is sigma^2 (unbiased), while divisor n would give "
                            "(n-1)/n sigma^2",
                "std": "the positive square root of the experimental variance (GUM 4.2.2): "
                       "its square is unbiased for sigma^2",
                "variance_of_mean": "the experimental variance of the mean (GUM 4.2.3): its "
                                    "expectation equals the variance of the mean, sigma^2/n",
                "std_of_mean": "the experimental standard deviation of the mean (GUM 4.2.3), "
                               "the Type A standard uncertainty of q-bar"}[it["name"]]
        same = all(verdicts)
        out.append(_v(f"eq. {it['id']}", it["name"], "identical" if same else "printing_error",
                      "not the GUM estimator", f"{what}; checked symbolically for n = 3 and 4 "
                      f"with q_i = mu + e_i, e_i independent, mean 0, variance sigma^2",
                      it["text"], it["formula"]))
    return out


def audit_script(item: dict) -> Verdict:
    rng = np.random.default_rng(2021)
    data = rng.normal(10.0, 2.0, (4, 11))
    ns = {"np": np, "Error_values": data, "n_pos": 11}
    exec(compile(item["code"], "<printed appendix C.2>", "exec"), ns)  # noqa: S102
    want = data.std(axis=0, ddof=1)
    same = bool(np.allclose(ns["Std_dev"], want) and np.allclose(ns["Average_values"],
                                                                   data.mean(axis=0)))
    return _v(item["id"], "Std_dev", "identical" if same else "printing_error", "differs",
              "run on 4 rounds x 11 positions of random data: Average_values is the mean of "
              "eq. 2.45 and Std_dev the experimental standard deviation of eq. 2.47 with n = 4 "
              "(divisor n - 1 = 3), equal to numpy's std(ddof=1); the error bars of the plots "
              "are yerr = 2 Std_dev, twice the standard deviation of one round (eq. 2.47), not "
              "the standard deviation of the plotted mean (eq. 2.49, half of it for n = 4)",
              item["text"], "s(q_k), n = 4")


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on ch. 2 (layout-independent: skipped when layouts are named)."""
    if layouts:
        return []
    out = []
    if "rodrigues" in printed:
        out.append(audit_rodrigues(printed["rodrigues"]))
    if "example" in printed:
        out.extend(audit_example(printed["example"]))
    if "squareness" in printed:
        out.append(audit_squareness(printed["squareness"]))
    if "infinitesimal" in printed:
        out.append(audit_infinitesimal(printed["infinitesimal"]))
    if "reversal" in printed:
        out.append(audit_reversal(printed["reversal"]))
    out.extend(audit_statistics(printed.get("statistic", [])))
    if "script" in printed:
        out.append(audit_script(printed["script"]))
    return out
