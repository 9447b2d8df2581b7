"""Generated code: wrapped lines mean what the one-line form meant; headers record the sympy
version and a hash over the derivation sources; the Units paragraphs fit the modules."""

import ast
import hashlib
from pathlib import Path

import pytest
import sympy as sp
from hypothesis import given, settings
from hypothesis import strategies as st

import volerr.generated
from volerr.derive.linewrap import wrap_statement

GENERATED = Path(volerr.generated.__file__).parent
REPO = Path(__file__).resolve().parents[2]

names = st.sampled_from(["x_P", "EXX", "_t12", "numpy.cos(A)", "(a + b)", "2.5e-07", "-y"])
ops = st.sampled_from([" + ", " - ", "*", "/", "**"])


@st.composite
def expressions(draw):
    terms = draw(st.lists(names, min_size=2, max_size=80))
    out = terms[0]
    for t in terms[1:]:
        out += draw(ops) + t
    if draw(st.booleans()):
        out = f"numpy.broadcast_to({out}, _shape)"
    return out


@settings(max_examples=150, deadline=None)
@given(expressions(), st.sampled_from(["", "    "]), st.sampled_from(["_t0 = ", "_out[1, 2] = "]))
def test_wrapped_statement_parses_to_the_same_tree(expr, indent, lhs):
    line = lhs + expr
    lines = wrap_statement(line, indent=indent, width=60)
    text = "\n".join(ln[len(indent):] if ln.startswith(indent) else ln for ln in lines)
    assert ast.dump(ast.parse(text)) == ast.dump(ast.parse(line))
    # every line fits unless a single token run is wider than the width
    assert all(len(ln) <= 60 for ln in lines) or len(lines) == 1 or \
        max(len(ln) for ln in lines) <= 60 + max(len(n) for n in expr.split())


def test_every_generated_line_fits_99_columns():
    for path in sorted(GENERATED.glob("*.py")):
        widths = [len(ln) for ln in path.read_text(encoding="utf-8").splitlines()]
        assert max(widths, default=0) <= 99, path.name


def _header_field(text: str, key: str) -> str:
    for line in text.splitlines():
        if line.startswith(key):
            return line[len(key):].strip()
    raise AssertionError(f"no {key!r} in header")


@pytest.mark.parametrize("module,sources", [
    ("probe.py", ["derive/probe.py"]),
    ("three_point.py", ["derive/htm.py", "derive/kinematics.py", "derive/three_point.py"]),
    ("mb1.py", ["runtime/machine/layout.py", "derive/htm.py", "derive/effects.py",
                "derive/kinematics.py", "derive/volumetric.py", "derive/inverse.py",
                "derive/symbols.py", "derive/generate.py"]),
])
def test_header_records_sympy_version_and_source_hash(module, sources):
    text = (GENERATED / module).read_text(encoding="utf-8")
    assert _header_field(text, "sympy") == sp.__version__
    h = hashlib.sha256()
    for name in sources + ["derive/codegen.py", "derive/linewrap.py", "derive/seal.py",
                           "derive/templates/model.py.j2"]:
        h.update(name.encode() + b"\0" + (REPO / name).read_bytes() + b"\0")
    assert _header_field(text, "derivation sha256") == h.hexdigest()


def test_units_paragraphs_fit_the_modules():
    probe = (GENERATED / "probe.py").read_text(encoding="utf-8").split('"""')[1]
    three = (GENERATED / "three_point.py").read_text(encoding="utf-8").split('"""')[1]
    model = (GENERATED / "mb1.py").read_text(encoding="utf-8").split('"""')[1]
    assert "probe tip" not in probe and "rad" in probe and "No lengths" in probe
    assert "probe tip" not in three and "mm^3" in three
    assert "probe tip / tool centre point" in model
