"""Basis expressions of effect terms: parsed once, evaluated with numpy (no sympy, no eval).

An effect term of a layout (``[effects.NAME]``, see :mod:`volerr.machine.layout`) multiplies a new
parameter by a *basis expression* such as ``"X*(T_C - 20)"`` or ``"sin(2*pi*X/25.4)"``.  The
same text is turned into sympy by the derivation (:mod:`volerr.derive.effects`) and evaluated
here for the fitting loop, so both always agree.

Grammar: numbers, names, ``+ - * / **``, unary minus, parentheses and the functions
``sin cos exp sqrt abs``, ``ind(a, b)`` (1 where ``a == b``, else 0) and ``legendre(n, x)``
(the Legendre polynomial of integer degree ``n``), ``lag(C, tau_s)`` (the covariate column ``C``
through a first-order lag of time constant ``tau_s`` seconds over the time column ``t_s``;
``lag(C, tau_s, t_min)`` over another time column: :mod:`volerr.machine.lags`).  ``pi`` is the
constant.  Bounds: at most 400 characters and 200 terms, numbers finite and at most 1e9 in
magnitude, an exponent a number between -64 and 64 (``9**9**9**9`` is refused).  Every other name is a variable: an axis position (mm; rad for rotary axes, as in
the derivation) or a covariate column of the measured data (``T_C``, ``t_s``, ``dir_X`` ...).
"""

from __future__ import annotations

import ast
import functools

import numpy as np

from ..errors import InputError

FUNCTIONS = {"sin": np.sin, "cos": np.cos, "exp": np.exp, "sqrt": np.sqrt, "abs": np.abs,
             "ind": lambda a, b: (np.asarray(a) == np.asarray(b)).astype(float),
             "legendre": lambda n, x: np.polynomial.legendre.legval(x, [0.0] * int(n) + [1.0]),
             "lag": None}     # evaluated by _lag_value: it needs the whole time series
CONSTANTS = {"pi": np.pi}
#: bounds that keep parsing, the derivation and the evaluation finite and fast
MAX_CHARS, MAX_NODES, MAX_EXPONENT, MAX_CONSTANT = 400, 200, 64, 1e9
_BINOPS = {ast.Add: np.add, ast.Sub: np.subtract, ast.Mult: np.multiply,
           ast.Div: np.divide, ast.Pow: np.power}


@functools.lru_cache(maxsize=4096)
def parse(text: str) -> ast.Expression:
    """Parse and check a basis expression; raises :class:`InputError` when it is not allowed."""
    try:
        tree = ast.parse(str(text), mode="eval")
    except SyntaxError:
        raise InputError(f"basis expression {text!r} is not a valid expression") from None
    nodes = list(ast.walk(tree))        # walked once: counted here, checked below
    require_small = len(str(text)) <= MAX_CHARS and len(nodes) <= MAX_NODES
    if not require_small:
        raise InputError(f"basis expression {str(text)[:40]!r}...: longer than {MAX_CHARS} "
                         f"characters or {MAX_NODES} terms")
    for node in nodes:
        if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
            e = node.right
            if isinstance(e, ast.UnaryOp) and isinstance(e.op, (ast.USub, ast.UAdd)):
                e = e.operand
            if not (isinstance(e, ast.Constant) and isinstance(e.value, (int, float))
                    and not isinstance(e.value, bool) and abs(e.value) <= MAX_EXPONENT):
                raise InputError(f"basis expression {text!r}: an exponent must be a number "
                                 f"between -{MAX_EXPONENT} and {MAX_EXPONENT}")
        if isinstance(node, ast.Constant) and isinstance(node.value, (int, float)) \
                and not isinstance(node.value, bool):
            v = float(node.value)
            if not (v == v and abs(v) <= MAX_CONSTANT):
                raise InputError(f"basis expression {text!r}: number {node.value!r} is not "
                                 f"finite or larger than {MAX_CONSTANT:g}")
        ok = isinstance(node, (ast.Expression, ast.BinOp, ast.UnaryOp, ast.USub, ast.UAdd,
                               ast.Name, ast.Load, ast.Call, *_BINOPS))
        if isinstance(node, ast.Constant):
            ok = isinstance(node.value, (int, float)) and not isinstance(node.value, bool)
        if isinstance(node, ast.Call):
            ok = (isinstance(node.func, ast.Name) and node.func.id in FUNCTIONS
                  and not node.keywords)
        if not ok:
            raise InputError(f"basis expression {text!r}: {type(node).__name__} not allowed")
        if isinstance(node, ast.Call) and node.func.id == "lag":
            _check_lag(text, node)
    return tree


def _check_lag(text: str, node: ast.Call) -> None:
    """``lag(NAME, TAU_S[, TIME])``: a column, a positive number of seconds, a time column."""
    from .lags import TIME_COLUMNS

    a = node.args
    ok = (len(a) in (2, 3) and isinstance(a[0], ast.Name) and isinstance(a[1], ast.Constant)
          and float(a[1].value) > 0
          and (len(a) == 2 or (isinstance(a[2], ast.Name) and a[2].id in TIME_COLUMNS)))
    if not ok:
        raise InputError(f"basis expression {text!r}: write a lag as lag(COLUMN, TAU_S) or "
                         f"lag(COLUMN, TAU_S, TIME) with TAU_S > 0 seconds and TIME one of "
                         f"{' '.join(TIME_COLUMNS)}")


@functools.lru_cache(maxsize=4096)
def lag_calls(text: str) -> tuple:
    """The lags of a basis expression: ((key, column, tau_s, time column), ...) with ``key``
    the canonical text :func:`volerr.machine.lags.lag_key`."""
    from .lags import lag_key

    out = []
    for node in ast.walk(parse(text)):
        if isinstance(node, ast.Call) and node.func.id == "lag":
            col, tau = node.args[0].id, float(node.args[1].value)
            time = node.args[2].id if len(node.args) == 3 else "t_s"
            out.append((lag_key(col, tau, time), col, tau, time))
    return tuple(dict.fromkeys(out))


def variables(text: str) -> tuple[str, ...]:
    """The variable names of a basis expression (positions and covariates), sorted."""
    tree = parse(text)
    names = {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}
    names |= {call[3] for call in lag_calls(text)}      # a lag's time column, named or not
    return tuple(sorted(names - set(FUNCTIONS) - set(CONSTANTS)))


def evaluate(text: str, values: dict) -> np.ndarray:
    """Evaluate a basis expression with numpy; ``values`` maps every variable to an array.
    A lag is taken from ``values[key]`` when given there (the key of :func:`lag_calls`: the
    lag of the whole series, for a subset of its points), else computed from the values."""
    tree = parse(text)

    def ev(node):
        if isinstance(node, ast.Expression):
            return ev(node.body)
        if isinstance(node, ast.Constant):
            return float(node.value)
        if isinstance(node, ast.Name):
            if node.id in CONSTANTS:
                return CONSTANTS[node.id]
            if node.id not in values:
                raise InputError(f"basis expression {text!r} needs {node.id!r}")
            return np.asarray(values[node.id], dtype=float)
        if isinstance(node, ast.UnaryOp):
            v = ev(node.operand)
            return -v if isinstance(node.op, ast.USub) else v
        if isinstance(node, ast.BinOp):
            return _BINOPS[type(node.op)](ev(node.left), ev(node.right))
        if node.func.id == "lag":
            return _lag_value(text, node, values)
        return FUNCTIONS[node.func.id](*(ev(a) for a in node.args))

    return np.asarray(ev(tree), dtype=float)


def _lag_value(text: str, node: ast.Call, values: dict) -> np.ndarray:
    from .lags import lag_key, lag_of_columns

    col, tau = node.args[0].id, float(node.args[1].value)
    time = node.args[2].id if len(node.args) == 3 else "t_s"
    key = lag_key(col, tau, time)
    if key in values:
        return np.asarray(values[key], dtype=float)
    for name in (col, time):
        if name not in values:
            raise InputError(f"basis expression {text!r} needs {name!r}")
    return lag_of_columns(values, col, tau, time)


def number(value, values: dict, what: str = "expression") -> float:
    """A number given as a number or as an expression in ``values`` (e.g. a layout coordinate
    ``"d + 12.5"`` in the layout parameters, mm); one float.  Raises :class:`InputError`
    ``"cannot evaluate <what> '...'"`` when it is neither."""
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return float(value)
    try:
        out = evaluate(str(value), values)
    except InputError:
        raise InputError(f"cannot evaluate {what} {value!r}") from None
    if out.ndim != 0:
        raise InputError(f"cannot evaluate {what} {value!r}")
    return float(out)
