"""The faster paths of the derivation give sympy's own results: the canonical order used by
cse (sympy.ordered with its default keys), the entry-by-entry matrix product (sympy's Matrix
product), polynomial-ring products and reductions (expand, rem, cancel), one-pass collect,
term-wise derivatives, the printer (sympy's NumPyPrinter) and the line tokeniser (tokenize),
on the expressions of real layouts and on random expressions."""

import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st
from sympy.printing.numpy import NumPyPrinter

from volerr.derive import volumetric as vol
from volerr.derive.codegen import _counted_nodes, canonical_order
from volerr.derive.generate import read_layout
from volerr.derive.kinematics import Chain, _matmul

x, y, z, a = sp.symbols("x y z a", real=True)
atoms = st.sampled_from([x, y, z, a, sp.Integer(2), sp.Rational(1, 3), sp.Float(0.5),
                         sp.sin(a), sp.cos(x)])


@st.composite
def exprs(draw, depth=3):
    if depth == 0 or draw(st.booleans()):
        return draw(atoms)
    op = draw(st.sampled_from([sp.Add, sp.Mul, lambda u, v: u ** 2 + v]))
    return op(draw(exprs(depth - 1)), draw(exprs(depth - 1)))


def _nodes_of(e):
    out = [e]
    for arg in e.args:
        out.extend(_nodes_of(arg))
    return out


@settings(max_examples=150, deadline=None)
@given(st.lists(exprs(), min_size=0, max_size=7))
def test_canonical_order_is_sympy_ordered(seq):
    want = list(sp.ordered(seq))
    with _counted_nodes():
        assert list(canonical_order(seq)) == want


def test_canonical_order_on_a_layout_and_cse_text():
    chain = Chain.from_layout(read_layout("MB1"))
    e = list(vol.exact_error(chain))
    for node in {n for ex in e for n in _nodes_of(ex) if n.is_Add or n.is_Mul}:
        with _counted_nodes():
            got = list(canonical_order(node.args))
        assert got == list(sp.ordered(node.args))
    plain = sp.cse(e, symbols=sp.numbered_symbols("_t"), order="canonical")
    with _counted_nodes():
        fast = sp.cse(e, symbols=sp.numbered_symbols("_t"), order="canonical")
    assert sp.srepr(fast) == sp.srepr(plain)


@settings(max_examples=60, deadline=None)
@given(st.lists(exprs(2), min_size=9, max_size=9), st.lists(exprs(2), min_size=6, max_size=6),
       st.lists(st.booleans(), min_size=9, max_size=9))
def test_matmul_is_sympys_product(ea, eb, zero):
    A = sp.Matrix(3, 3, [0 if zz else v for v, zz in zip(ea, zero)])
    B = sp.Matrix(3, 2, eb)
    got, want = _matmul(A, B), A * B
    assert [sp.srepr(v) for v in got] == [sp.srepr(v) for v in want]


def test_exact_htm_is_the_sympy_product_of_the_factors():
    chain = Chain.from_layout(read_layout("DMU50"))
    m = sp.eye(4)
    for f in chain.factors:
        m = m * f.exact()
    # structural equality (same classes, same args in the same order), not mathematical
    assert all(u == v for u, v in zip(chain.exact_htm(), m))


# ---- the polynomial-ring and term-wise paths of the derivation (issue 14) -------------------
from volerr.derive import inverse as inv  # noqa: E402
from volerr.derive import probe as probe_derivation  # noqa: E402
from volerr.derive import three_point as tp  # noqa: E402
from volerr.derive.kinematics import RingMatrices  # noqa: E402

s2 = sp.sqrt(2)
poly_atoms = st.sampled_from([x, y, z, a, sp.sin(a), sp.cos(a), sp.sin(x), sp.cos(x), s2,
                              sp.Integer(2), sp.Integer(-3), sp.Rational(1, 2)])


@st.composite
def polys(draw, depth=3):
    """Polynomials in symbols, sines, cosines and sqrt(2), neither expanded nor canonical."""
    if depth == 0 or draw(st.booleans()):
        return draw(poly_atoms)
    op = draw(st.sampled_from([sp.Add, sp.Mul, lambda u, v: u ** 2 - v]))
    return op(draw(polys(depth - 1)), draw(polys(depth - 1)))


def _same(u, v):
    return sp.srepr(u) == sp.srepr(v)


@settings(max_examples=100, deadline=None)
@given(st.lists(polys(), min_size=1, max_size=5))
def test_collect_symbols_is_sympy_collect(terms):
    e = sp.expand(sp.Add(*terms))
    syms = [z, x, y]
    assert _same(vol.collect_symbols(e, syms), sp.collect(e, syms))


@settings(max_examples=60, deadline=None)
@given(polys(3))
def test_reduce_sin_cos_ring_equals_sympy_rem(e):
    got = inv._reduce_sin_cos(e, [a, x])
    assert _same(got, inv._reduce_sin_cos_sympy(e, [a, x]))
    # and it is the same function: equal at a point
    pt = {a: 0.3, x: -1.1, y: 0.7, z: 2.5}
    assert abs(complex(got.subs(pt)) - complex(e.subs(pt))) < 1e-9


@settings(max_examples=60, deadline=None)
@given(st.lists(polys(2), min_size=6, max_size=6), st.lists(polys(2), min_size=6, max_size=6))
def test_ring_matrix_product_is_expanded_sympy_product(ea, eb):
    A, B = sp.Matrix(2, 3, ea), sp.Matrix(3, 2, eb)
    ring = RingMatrices.build([A, B])
    got = ring.as_expr(ring.mul(ring.convert(A), ring.convert(B)))
    want = (A * B).applyfunc(sp.expand)
    assert all(_same(u, v) for u, v in zip(got, want))


@settings(max_examples=100, deadline=None)
@given(polys(3))
def test_is_expanded_only_when_expand_changes_nothing(e):
    if vol.is_expanded(e):
        assert _same(sp.expand(e), e)
    assert vol.is_expanded(sp.expand(e)) or sp.expand(e).has(sp.Pow(2, sp.Rational(-1, 2)))


@settings(max_examples=60, deadline=None)
@given(st.lists(polys(2), min_size=1, max_size=5))
def test_diff_sum_is_diff(terms):
    e = sp.expand(sp.Add(*terms))
    assert sp.expand(vol._diff_sum(e, x) - sp.diff(e, x)) == 0


def _augmented(layout, terms):
    import volerr
    from volerr.loop.run import augmented_layout_text
    from volerr.machine.layout import parse_layout

    class S:
        cand = type("C", (), {"name": "extra", "kind": "thermal", "info": {},
                              "terms": terms})()

    return parse_layout(augmented_layout_text(volerr.load(layout), [S]), f"{layout}_aug.toml")


def test_first_order_displacement_ring_path_equals_expression_path():
    """Shipped layouts (sqrt(2) directions of DMU50 included) and an augmented layout whose
    effect is polynomial take the ring path; one with a periodic effect sin(2 pi X / 50)
    (a function the ring path declines) takes the expression path: all equal sympy's."""
    lays = [read_layout("DMU50"), read_layout("TT_AC"),
            _augmented("MB1", [("KT_X", "EXX", "X*(T_C - 20)")]),
            _augmented("MB1", [("PS_X", "EXX", "sin(2*pi*X/50)")])]
    for lay in lays:
        chain = Chain.from_layout(lay)
        for v in (sp.Matrix([*vol.PROBE, 1]), sp.Matrix([0, 0, 1, 0])):
            got = vol._first_order_displacement(chain, v)
            want = vol._first_order_displacement_sympy(chain, v)
            assert all(_same(u, w) for u, w in zip(got, want)), lay.name


def test_setup_sensitivity_is_the_jacobian_of_the_twisted_chain():
    chain = Chain.from_layout(read_layout("TT_AC"))
    syms = sp.symbols("u0:6", real=True)
    d = vol.twist(**dict(zip(vol.SETUP_TWIST, syms)))
    T, p = chain.nominal_htm(), sp.Matrix([*vol.PROBE, 1])
    work = (d * (T * p))[0:3, 0].jacobian(sp.Matrix(syms))
    tool = (T * (d * p))[0:3, 0].jacobian(sp.Matrix(syms))
    want = work.row_join(tool).applyfunc(sp.expand)
    assert all(_same(u, w) for u, w in zip(vol.setup_sensitivity(chain), want))


def test_nominal_htm_is_the_sympy_product_and_a_fresh_copy():
    chain = Chain.from_layout(read_layout("HH_BC"))
    m = sp.eye(4)
    for f in chain.factors:
        if not f.is_error:
            m = m * f.nominal
    first = chain.nominal_htm()
    first[0, 0] = sp.Symbol("changed")
    assert all(_same(u, w) for u, w in zip(chain.nominal_htm(), m))


def test_three_point_quotients_are_sympy_cancel():
    A, b = tp.selected_system("z")
    det = tp._det(A)
    sol = tp.closed_form("z")
    for j, name in enumerate(tp.MOTIONS):
        Aj = sp.Matrix(A)
        Aj[:, j] = b
        assert _same(sol[name], sp.cancel(tp._det(Aj) / det))
    assert _same(sol["N"], sp.factor(det))


def test_probe_basis_equals_the_simplified_construction():
    """The eq. (11) basis reduced by sin^2 + cos^2 = 1 is what simplify gives (and is
    orthonormal)."""
    A_, B_ = probe_derivation.A, probe_derivation.B
    ez = probe_derivation.probe_axis()
    ey = sp.simplify(ez.cross(probe_derivation.E_Z) / sp.sin(A_))
    ex = sp.simplify(ey.cross(ez))
    got = probe_derivation.basis()
    for u, w in zip(got, (ex, ey, ez)):
        assert all(_same(p, q) for p, q in zip(u, w))
    m = sp.Matrix.hstack(*got)
    assert (m.T * m).applyfunc(lambda e: probe_derivation._pythagoras(e, (A_, B_))) == sp.eye(3)


def test_exact_error_htm_is_the_sympy_product():
    from volerr.derive.htm import exact_error_htm, rotation, translation

    e = sp.symbols("ea eb ec", real=True)
    d = sp.symbols("dx dy dz", real=True)
    want = (translation(d) * rotation((0, 0, 1), e[2]) * rotation((0, 1, 0), e[1])
            * rotation((1, 0, 0), e[0]))
    got = exact_error_htm(*e, *d)
    assert all(_same(u, w) for u, w in zip(got, want))


print_atoms = st.sampled_from([x, y, z, a, sp.sin(a), sp.cos(x), sp.sqrt(2), sp.Integer(2),
                               sp.Integer(-3), sp.Rational(1, 2), sp.Rational(-5, 3),
                               sp.Float(0.25), sp.Float(-1.5), sp.Symbol("_t3"), sp.pi,
                               sp.atan2(x, y)])


@st.composite
def print_exprs(draw, depth=3):
    if depth == 0 or draw(st.booleans()):
        return draw(print_atoms)
    op = draw(st.sampled_from([sp.Add, sp.Mul, lambda u, v: u / v, lambda u, v: u - v,
                               lambda u, v: u ** 2, lambda u, v: sp.sqrt(u * u + v * v),
                               lambda u, v: 1 / sp.sqrt(u), lambda u, v: u ** -3,
                               lambda u, v: sp.sin(u + v), lambda u, v: -u * v]))
    return op(draw(print_exprs(depth - 1)), draw(print_exprs(depth - 1)))


class _SympyPrinter(NumPyPrinter):
    """The reference: sympy's NumPy printer with the generator's settings and floats."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "inline": True,
                          "allow_unknown_functions": False})

    def _print_Float(self, expr):
        return repr(float(expr))


@settings(max_examples=300, deadline=None)
@given(print_exprs())
def test_printer_prints_what_sympys_printer_prints(e):
    from volerr.derive.codegen import print_expr

    try:
        want = _SympyPrinter().doprint(e)
    except Exception as exc:    # e.g. zoo from a division by zero: sympy cannot print it either
        with pytest.raises(type(exc)):
            print_expr(e)
        return
    assert print_expr(e) == want


code_tokens = st.sampled_from(["_t12", "numpy.sin", "x", "(", ")", "[", "]", ",", " ", "+",
                               "-", "*", "**", "/", "=", "1", "0.5", "1e-05", "2.5e+20",
                               "'EXX'", ":", "{", "}", "_out[0, 1]", ".", "3.", "05", "f",
                               "j", "_", "0x1f", "1_0", "e", "'a\\'b'", "\"q\"", "  "])


@settings(max_examples=300, deadline=None)
@given(st.lists(code_tokens, min_size=1, max_size=30))
def test_statement_tokens_are_pythons_tokens(parts):
    from volerr.derive import linewrap as lw

    code = "".join(parts).strip()
    try:
        want = lw._tokenize(code)
    except Exception:      # not a tokenizable line (unbalanced brackets ...): nothing to compare
        return
    assert lw._tokens(code) == want


@settings(max_examples=60, deadline=None)
@given(st.integers(-12, 12), st.integers(1, 12), st.sampled_from([1, 2, 3, 5, 6, 7, 8, 12]),
       st.sampled_from([sp.S.Half, sp.Rational(1, 3), sp.Rational(-1, 2)]))
def test_inverse_simplify_keeps_what_simplify_keeps(p, q, n, ex):
    e = sp.Rational(p, q) * sp.Integer(n) ** ex
    assert _same(inv._simplify(e), sp.simplify(e))
