"""Nominal inverse kinematics of a five-axis layout, derived from its chain (sympy).

Scope: layouts with three linear axes and two rotary axes, in any arrangement (table-table,
head-head, table-head, inclined axes as on the DMU 50).  Two facts make a closed form generic:

* the tool orientation depends on the rotary axes only: the rotation part of ``tool2work`` is
  ``A0 @ Rot(u1, q1) @ A1 @ Rot(u2, q2) @ A2`` with constant rotations ``A0 A1 A2`` (fixed frames)
  and ``q1``, ``q2`` the rotary positions in chain order (left to right in ``tool2work``);
* for fixed rotary positions the tool tip is affine in the linear positions:
  ``p = M(q_rot) @ (X, Y, Z) + t(q_rot, tool)``.

Tool axis ``k`` (unit, workpiece frame) -> rotary positions: with ``k' = A0^T k``,
``w2 = A1 u2`` and ``p0 = A1 A2 e_z`` the equation ``Rot(u1, q1) Rot(w2, q2) p0 = k'`` is
Paden-Kahan subproblem 2 (Murray, Li, Sastry 1994, sec. 3.3): the intermediate vector
``c = alpha u1 + beta w2 + gamma (u1 x w2)`` with ``gamma = branch * sqrt(...)``, ``branch = +1 or
-1`` choosing one of the two solutions, then two subproblems 1 (``atan2``) give ``q2`` and ``q1``.
On a singular orientation (``k'`` along ``u1``) ``q1`` is undetermined and comes out as
``atan2(0, 0) = 0``; the runtime keeps the previous value there.  Unreachable orientations give
NaN (negative radicand).

Tool tip ``p`` -> linear positions: ``(X, Y, Z) = M^-1 (p - t)``; ``M`` is the derivative of the
nominal tip with respect to the linear positions (``M^T`` when orthogonal).

Units: rad and mm.  This module does no file I/O.
"""

from __future__ import annotations

import sympy as sp

from volerr.machine.layout import Layout

from .codegen import Function
from .kinematics import PROBE, Chain, _radical, _rational_vec, position_symbol
from .volumetric import nominal_point

TOOL_AXIS = sp.symbols("i j k", real=True)
TIP = sp.symbols("x y z", real=True)
BRANCH = sp.Symbol("branch", real=True)


def applies(layout: Layout) -> bool:
    """True for layouts with exactly three linear axes X Y Z and two rotary axes."""
    lin = [a for a in layout.axis_names if layout.axes[a].kind == "linear"]
    rot = [a for a in layout.axis_names if layout.axes[a].kind == "rotary"]
    return lin == ["X", "Y", "Z"] and len(rot) == 2


def rotation_structure(chain: Chain):
    """(A0, u1, axis1, A1, u2, axis2, A2): the rotation part of nominal ``tool2work`` split at
    its two rotary motions (3x3 sympy matrices, unit 3-vectors, axis names)."""
    layout = chain.layout
    parts, axes, dirs = [sp.eye(3)], [], []
    for f in chain.factors:
        if f.is_error:
            continue
        if f.role == "motion" and layout.axes[f.owner].kind == "rotary":
            axes.append(f.owner)
            dirs.append(_rational_vec(layout.axes[f.owner].direction))
            parts.append(sp.eye(3))
        else:
            parts[-1] = parts[-1] * f.nominal[0:3, 0:3]
    if len(axes) != 2:
        raise ValueError(f"layout {layout.name}: expected two rotary motions, found {len(axes)}")
    return parts[0], dirs[0], axes[0], parts[1], dirs[1], axes[1], parts[2]


def _simplify(e):
    """``sympy.simplify(e)``, except for numbers already in simplest form (a rational, a
    radical ``sqrt(n)`` or a rational times one), which it returns unchanged: the fixed
    rotations of most layouts have only such entries (a test compares with simplify)."""
    e = sp.sympify(e)
    if e.is_Rational or _radical(e) or (e.is_Mul and len(e.args) == 2 and e.args[0].is_Rational
                                        and _radical(e.args[1])):
        return e
    return sp.simplify(e)


def _subproblem1(axis: sp.Matrix, a: sp.Matrix, b: sp.Matrix):
    """Angle of the right-hand rotation about unit ``axis`` that turns ``a`` onto ``b``."""
    ap = a - axis * (axis.dot(a))
    bp = b - axis * (axis.dot(b))
    return sp.atan2(axis.dot(ap.cross(bp)), ap.dot(bp))


def rotary_inverse(chain: Chain) -> dict:
    """Axis name -> expression of its position (rad) in the tool axis (i, j, k) and ``branch``."""
    a0, u1, n1, a1, u2, n2, a2 = rotation_structure(chain)
    kp = a0.T * sp.Matrix(TOOL_AXIS)
    w2 = (a1 * u2).applyfunc(_simplify)
    p0 = (a1 * a2 * sp.Matrix([0, 0, 1])).applyfunc(_simplify)
    c12 = sp.nsimplify(_simplify(u1.dot(w2)))
    if _simplify(c12 ** 2 - 1) == 0:
        raise ValueError(f"layout {chain.layout.name}: the two rotary axes are parallel")
    alpha = (c12 * w2.dot(p0) - u1.dot(kp)) / (c12 ** 2 - 1)
    beta = (c12 * u1.dot(kp) - w2.dot(p0)) / (c12 ** 2 - 1)
    cross = u1.cross(w2)
    radicand = sp.factor(sp.simplify(
        (p0.dot(p0) - alpha ** 2 - beta ** 2 - 2 * alpha * beta * c12) / cross.dot(cross)))
    alpha, beta = _simplify(alpha), _simplify(beta)
    gamma = BRANCH * sp.sqrt(radicand)
    c = alpha * u1 + beta * w2 + gamma * cross
    q2 = _subproblem1(w2, p0, c)
    q1 = _subproblem1(u1, c, kp)
    return {n1: q1, n2: q2}


def _reduce_sin_cos(expr, angles) -> sp.Expr:
    """``expr`` (polynomial in sin and cos of ``angles``) expanded and reduced modulo
    ``sin^2 + cos^2 = 1`` of every angle: the remainder of the division by
    ``cos^2 + sin^2 - 1`` in each cosine, a canonical form (at most linear in each cosine).

    Done in a sparse polynomial ring over QQ whose generators are the free symbols, the
    sines and cosines and any radicals of the coefficients (``sqrt(2)``): the divisor is
    monic in the cosine ``c``, so the remainder replaces ``c^k`` by
    ``c^(k mod 2) (1 - s^2)^(k // 2)`` term by term.  The result is mathematically the
    remainder that ``sympy.rem`` gives, expanded: the same canonical expression (the
    generated code is compared byte for byte)."""
    from sympy.polys.domains import QQ
    from sympy.polys.rings import ring

    pairs = [(sp.Dummy(f"s{i}"), sp.Dummy(f"c{i}")) for i in range(len(angles))]
    fwd = {}
    for q, (s_, c_) in zip(angles, pairs):
        fwd[sp.sin(q)], fwd[sp.cos(q)] = s_, c_
    e = sp.sympify(expr).xreplace(fwd)
    radicals = sorted((a for a in e.atoms(sp.Pow) if _radical(a)), key=sp.default_sort_key)
    # every sine is a generator: the remainder brings in sin(q) where only cos(q)^2 was
    gens = [*sorted(e.free_symbols | {s_ for s_, _ in pairs}, key=sp.default_sort_key),
            *radicals]
    try:
        R, *xs = ring(gens, QQ)
        p = R.from_expr(e)
    except (ValueError, TypeError, sp.polys.polyerrors.CoercionFailed):
        return _reduce_sin_cos_sympy(expr, angles)   # not a polynomial of that shape
    index = {g: i for i, g in enumerate(gens)}
    for s_, c_ in pairs:
        if c_ not in index:
            continue
        ic, s = index[c_], xs[index[s_]]
        if all(m[ic] < 2 for m in p.keys()):
            continue
        powers = [R.one]
        out = R.zero
        for m, coeff in p.terms():
            k = m[ic]
            while len(powers) <= k // 2:
                powers.append(powers[-1] * (1 - s ** 2))
            low = m[:ic] + (k % 2,) + m[ic + 1:]
            out += R({low: coeff}) * powers[k // 2]
        p = out
    back = {v: k for k, v in fwd.items()}
    return sp.expand(p.as_expr().xreplace(back))


def _reduce_sin_cos_sympy(expr, angles) -> sp.Expr:
    """:func:`_reduce_sin_cos` by ``sympy.rem`` on expressions (the general path)."""
    pairs = [(sp.Dummy(f"s{i}"), sp.Dummy(f"c{i}")) for i in range(len(angles))]
    fwd = {}
    for q, (s_, c_) in zip(angles, pairs):
        fwd[sp.sin(q)], fwd[sp.cos(q)] = s_, c_
    e = sp.expand(sp.expand(expr).xreplace(fwd))
    for s_, c_ in pairs:
        if e.has(c_):
            e = sp.expand(sp.rem(e, c_ ** 2 + s_ ** 2 - 1, c_))
    return sp.expand(e.xreplace({v: k for k, v in fwd.items()}))


def linear_inverse(chain: Chain) -> dict:
    """Linear axis -> expression in the rotary positions, the tip (x, y, z) and the tool offset."""
    lin = [position_symbol(a) for a in ("X", "Y", "Z")]
    layout = chain.layout
    angles = [position_symbol(a) for a in layout.axis_names if layout.axes[a].kind == "rotary"]
    p = nominal_point(chain)
    m = p.jacobian(sp.Matrix(lin))
    t = p.subs({s: 0 for s in lin})
    mtm = (m.T * m).applyfunc(lambda e: _reduce_sin_cos(e, angles))
    minv = m.T if mtm == sp.eye(3) else sp.simplify(m.inv())
    sol = minv * (sp.Matrix(TIP) - t)
    return {a: _reduce_sin_cos(sol[i], angles) for i, a in enumerate(("X", "Y", "Z"))}


def inverse_functions(layout: Layout, chain: Chain | None = None) -> list[Function]:
    """Generated functions ``inverse_rotary`` and ``inverse_linear`` of a five-axis layout
    (``chain``: the layout's chain if already built, default tool-point pivot)."""
    chain = Chain.from_layout(layout) if chain is None else chain
    rot = [a for a in layout.axis_names if layout.axes[a].kind == "rotary"]
    rinv = rotary_inverse(chain)
    linv = linear_inverse(chain)
    return [
        Function("inverse_rotary", [str(s) for s in TOOL_AXIS] + [str(BRANCH)],
                 [rinv[a] for a in rot],
                 f"Rotary positions ({', '.join(rot)}), rad, that give the unit tool axis "
                 "(i, j, k) "
                 "in the workpiece frame; branch = +1 or -1 picks one of the two solutions "
                 "(Paden-Kahan subproblem 2). NaN where the orientation is unreachable."),
        Function("inverse_linear", rot + [str(s) for s in TIP] + [str(s) for s in PROBE],
                 [linv[a] for a in ("X", "Y", "Z")],
                 "Linear positions (X, Y, Z), mm, that put the tool tip (offset Xp, Yp, Zp in the "
                 "tool frame) at (x, y, z) in the workpiece frame for the given rotary "
                 "positions (rad)."),
    ]
