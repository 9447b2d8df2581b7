"""Fused evaluation of generated functions: block kernels (numpy) and an optional numba backend.

The generated functions (``volerr.generated.<layout>.volumetric_error`` ...) are straight-line
numpy arithmetic: ``_t = ...`` temporaries, then outputs ``_o = numpy.broadcast_to(expr,
_shape)`` returned as a tuple.  Called on N points they pay, per call, the broadcast-shape
bookkeeping and one temporary (N,) array per operation, and the caller stacks the outputs into
an (N, 3) array.  This module rewrites such a function, from its own source (no kinematics is
written here), into

* a **numpy block kernel** ``kernel(_out, _s, **inputs)`` in three-address form: every
  operation on arrays is one ufunc call whose result goes into a row of the preallocated
  scratch ``_s`` (reused once a value is dead) or straight into a column of the block
  ``_out`` (m, n_out) of the result -- no ``_shape``, no ``broadcast_to``, no allocation, no
  stacking.  Arguments known to be scalar 0 are folded away (``x * 0`` -> 0, ``x + 0`` -> x),
  so unused error parameters cost nothing, and negations are absorbed where that is exact
  (``(-a)*c + b`` -> ``b - a*c``); the sines and cosines of arguments (the rotary axes) can be
  given as inputs, computed once for several functions at the same positions
  (:meth:`volerr.machine.model.Model.prepared`): the values are bitwise those of the
  generated function;
* a **point kernel** for one point (:func:`point_kernel`; a compensation chunk of one line):
  the same three-address code with the additions, subtractions, multiplications and
  negations written as Python float arithmetic on the values and the other functions (sin,
  cos, sqrt ...) still the ufuncs on one-element arrays -- the same bits without the ~1 us
  ufunc call of every operation;
* a **numba kernel** (optional, ``pip install 'volerr[fast]'``): one compiled per-point loop
  over 2-D broadcast inputs writing an (S, P, n_out) array, the whole expression fused in
  registers.  Compilation costs 1-4 s per function the first time, so it is opt-in
  (``backend="numba"`` of the Monte Carlo), never on a default path; the compiled code is cached
  on disk next to the kernel source in ``<volerr cache dir>/fused`` (outside the package).  It
  pays on Monte Carlo blocks (S machines x P points, inputs broadcast from (S, P), (S, 1) and
  (P,)); on 10^7 points held in 27 separate arrays its 27 simultaneous memory streams make it
  slower than the blocked numpy kernel (``benchmarks/bench_volumetric.py``).

A function whose source does not have the straight-line form is not fused (:func:`parse`
returns None) and the callers evaluate the generated function as it is.
"""

from __future__ import annotations

import ast
import functools
import hashlib
import importlib.util
import inspect
import sys
import textwrap
import warnings
from dataclasses import dataclass

import numpy as np

BACKENDS = ("numpy", "numba")

#: numpy functions a fusable expression may call (all elementwise, all supported by numba)
_CALLS = frozenset({"sin", "cos", "tan", "sqrt", "arcsin", "arccos", "arctan", "arctan2",
                    "exp", "log", "abs", "absolute", "sinh", "cosh", "tanh", "hypot"})


class FallbackWarning(UserWarning):
    """The numba backend was asked for but is not available: numpy is used instead."""


@dataclass(frozen=True)
class Parsed:
    """A generated function in straight-line form: argument names, temporaries
    ``(name, expression)`` in order, and the output expressions."""

    name: str
    args: tuple
    temps: tuple
    outputs: tuple


def _is_numpy_call(node, names=None) -> bool:
    return (isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute)
            and isinstance(node.func.value, ast.Name) and node.func.value.id == "numpy"
            and (names is None or node.func.attr in names))


def _valid(expr, known: set) -> bool:
    """Only numbers, known names, arithmetic and the elementwise numpy calls of _CALLS."""
    for node in ast.walk(expr):
        if isinstance(node, ast.Call):
            if not _is_numpy_call(node, _CALLS) or node.keywords:
                return False
        elif isinstance(node, ast.Attribute):
            if not (isinstance(node.value, ast.Name) and node.value.id == "numpy"):
                return False
        elif isinstance(node, ast.Name):
            if node.id not in known and node.id != "numpy":
                return False
        elif isinstance(node, ast.Constant):
            if not isinstance(node.value, (int, float)):
                return False
        elif not isinstance(node, (ast.BinOp, ast.UnaryOp, ast.operator, ast.unaryop,
                                   ast.expr_context)):
            return False
    return True


@functools.lru_cache(maxsize=None)
def parse(fn) -> Parsed | None:
    """The straight-line form of generated function ``fn``, or None if it has another form."""
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(fn)))
    except (OSError, TypeError, SyntaxError):
        return None
    if len(tree.body) != 1 or not isinstance(tree.body[0], ast.FunctionDef):
        return None
    f = tree.body[0]
    a = f.args
    if a.vararg or a.kwarg or a.kwonlyargs or a.posonlyargs or a.defaults:
        return None
    args = tuple(x.arg for x in a.args)
    # numeric module constants (a layout's fixed lengths such as ``h = 150.0``) are inlined
    consts = {k: float(v) for k, v in getattr(fn, "__globals__", {}).items()
              if isinstance(v, (int, float)) and not isinstance(v, bool) and k not in args}
    known, temps, returned = set(args), [], None
    for i, st in enumerate(f.body):
        if i == 0 and isinstance(st, ast.Expr) and isinstance(st.value, ast.Constant):
            continue  # docstring
        if isinstance(st, ast.Return):
            if not (isinstance(st.value, ast.Tuple)
                    and all(isinstance(e, ast.Name) for e in st.value.elts)):
                return None
            returned = [e.id for e in st.value.elts]
            if i != len(f.body) - 1:
                return None
            continue
        if not (isinstance(st, ast.Assign) and len(st.targets) == 1
                and isinstance(st.targets[0], ast.Name)):
            return None
        name, value = st.targets[0].id, st.value
        if name == "_shape":
            continue
        if _is_numpy_call(value, {"broadcast_to"}):
            if len(value.args) != 2 or not (isinstance(value.args[1], ast.Name)
                                            and value.args[1].id == "_shape"):
                return None
            value = value.args[0]
        value = _Inline(consts, known).visit(value)
        if name in args or not _valid(value, known):
            return None
        known.add(name)
        temps.append((name, value))
    if not returned:
        return None
    defined = dict(temps)
    if any(r not in defined for r in returned):
        return None
    outputs = tuple(defined[r] for r in returned)
    out_names = set(returned)
    temps = tuple((k, v) for k, v in temps if k not in out_names)
    if any(isinstance(n, ast.Name) and n.id in out_names
           for _, v in temps for n in ast.walk(v)) or any(
            isinstance(n, ast.Name) and n.id in out_names for v in outputs for n in ast.walk(v)):
        return None  # an output used as an input of another expression: keep it simple
    return Parsed(f.name, args, temps, outputs)


class _Inline(ast.NodeTransformer):
    """Module constants -> their values (names bound locally or as arguments stay names)."""

    def __init__(self, consts: dict, local: set):
        self.consts, self.local = consts, local

    def visit_Name(self, node):
        if node.id not in self.local and node.id in self.consts:
            return ast.copy_location(ast.Constant(self.consts[node.id]), node)
        return node


# ---- zero folding ---------------------------------------------------------------------------
def _is_const(node, value=None) -> bool:
    return (isinstance(node, ast.Constant) and isinstance(node.value, (int, float))
            and (value is None or node.value == value))


def _is_neg(node) -> bool:
    return isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub)


def _negated(node):
    """``x`` if ``node`` is ``-x``, ``(-a)*b`` or ``a*(-b)`` (x = a*b), else None."""
    if _is_neg(node):
        return node.operand
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Mult):
        if _is_neg(node.left):
            return ast.BinOp(node.left.operand, ast.Mult(), node.right)
        if _is_neg(node.right):
            return ast.BinOp(node.left, ast.Mult(), node.right.operand)
    return None


class _Fold(ast.NodeTransformer):
    """Replace names known to be 0 by 0 and fold ``x*0``, ``x+0``, ``0-x``, ``-0``, ``0**k``."""

    def __init__(self, zeros: set):
        self.zeros = zeros

    def visit_Name(self, node):
        return ast.Constant(0.0) if node.id in self.zeros else node

    def visit_UnaryOp(self, node):
        self.generic_visit(node)
        if isinstance(node.op, ast.USub) and _is_const(node.operand, 0):
            return ast.Constant(0.0)
        return node

    def visit_BinOp(self, node):
        self.generic_visit(node)
        left, right, op = node.left, node.right, node.op
        zl, zr = _is_const(left, 0), _is_const(right, 0)
        if isinstance(op, ast.Mult) and (zl or zr):
            return ast.Constant(0.0)
        if isinstance(op, ast.Add):
            if zl:
                return right
            if zr:
                return left
            # exact rewrites that save a negation pass (IEEE: -(a*b) == (-a)*b, a+b == b+a):
            # -a + b -> b - a, (-a)*c + b -> b - a*c, a + -b -> a - b
            if _negated(left) is not None:
                return ast.BinOp(right, ast.Sub(), _negated(left))
            if _negated(right) is not None:
                return ast.BinOp(left, ast.Sub(), _negated(right))
        if isinstance(op, ast.Sub) and _negated(right) is not None:
            return ast.BinOp(left, ast.Add(), _negated(right))  # a - -b -> a + b
        if isinstance(op, ast.Sub):
            if zr:
                return left
            if zl:
                return ast.UnaryOp(ast.USub(), right)
        if isinstance(op, ast.Pow) and zl and _is_const(right) and right.value > 0:
            return ast.Constant(0.0)
        return node


class _Given(ast.NodeTransformer):
    """``numpy.sin(a)`` / ``numpy.cos(a)`` of an argument ``a`` in ``names`` -> the input
    ``_sin_a`` / ``_cos_a`` (:func:`trig_name`): computed once by the caller for several
    functions at the same positions."""

    def __init__(self, names):
        self.names = names

    def visit_Call(self, node):
        self.generic_visit(node)
        if (_is_numpy_call(node, {"sin", "cos"}) and len(node.args) == 1 and not node.keywords
                and isinstance(node.args[0], ast.Name) and node.args[0].id in self.names):
            return ast.copy_location(ast.Name(trig_name(node.func.attr, node.args[0].id),
                                              ast.Load()), node)
        return node


def trig_name(func: str, arg: str) -> str:
    """The kernel input that holds ``numpy.<func>(<arg>)`` (``func`` "sin" or "cos")."""
    return f"_{func}_{arg}"


def _fold(parsed: Parsed, zeros: frozenset, trig=frozenset()):
    """Temporaries and outputs with ``zeros`` folded away and the sines and cosines of the
    arguments ``trig`` taken as inputs; dead temporaries dropped."""
    zeros = set(zeros)
    given = _Given(trig)
    temps = []
    for name, value in parsed.temps:
        value = _Fold(zeros).visit(given.visit(_copy(value)))
        if _is_const(value, 0):
            zeros.add(name)
        else:
            temps.append((name, value))
    outputs = [_Fold(zeros).visit(given.visit(_copy(v))) for v in parsed.outputs]
    used = {n.id for v in outputs for n in ast.walk(v) if isinstance(n, ast.Name)}
    live = []
    for name, value in reversed(temps):
        if name in used:
            live.append((name, value))
            used |= {n.id for n in ast.walk(value) if isinstance(n, ast.Name)}
    return live[::-1], outputs


def _copy(node):
    # through the source text: copy.deepcopy recurses once per nesting level and exceeds
    # Python's recursion limit on the deep expressions of five-axis exact_error
    return ast.parse(ast.unparse(node), mode="eval").body


# ---- numpy block kernel ---------------------------------------------------------------------
_UFUNC = {ast.Add: "add", ast.Sub: "subtract", ast.Mult: "multiply", ast.Div: "true_divide",
          ast.Pow: "power"}
#: ufuncs a one-point kernel writes as Python float arithmetic: one IEEE double operation each,
#: as the ufunc's loop does it (no division: Python raises where numpy gives inf)
_POINT_OPS = {"add": "{0} + {1}", "subtract": "{0} - {1}", "multiply": "{0} * {1}",
              "square": "{0} * {0}", "negative": "-{0}"}


class _Emitter:
    """Three-address code of the folded expressions: every operation on arrays is one ufunc call
    with ``out=`` a row of the scratch array ``_s`` (or the output column), so a block
    allocates nothing; operations on scalars only stay scalar expressions."""

    def __init__(self, arrays: set, point: bool = False):
        self.arrays = set(arrays)       # names bound to arrays
        #: the one-point form (:func:`point_kernel`); False when an operation has none
        self.point = self.point_ok = point
        self.lines: list[str] = []
        self.free: list[int] = []
        self.n_buf = 0
        self.owned: dict = {}           # named temporary -> its buffer

    def is_array(self, node) -> bool:
        return any(isinstance(n, ast.Name) and n.id in self.arrays for n in ast.walk(node))

    def buffer(self) -> int:
        if self.free:
            return self.free.pop()
        self.n_buf += 1
        return self.n_buf - 1

    def emit(self, node, target: str | None = None):
        """Emit code for array-valued ``node``; returns (operand text, buffer index or None)."""
        if not self.is_array(node):
            return f"({ast.unparse(node)})", None
        if isinstance(node, ast.Name):
            return node.id, None
        if isinstance(node, ast.BinOp) and type(node.op) in _UFUNC:
            if isinstance(node.op, ast.Pow) and _is_const(node.right, 2):
                return self._op("square", [node.left], target)
            return self._op(_UFUNC[type(node.op)], [node.left, node.right], target)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub):
            return self._op("negative", [node.operand], target)
        if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.UAdd):
            return self.emit(node.operand, target)
        if _is_numpy_call(node, _CALLS):
            return self._op(node.func.attr, node.args, target)
        raise ValueError(f"cannot emit {ast.unparse(node)}")

    def _op(self, ufunc: str, operands, target):
        texts, bufs = zip(*(self.emit(o) for o in operands))
        for b in bufs:
            if b is not None:
                self.free.append(b)
        buf = None
        if target is None:
            buf = self.buffer()
            target = f"_b{buf}"
        if self.point:
            self.lines.append(f"{target} = {self._point_op(ufunc, operands, texts)}")
        else:   # out as the last positional argument: cheaper to parse than the keyword
            self.lines.append(f"numpy.{ufunc}({', '.join(texts)}, {target})")
        return target, buf

    def _point_op(self, ufunc: str, operands, texts) -> str:
        """The operation of one point on the values (floats) of the array operands: Python
        arithmetic (:data:`_POINT_OPS`), or the ufunc called on one-element arrays made of
        them, as the numpy kernel calls it on (1,) arrays (scalar operands stay scalars)."""
        if ufunc in _POINT_OPS:
            return _POINT_OPS[ufunc].format(*texts)
        if ufunc not in _CALLS:
            self.point_ok = False
            return "None"
        args = [f"_one({t})" if self.is_array(o) else t for o, t in zip(operands, texts)]
        return f"numpy.{ufunc}({', '.join(args)}).item()"


def numpy_source(parsed: Parsed, zeros=frozenset(), scalars=frozenset(),
                 trig=frozenset(), point: bool = False) -> tuple[str | None, int]:
    """Source of the numpy block kernel ``kernel(_out, _s, <args>)`` and its number of scratch
    rows: ``_out`` (m, n_out) the block of the result, ``_s`` (n_scratch, m) scratch space;
    ``zeros`` arguments known to be scalar 0 (folded away), ``scalars`` other scalar arguments
    (all others are (m,) or (1,) arrays); ``trig`` array arguments whose sine and cosine are
    given as the further arguments ``_sin_<a>``, ``_cos_<a>`` (in sorted order of ``a``).

    ``point``: the one-point kernel ``kernel(_out, <args>)`` instead (:func:`point_kernel`;
    no scratch; the source None when an operation has no one-point form)."""
    temps, outputs = _fold(parsed, frozenset(zeros), frozenset(trig))
    given = [trig_name(f, a) for a in sorted(trig) for f in ("sin", "cos")]
    em = _Emitter(set(parsed.args) - set(zeros) - set(scalars) | set(given), point)
    last_use = {}
    for i, (_, value) in enumerate(temps + [(None, v) for v in outputs]):
        for node in ast.walk(value):
            if isinstance(node, ast.Name):
                last_use[node.id] = i
    for i, (name, value) in enumerate(temps):
        if not em.is_array(value):
            em.lines.append(f"{name} = {ast.unparse(value)}")
        elif isinstance(value, ast.Name):
            em.lines.append(f"{name} = {value.id}")
            em.arrays.add(name)
            if value.id in em.owned:  # an alias keeps the buffer it names alive
                last_use[value.id] = max(last_use.get(value.id, -1), last_use.get(name, -1))
        else:
            text, buf = em.emit(value)
            em.lines.append(f"{name} = {text}")
            em.arrays.add(name)
            em.owned[name] = buf
        _release(em, last_use, i)
    for k, value in enumerate(outputs):
        col = f"_out[:, {k}]"
        if em.is_array(value) and not isinstance(value, ast.Name):
            em.emit(value, target=col)
        else:
            em.lines.append(f"{col} = {ast.unparse(value)}")
        _release(em, last_use, len(temps) + k)
    if point:
        head = [f"def kernel(_out, {', '.join(parsed.args + tuple(given))}):"]
        return ("\n".join(head + ["    " + ln for ln in em.lines]) + "\n"
                if em.point_ok else None), 0
    head = [f"def kernel(_out, _s, {', '.join(parsed.args + tuple(given))}):"]
    if em.n_buf:
        head.append(f"    {''.join(f'_b{j}, ' for j in range(em.n_buf))}= _s")
    return "\n".join(head + ["    " + ln for ln in em.lines]) + "\n", em.n_buf


def _release(em: _Emitter, last_use: dict, i: int) -> None:
    """Return the buffers of named temporaries whose last use was statement ``i``."""
    for name in [t for t, b in em.owned.items() if last_use.get(t, -1) <= i]:
        buf = em.owned.pop(name)
        if buf is not None:
            em.free.append(buf)


@functools.lru_cache(maxsize=256)
def numpy_kernel(fn, zeros=frozenset(), scalars=frozenset(), trig=frozenset()):
    """``(kernel, n_scratch)``: the numpy block kernel of generated function ``fn`` (see
    :func:`numpy_source`), or None if ``fn`` is not in straight-line form."""
    parsed = parse(fn)
    if parsed is None:
        return None
    src, n_scratch = numpy_source(parsed, zeros, scalars, trig)
    ns = {"numpy": np}
    exec(compile(src, f"<fused {parsed.name}>", "exec"), ns)
    return ns["kernel"], n_scratch


@functools.lru_cache(maxsize=256)
def point_kernel(fn, zeros=frozenset(), scalars=frozenset(), trig=frozenset()):
    """The kernel of :func:`numpy_kernel` for one point: ``kernel(_out, **inputs)`` with
    ``_out`` (1, n_out) and every (1,) array input given as its value (a float).  The same
    operations on the same operands in the same order, so the same bits: additions,
    subtractions, multiplications and negations are single IEEE double operations in Python
    as in the ufunc loops, and the other elementwise functions (sin, cos, sqrt ...) are the
    ufuncs called on one-element arrays as in the numpy kernel.  What it saves is the ufunc
    call of every operation (about 1 us each, some 750 for a five-axis ``exact_error``),
    the per-chunk cost of a program compensated one line at a time.  None when ``fn`` is not
    in straight-line form or divides (Python raises on a zero where numpy gives inf)."""
    parsed = parse(fn)
    if parsed is None:
        return None
    src, _ = numpy_source(parsed, zeros, scalars, trig, point=True)
    if src is None:
        return None
    ns = {"numpy": np, "_one": lambda v: np.array((v,))}
    exec(compile(src, f"<point {parsed.name}>", "exec"), ns)
    return ns["kernel"]


def n_outputs(fn) -> int | None:
    parsed = parse(fn)
    return None if parsed is None else len(parsed.outputs)


# ---- numba backend --------------------------------------------------------------------------
def numba_available() -> bool:
    return importlib.util.find_spec("numba") is not None


def resolve_backend(backend: str | None) -> str:
    """``backend`` checked (``"numpy"`` or ``"numba"``); ``"numba"`` without numba installed
    falls back to ``"numpy"`` with one :class:`FallbackWarning`."""
    from ..errors import require

    backend = backend or "numpy"
    require(backend in BACKENDS, f"unknown backend {backend!r} (one of {', '.join(BACKENDS)})")
    if backend == "numba" and not numba_available():
        warnings.warn("numba is not installed (pip install 'volerr[fast]'): using the numpy "
                      "backend", FallbackWarning, stacklevel=2)
        return "numpy"
    return backend


def numba_source(parsed: Parsed) -> str:
    """Source of the fused per-point loop ``kernel(_out, <args>)`` over (S, P) inputs."""
    lines = ["import numpy", "import numba", "",
             "", f"def kernel(_out, {', '.join('a_' + a for a in parsed.args)}):",
             "    for _i in range(_out.shape[0]):",
             "        for _j in range(_out.shape[1]):"]
    used = {n.id for _, v in parsed.temps for n in ast.walk(v) if isinstance(n, ast.Name)}
    used |= {n.id for v in parsed.outputs for n in ast.walk(v) if isinstance(n, ast.Name)}
    lines += [f"            {a} = a_{a}[_i, _j]" for a in parsed.args if a in used]
    lines += [f"            {name} = {ast.unparse(value)}" for name, value in parsed.temps]
    lines += [f"            _out[_i, _j, {k}] = {ast.unparse(v)}"
              for k, v in enumerate(parsed.outputs)]
    return "\n".join(lines) + "\n"


def _signature(n_args: int, n_out: int):
    from numba import types
    arr2 = types.Array(types.float64, 2, "A", readonly=True)  # also takes writable arrays
    return types.void(types.Array(types.float64, 3, "C"), *([arr2] * n_args))


@functools.lru_cache(maxsize=None)
def numba_kernel(fn):
    """The compiled fused kernel of generated function ``fn`` (None if not straight-line).

    The kernel source is written to ``<cache dir>/fused/<module>-<function>-<hash>.py`` and
    compiled with ``cache=True`` there, so a later process loads the machine code instead of
    compiling; if that folder is not writable it is compiled in memory (every process)."""
    import numba

    parsed = parse(fn)
    if parsed is None:
        return None
    src = numba_source(parsed)
    sig = _signature(len(parsed.args), len(parsed.outputs))
    key = hashlib.sha256((src + numba.__version__).encode()).hexdigest()[:16]
    mod_name = f"{getattr(fn, '__module__', 'fn').rsplit('.', 1)[-1]}-{parsed.name}-{key}"
    try:
        from .derivation import cache_dir
        folder = cache_dir() / "fused"
        folder.mkdir(parents=True, exist_ok=True)
        path = folder / f"{mod_name.replace('-', '_')}.py"
        if not path.exists() or path.read_text() != src:
            tmp = path.with_suffix(f".tmp{id(src)}")
            tmp.write_text(src)
            tmp.replace(path)
        spec = importlib.util.spec_from_file_location(f"volerr_fused_{path.stem}", path)
        module = importlib.util.module_from_spec(spec)
        sys.modules[spec.name] = module  # numba's cache re-imports the module by name
        spec.loader.exec_module(module)
        return numba.njit(sig, cache=True, boundscheck=False)(module.kernel)
    except OSError:
        ns: dict = {}
        exec(compile(src, f"<fused {parsed.name}>", "exec"), ns)
        return numba.njit(sig, cache=False, boundscheck=False)(ns["kernel"])


def evaluate_numba(fn, kwargs: dict) -> np.ndarray:
    """``fn(**kwargs)`` by the compiled kernel: inputs broadcast to one shape of at most 2
    dimensions; returns ``shape + (n_out,)`` float array.  Raises ValueError when ``fn`` cannot
    be fused (the caller then evaluates ``fn`` itself)."""
    kernel = numba_kernel(fn)
    if kernel is None:
        raise ValueError(f"{getattr(fn, '__name__', fn)} is not in straight-line form")
    parsed = parse(fn)
    values = [np.asarray(kwargs[a], dtype=float) for a in parsed.args]
    shape = np.broadcast_shapes(*(v.shape for v in values))
    if len(shape) > 2:
        raise ValueError(f"the numba backend evaluates at most 2-D inputs, got {shape}")
    shape2 = (1,) * (2 - len(shape)) + shape
    out = np.empty(shape2 + (len(parsed.outputs),))
    kernel(out, *(np.broadcast_to(v, shape2) for v in values))
    return out.reshape(shape + (len(parsed.outputs),))
