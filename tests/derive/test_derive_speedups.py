"""The faster paths of the derivation give sympy's own results: the canonical order used by
cse (sympy.ordered with its default keys) and the entry-by-entry matrix product (sympy's
Matrix product), on the expressions of a real layout and on random expressions."""

import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

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
