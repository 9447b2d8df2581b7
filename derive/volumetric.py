"""Volumetric error, sensitivities, random error and transfer rules derived from a chain.

Everything here is computed from :class:`volerr.derive.kinematics.Chain`; nothing is
transcribed from a paper.  Units: positions and offsets in mm, rotary positions in rad,
translational errors in mm, angular errors in rad.  Sign: error = actual - nominal position of
the probe tip / tool centre point in the workpiece frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

from volerr.machine.layout import SQUARENESS

from .htm import Factor, _matmul
from .kinematics import (NOT_POLYNOMIAL, PROBE, Chain, RingMatrices, _table_rotary,
                         parameter_symbol, position_symbol, stage_factors, twist)
from .symbols import PROBE_TWIST, insert_variations


def nominal_point(chain: Chain) -> sp.Matrix:
    """Nominal probe-tip position in the workpiece frame (3x1), mm."""
    return (chain.nominal_htm() * sp.Matrix([*PROBE, 1]))[0:3, 0]


def nominal_tool_axis(chain: Chain) -> sp.Matrix:
    """Nominal direction of the tool axis (tool-frame +z) in the workpiece frame (3x1)."""
    return chain.nominal_htm()[0:3, 2]


def work_rotation(chain: Chain) -> sp.Matrix:
    """Orientation of the workpiece frame in the base frame (the frame of the machine's linear
    axes), 3x3: columns are the workpiece axes in base coordinates.  The workpiece side of
    ``tool2work`` is ``base2work``; this is the transpose of its rotation."""
    layout = chain.layout
    m = sp.eye(4)
    for entry in reversed(layout.workpiece_chain):
        fs = stage_factors(layout, entry)
        if entry in layout.axes and layout.axes[entry].kind == "rotary":
            fs = _table_rotary(fs)
        for f in fs:
            if not f.is_error:
                m = m * f.nominal
    return m[0:3, 0:3].T.applyfunc(sp.expand)


def volumetric_error(chain: Chain) -> sp.Matrix:
    """First-order volumetric error (dX, dY, dZ), linear in the error parameters."""
    return _first_order_displacement(chain, sp.Matrix([*PROBE, 1]))


def _first_order_displacement(chain: Chain, v: sp.Matrix) -> sp.Matrix:
    """sum_k prefix_k @ D_k @ suffix_k @ v: the first-order change of the homogeneous vector v
    (a point when v[3] = 1, a direction when v[3] = 0), expanded.

    Computed on polynomial-ring elements (:class:`volerr.derive.kinematics.RingMatrices`):
    the expanded result is the same expression as ``expand`` of the product of the
    matrices; chains with other functions than sines and cosines take the expression path."""
    factors = chain.factors
    mats = [f.first_order() if f.is_error else f.nominal for f in factors]
    ring = RingMatrices.build([*mats, v])
    if ring is not None:
        try:
            mats = [ring.convert(m) for m in mats]
            v = ring.convert(v)
        except NOT_POLYNOMIAL:
            ring = None
    if ring is None:
        return _first_order_displacement_sympy(chain, v)
    suffix = [None] * len(factors)
    for i in range(len(factors) - 1, -1, -1):
        suffix[i] = v
        if not factors[i].is_error:
            v = ring.mul(mats[i], v)
    total = None
    prefix = None
    for i, f in enumerate(factors):
        if f.is_error:
            term = ring.mul(mats[i], suffix[i])
            if prefix is not None:
                term = ring.mul(prefix, term)
            total = term if total is None else ring.add(total, term)
        else:
            prefix = mats[i] if prefix is None else ring.mul(prefix, mats[i])
    if total is None:
        return sp.zeros(3, 1)
    return sp.Matrix([total[i][0].as_expr() for i in range(3)])


def _first_order_displacement_sympy(chain: Chain, v: sp.Matrix) -> sp.Matrix:
    """:func:`_first_order_displacement` on sympy expressions (any chain)."""
    factors = chain.factors
    suffix = [None] * len(factors)
    for i in range(len(factors) - 1, -1, -1):
        suffix[i] = v
        if not factors[i].is_error:
            v = factors[i].nominal * v
    total = sp.zeros(4, 1)
    prefix = sp.eye(4)
    for i, f in enumerate(factors):
        if f.is_error:
            total += prefix * (f.first_order() * suffix[i])
        else:
            prefix = prefix * f.nominal
    return sp.Matrix([sp.expand(total[i]) for i in range(3)])


def collect_symbols(expr, syms) -> sp.Expr:
    """``sympy.collect(expr, syms)`` for an expanded sum (the same expression, tested): each
    term goes to the group of the first of ``syms`` (in that order) that is one of its
    factors, alone or to a positive integer power; the group is ``key * (sum of the rest)``.
    Terms without such a factor stay as they are.  One pass over the terms, where ``collect``
    re-parses every term for every symbol."""
    order = {q: i for i, q in enumerate(syms)}
    groups, rest = {}, []
    for term in sp.Add.make_args(expr):
        factors = sp.Mul.make_args(term)
        best = None
        for j, f in enumerate(factors):
            base = f.base if f.is_Pow and f.exp.is_Integer and f.exp > 0 else f
            i = order.get(base)
            if i is not None and (best is None or i < best[0]):
                best = (i, j)
        if best is None:
            rest.append(term)
            continue
        j = best[1]
        groups.setdefault(factors[j], []).append(sp.Mul(*factors[:j], *factors[j + 1:]))
    return sp.Add(*rest, *[sp.Mul(k, sp.Add(*c)) for k, c in groups.items()])


def orientation_error(chain: Chain) -> sp.Matrix:
    """First-order error of the tool-axis direction (tool +z) in the workpiece frame."""
    return _first_order_displacement(chain, sp.Matrix([0, 0, 1, 0]))


def exact_error(chain: Chain) -> sp.Matrix:
    """Exact (non-linearised) error: exact actual chain minus nominal chain, applied to the probe."""
    p = sp.Matrix([*PROBE, 1])
    return (_matmul(chain.exact_htm(), p) - _matmul(chain.nominal_htm(), p))[0:3, 0]


def sensitivity(chain: Chain, error: sp.Matrix | None = None) -> sp.Matrix:
    """3 x n_parameters matrix d(dX, dY, dZ)/d(parameter) (unitless or mm/rad)."""
    error = volumetric_error(chain) if error is None else error
    params = list(chain.parameters)
    index = {q: j for j, q in enumerate(params)}
    out = sp.zeros(3, len(params))
    for i in range(3):
        # the first-order error is linear in the parameters: each expanded term holds exactly
        # one parameter to the first power, its coefficient is the derivative (as diff gives)
        coeffs = [[] for _ in params]
        for term in sp.Add.make_args(expand(error[i])):
            found = [q for q in term.free_symbols if q in index]
            if len(found) != 1 or not _linear_factor(term, found[0]):
                return error.jacobian(sp.Matrix(params))   # not linear term by term: general
            coeffs[index[found[0]]].append(term.xreplace({found[0]: sp.Integer(1)}))
        for j, c in enumerate(coeffs):
            out[i, j] = sp.Add(*c)
    return out


#: twist coordinates of :func:`setup_sensitivity` (work end, then tool end)
SETUP_TWIST = ("dx", "dy", "dz", "ex", "ey", "ez")


def setup_sensitivity(chain: Chain) -> sp.Matrix:
    """3 x 12 matrix d(dX, dY, dZ)/d(twist): columns 0-5 a small rigid twist
    (dx, dy, dz mm; ex, ey, ez rad) of the workpiece frame standing first in the chain (the
    measuring instrument's placement: ``(I + D) T p``), columns 6-11 the same twist at the
    tool end, in the tool frame, standing last (``T (I + D) p``: a probe / tool offset error).
    Exact in the nominal chain (first order in the twist)."""
    T, p = chain.nominal_htm(), sp.Matrix([*PROBE, 1])
    # the twist is linear in its six coordinates: column k is the product with the twist of
    # the k-th unit coordinate, computed on polynomial-ring elements (expanded, as below)
    ring = RingMatrices.build([T, p])
    if ring is not None:
        try:
            Tr, pr = ring.convert(T), ring.convert(p)
        except NOT_POLYNOMIAL:
            ring = None
    if ring is not None:
        units = [ring.convert(twist(**{k: 1})) for k in SETUP_TWIST]
        Tp = ring.mul(Tr, pr)
        work = [ring.mul(g, Tp) for g in units]
        tool = [ring.mul(Tr, ring.mul(g, pr)) for g in units]
        return sp.Matrix(3, 12, lambda i, j: (work[j] if j < 6 else tool[j - 6])[i][0].as_expr())
    syms = sp.symbols("_tw_dx _tw_dy _tw_dz _tw_ex _tw_ey _tw_ez", real=True)
    d = twist(**dict(zip(SETUP_TWIST, syms)))
    work = (d * (T * p))[0:3, 0].jacobian(sp.Matrix(syms))
    tool = (T * (d * p))[0:3, 0].jacobian(sp.Matrix(syms))
    return work.row_join(tool).applyfunc(sp.expand)
def symbol_sensitivity(chain: Chain) -> sp.Matrix:
    """3 x n_symbols matrix d(nominal tool point)/d(symbol), symbols in
    :attr:`Layout.symbols` order (mm/mm or mm/rad): the nominal chain (error factors left out)
    with every symbol's variation inserted (:func:`volerr.derive.symbols.insert_variations`),
    differentiated by its first-order machinery."""
    names = chain.layout.symbols
    delta = {n: sp.Symbol(f"_dsym{i}", real=True) for i, n in enumerate(names)}
    factors = insert_variations([f for f in chain.factors if not f.is_error], delta)
    factors.append(Factor(twist_args={k: delta[s] for s, k in PROBE_TWIST.items()},
                          owner="tool", role="effect"))
    varied = Chain(chain.layout, factors, chain.positions, tuple(delta[n] for n in names))
    return sensitivity(varied)


def _is_expanded_factor(f) -> bool:
    if f.is_Atom:
        return True
    if f.is_Pow and f.base.is_Integer and f.base > 0 and f.exp.is_Rational:
        return True   # a numeric radical such as sqrt(2)
    if f.is_Pow:
        return f.exp.is_Integer and (f.base.is_Atom or _is_expanded_factor(f.base)) and \
            not f.base.is_Add and not f.base.is_Mul and not f.base.is_Pow
    if f.func in (sp.sin, sp.cos):
        return is_expanded(f.args[0])
    return False


def is_expanded(expr) -> bool:
    """True when ``sympy.expand(expr)`` is ``expr`` itself, recognised for the shapes the
    derivation produces: sums of products of symbols, numbers, integer powers of those and
    sines and cosines of such sums (anything else answers False, and the caller expands)."""
    return all(_is_expanded_factor(f) for t in sp.Add.make_args(expr)
               for f in sp.Mul.make_args(t))


def expand(expr):
    """``sympy.expand(expr)``, skipped when ``expr`` is already expanded (:func:`is_expanded`)."""
    return expr if is_expanded(expr) else sp.expand(expr)


def _linear_factor(term, q) -> bool:
    """``sp.degree(term, q) == 1`` for a term of an expanded sum: a product with the factor
    ``q`` to the first power and ``q`` nowhere else (checked without building a polynomial;
    anything else is left to ``sp.degree``)."""
    factors = sp.Mul.make_args(term)
    if factors.count(q) == 1 and not any(f != q and f.has(q) for f in factors):
        return True
    return sp.degree(term, q) == 1


def random_error_termwise(sens: sp.Matrix, sigmas) -> sp.Matrix:
    """Pahk's printed quadrature (eq. 5, 8): every monomial of a sensitivity squared alone,
    so cross terms such as 2 Z Zp of (Z + Zp)^2 are dropped."""
    rows = []
    for i in range(3):
        # one Add of all squares (the same canonical sum as adding them one by one)
        acc = []
        for j in range(sens.shape[1]):
            for term in sp.Add.make_args(expand(sens[i, j])):
                if term != 0:
                    acc.append(term ** 2 * sigmas[j] ** 2)
        rows.append(sp.sqrt(sp.Add(*acc)))
    return sp.Matrix(rows)


def random_error_exact(sens: sp.Matrix, sigmas) -> sp.Matrix:
    """First-order standard uncertainty of (dX, dY, dZ) for independent parameters:
    ``u_k = sqrt(sum_p (d dk/d p)^2 s_p^2)`` (GUM eq. 10, no covariances), ``s_p`` the standard
    deviation of parameter p.  One fused expression per component, so that the runtime never
    builds the (3, n_parameters, N) sensitivity array."""
    rows = []
    for i in range(3):
        acc = sp.Integer(0)
        for j in range(sens.shape[1]):
            if sens[i, j] != 0:
                acc += sens[i, j] ** 2 * sigmas[j] ** 2
        rows.append(sp.sqrt(acc))
    return sp.Matrix(rows)


def nominal_jacobian(chain: Chain) -> sp.Matrix:
    """Exact derivatives of the nominal tool tip (rows 0-2, mm per mm or mm per rad) and of the
    nominal tool axis (rows 3-5, per mm = 0 or per rad) with respect to the axis positions in
    chain order: a 6 x n_axes matrix."""
    q = sp.Matrix(chain.positions)
    tip = nominal_point(chain).jacobian(q)
    axis = nominal_tool_axis(chain).jacobian(q)
    return tip.col_join(axis)


OFFSETS = sp.symbols("Xo Yo Zo", real=True)


@dataclass
class TransferRules:
    """Transfer rules: measured value = reference value + ``shift``.

    ``shift[name]`` is a sympy expression in the offsets (Xo, Yo, Zo) and the angular error
    parameters.  For a translational error of an axis it is the Abbe term ``(eps x o)`` of the
    axis' own angular errors at lever arm ``o`` from the axis' reference point; for a
    squareness it is what the other axes' angular errors at position ``o`` add to the angle
    between the straightness reference lines."""

    shift: dict


def transfer_rules(chain: Chain, error: sp.Matrix | None = None) -> TransferRules:
    """Derive the transfer rules of every linear axis' translational errors and squareness."""
    layout = chain.layout
    o = sp.Matrix([*OFFSETS, 1])
    shift = {}
    for f in chain.factors:
        if f.role != "component" or layout.axes[f.owner].kind != "linear":
            continue
        angular_only = {k: v for k, v in f.twist_args.items() if k in ("ex", "ey", "ez")}
        abbe = twist(**angular_only) * o
        for i, t in enumerate("XYZ"):
            shift[f"E{t}{f.owner}"] = sp.expand(abbe[i])
    error = volumetric_error(chain) if error is None else error
    frozen = _squareness_slopes(chain, error)
    for name, expr in frozen.items():
        shift[name] = sp.expand(expr - parameter_symbol(name))
    return TransferRules(shift)


def _squareness_slopes(chain: Chain, error: sp.Matrix) -> dict:
    """Apparent squareness from the slopes of straightness reference lines, all component
    errors frozen at their values at the measuring position (Xo, Yo, Zo)."""
    layout = chain.layout
    idx = {"X": 0, "Y": 1, "Z": 2}
    pos = {t: position_symbol(t) for t in "XYZ"}
    out = {}
    for name in layout.squareness:
        about, b, a = SQUARENESS[name]
        ia, ib = idx[a], idx[b]
        slope = _diff_sum(error[ia], pos[b]) + _diff_sum(error[ib], pos[a])
        # the angle between lines a and b: 90 deg - slope; convert to the named rotation
        sign = {"EC0Y": -1, "EB0Z": 1, "EA0Z": -1}[name]
        apparent = sign * slope
        apparent = apparent.xreplace({position_symbol(t): OFFSETS[i]
                                      for i, t in enumerate("XYZ") if t in layout.axes})
        apparent = apparent.xreplace({p: sp.S.Zero for p in PROBE})
        out[name] = sp.expand(apparent)
    return out


def _diff_sum(expr, x) -> sp.Expr:
    """``diff(expr, x)`` of a sum, term by term: a term that holds ``x`` only as a factor
    ``x**n`` (n a positive integer) gives ``n x**(n-1)`` times the other factors, a term
    without ``x`` nothing, any other term its sympy derivative.  The same sum as ``diff``
    (mathematically; the callers expand it), without sympy's general derivative machinery on
    every term."""
    out = []
    for term in sp.Add.make_args(expr):
        if x not in term.free_symbols:
            continue
        factors = sp.Mul.make_args(term)
        hits = [j for j, f in enumerate(factors) if f.has(x)]
        f = factors[hits[0]]
        n = 1 if f == x else (f.exp if f.is_Pow and f.base == x and f.exp.is_Integer
                              and f.exp > 0 else None)
        if len(hits) != 1 or n is None:
            out.append(sp.diff(term, x))
            continue
        j = hits[0]
        out.append(sp.Mul(n, x ** (n - 1), *factors[:j], *factors[j + 1:]))
    return sp.Add(*out)
