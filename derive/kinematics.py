"""Kinematic chains of small-angle homogeneous transforms (sympy).

Frames and direction of every matrix
------------------------------------
``tool2work`` is the 4x4 HTM that maps coordinates in the tool (probe) frame to the workpiece
frame.  It is the product, left to right, of *factors*

    tool2work = F_1 @ F_2 @ ... @ F_n

where the list is the workpiece chain reversed (each table stage written as the tool's motion
relative to the table, ISO 841) followed by the tool chain from the base to the probe.  A
factor is either *nominal* (a known HTM of positions and layout parameters) or an *error
factor* ``I + D`` whose 4x4 twist ``D`` is linear in error parameters::

    D = [[ 0,  -ez,  ey, dx],
         [ ez,  0,  -ex, dy],
         [-ey,  ex,  0,  dz],
         [ 0,   0,   0,  0 ]]

(Pahk eq. 2: the small-angle rotation ``T`` and the translation ``L``).  The exact model uses
``Trans(dx, dy, dz) @ Rz(ez) @ Ry(ey) @ Rx(ex)`` instead; the two differ at second order.

Stage conventions
-----------------
* linear axis ``A`` with direction ``u``: ``Trans(q u) @ (I + D_squareness) @ (I + D_A(q))``
  -- the angular error rotates what rides on the carriage, not its own travel.
* rotary axis ``R`` through point ``c``: ``Trans(c) @ (I + D_location) @ (I + D_R(q)) @
  Rot(u, q) @ Trans(-c)`` -- error motions in the non-rotating frame on the axis (ISO 230-7).
* fixed frame: ``Trans(t) @ Rot(axis, angle)``.
* a table (workpiece-side) stage is written as the tool's motion relative to the table, so its
  error parameters are tool-relative (ISO 230-1) and its rotation pivots about the tool-side
  reference point.  ``table_pivot="table_origin"`` instead pivots the table about its own moving
  origin, which adds own-travel lever arms (Pahk's appendix reading; used by the audit).
* a table rotary axis ``R``: ``Trans(c) @ Rot(u, q) @ (I + D_location) @ (I + D_R(q)) @
  Trans(-c)`` -- in ``tool2work`` the frame left of ``Rot`` turns with the table, so the error
  twists stand right of it, in the frame of the body that carries the table axis (which does
  not turn with it; ISO 230-7).  A constant location error then moves the tool relative to
  the workpiece by an amount that turns with the axis, as an offset axis line does.

Angles of rotary axes are in radians inside the derivation.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import sympy as sp

from volerr.machine.layout import SQUARENESS, Layout

from .effects import apply_effects
from .htm import (PROBE, Factor, _matmul, exact_error_htm, parameter_symbol,  # noqa: F401
                  position_symbol, rotation, translation, twist)


def _sympify_vec(v, params: dict) -> sp.Matrix:
    loc = {k: sp.Symbol(k, real=True) for k in params}
    return sp.Matrix([sp.nsimplify(c) if not isinstance(c, str) else sp.sympify(c, locals=loc)
                      for c in v])


def _rational_vec(v) -> sp.Matrix:
    """Direction cosines as exact numbers where they are simple (1, 0, sqrt(2)/2 ...)."""
    return sp.Matrix([sp.nsimplify(c, [sp.sqrt(2), sp.sqrt(3)], tolerance=1e-12) for c in v])


def _component_twist(axis: str) -> dict:
    return dict(dx=parameter_symbol(f"EX{axis}"), dy=parameter_symbol(f"EY{axis}"),
                dz=parameter_symbol(f"EZ{axis}"), ex=parameter_symbol(f"EA{axis}"),
                ey=parameter_symbol(f"EB{axis}"), ez=parameter_symbol(f"EC{axis}"))


def _squareness_twist(layout: Layout, axis: str, direction: sp.Matrix, q) -> dict | None:
    """Translation twist q * (omega x u) of the squareness rotations this axis carries."""
    omega = sp.zeros(3, 1)
    for name, carrier in layout.squareness.items():
        if carrier != axis:
            continue
        about, moving, _ = SQUARENESS[name]
        sign = 1 if carrier == moving else -1
        omega[about] += sign * parameter_symbol(name)
    if omega == sp.zeros(3, 1):
        return None
    shift = q * omega.cross(direction)
    return dict(dx=shift[0], dy=shift[1], dz=shift[2])


def _location_twist(axis) -> dict:
    args = {}
    for name in axis.location_errors:
        key = {"X": "dx", "Y": "dy", "Z": "dz", "A": "ex", "B": "ey", "C": "ez"}[name[1]]
        args[key] = parameter_symbol(name)
    return args


def _twist_args(d=None, e=None) -> dict:
    """Twist arguments of a translation ``d`` and a rotation ``e`` (3-vectors), zeros left out."""
    out = {}
    for keys, v in (("dx dy dz", d), ("ex ey ez", e)):
        if v is None:
            continue
        for k, c in zip(keys.split(), v):
            c = sp.expand(c)
            if c != 0:
                out[k] = c
    return out


def _parameter_variations(vec: sp.Matrix, params: dict, sign: int = 1) -> dict:
    """``param.<p>`` -> translation twist ``sign * d(vec)/dp`` for each layout parameter the
    vector holds (an axis point, a frame translation)."""
    out = {}
    for p in sorted(params):
        d = vec.diff(sp.Symbol(p, real=True))
        if any(c != 0 for c in d):
            out[f"param.{p}"] = _twist_args(d=sign * d)
    return out


def _frame_variations(entry: str, t: sp.Matrix, u: sp.Matrix, theta, params: dict) -> dict:
    """Variations of a fixed frame ``Trans(t) Rot(u, theta)``: ``F^-1 dF = [[R^T dR, R^T dt]]``
    with ``R^T dR = dtheta [u]x`` (the axis is fixed): a unit change of a translation
    component ``frame.F.x`` (mm, base side of the rotation) or of the angle ``frame.F.angle``
    (rad), and of each layout parameter in ``t`` or ``theta``."""
    Rt = rotation(u, theta)[0:3, 0:3].T
    out = {f"frame.{entry}.{k}": _twist_args(d=Rt[:, i]) for i, k in enumerate("xyz")}
    out[f"frame.{entry}.angle"] = _twist_args(e=u)
    for p in sorted(params):
        s = sp.Symbol(p, real=True)
        dt, dth = t.diff(s), sp.diff(theta, s)
        if any(c != 0 for c in dt) or dth != 0:
            out[f"param.{p}"] = _twist_args(d=Rt * dt, e=u * dth)
    return out


def stage_factors(layout: Layout, entry: str) -> list[Factor]:
    """The factors of one chain entry (axis or frame), in tool-side form.  Every nominal
    factor carries its ``variation``: the twist of a unit change of each nominal symbol it
    depends on (an axis position, a layout parameter, a frame's offset or angle)."""
    params = layout.parameters
    if entry in layout.frames:
        f = layout.frames[entry]
        angle = sp.sympify(f.angle_deg, locals={k: sp.Symbol(k, real=True) for k in params})
        t, u = _sympify_vec(f.translation, params), _rational_vec(f.rotation_axis)
        theta = sp.pi * sp.nsimplify(angle) / 180
        m = translation(t) * rotation(u, theta)
        return [Factor(nominal=m, owner=entry, role="fixed",
                       variation=_frame_variations(entry, t, u, theta, params))]
    axis = layout.axes[entry]
    q = position_symbol(entry)
    u = _rational_vec(axis.direction)
    if axis.kind == "linear":
        out = [Factor(nominal=translation(q * u), owner=entry, role="motion",
                      variation={f"axis.{entry}": _twist_args(d=u)})]
        sq = _squareness_twist(layout, entry, u, q)
        if sq:
            out.append(Factor(twist_args=sq, owner=entry, role="squareness"))
        out.append(Factor(twist_args=_component_twist(entry), owner=entry, role="component"))
        return out
    c = _sympify_vec(axis.point, params)
    out = [Factor(nominal=translation(c), owner=entry, role="fixed",
                  variation=_parameter_variations(c, params))]
    loc = _location_twist(axis)
    if loc:
        out.append(Factor(twist_args=loc, owner=entry, role="location"))
    out.append(Factor(twist_args=_component_twist(entry), owner=entry, role="component"))
    out.append(Factor(nominal=rotation(u, q), owner=entry, role="motion",
                      variation={f"axis.{entry}": _twist_args(e=u)}))
    out.append(Factor(nominal=translation(-c), owner=entry, role="fixed",
                      variation=_parameter_variations(c, params, -1)))
    return out


def _move_to_table_origin(factors: list[Factor]) -> list[Factor]:
    """Pahk's appendix reading: a table's error twist acts before its own travel."""
    motion = [f for f in factors if f.role == "motion"]
    errors = [f for f in factors if f.is_error]
    if len(motion) == 1 and all(f.role in ("motion", "component", "squareness") for f in factors):
        return errors + motion
    return factors


def _table_rotary(factors: list[Factor]) -> list[Factor]:
    """A table rotary stage: error twists right of the rotation (carrier frame, not turning)."""
    fixed_in, *rest = factors
    motion = [f for f in rest if f.role == "motion"]
    errors = [f for f in rest if f.is_error]
    fixed_out = [f for f in rest if f.role == "fixed"]
    return [fixed_in, *motion, *errors, *fixed_out]


def chain_factors(layout: Layout, table_pivot: str = "tool_point") -> list[Factor]:
    """All factors of ``tool2work``, workpiece side first (reversed), then the tool side."""
    out: list[Factor] = []
    for entry in reversed(layout.workpiece_chain):
        fs = stage_factors(layout, entry)
        if entry in layout.axes and layout.axes[entry].kind == "rotary":
            fs = _table_rotary(fs)
        if table_pivot == "table_origin" and entry in layout.axes:
            fs = _move_to_table_origin(fs)
        out.extend(fs)
    for entry in layout.tool_chain:
        out.extend(stage_factors(layout, entry))
    if layout.effects:  # declared effects (augmented models): see volerr.derive.effects
        out = apply_effects(layout, out)
    return out


def _radical(a) -> bool:
    """A numeric radical such as ``sqrt(2)`` or ``3**(1/3)`` (a generator of the rings below;
    other numeric powers are polynomial arithmetic on numbers)."""
    return a.is_Pow and a.base.is_Rational and a.exp.is_Rational and not a.exp.is_Integer


def _ring_atoms(expr) -> set | None:
    """Generators a polynomial ring needs for ``expr``: its free symbols, its sines and
    cosines (of expanded arguments) and its numeric radicals (``sqrt(2)``); ``None`` when it
    holds any other function (``expand`` could rewrite inside it)."""
    funcs = expr.atoms(sp.Function)
    if any(f.func not in (sp.sin, sp.cos) or f.args[0] != sp.expand(f.args[0]) for f in funcs):
        return None
    return (set(expr.free_symbols) | funcs | expr.atoms(sp.NumberSymbol)
            | {a for a in expr.atoms(sp.Pow) if _radical(a)})


def _not_polynomial():
    from sympy.polys.polyerrors import CoercionFailed

    return (ValueError, TypeError, CoercionFailed)


#: exceptions of :meth:`RingMatrices.convert` for an entry that is not a polynomial
NOT_POLYNOMIAL = _not_polynomial()


class RingMatrices:
    """Matrices of expressions as matrices of elements of one sparse polynomial ring over
    QQ (``sympy.polys.rings``): products are polynomial arithmetic, and ``as_expr`` of a
    ring element is the expanded expression (``sympy.expand`` of the same product: the
    expanded form of a polynomial in its generators is unique).  Generators: the symbols,
    function applications and numeric radicals of the given matrices; sines and cosines are
    generators, so no trigonometric identity is applied (as with ``expand``).  ``None`` from
    :meth:`build` when an entry is not a polynomial in such generators."""

    def __init__(self, ring):
        self.ring = ring

    @classmethod
    def build(cls, matrices):
        from sympy.polys.domains import QQ
        from sympy.polys.rings import PolyRing

        atoms = set()
        for m in matrices:
            for e in m:
                more = _ring_atoms(sp.sympify(e))
                if more is None:
                    return None
                atoms |= more
        gens = sorted(atoms, key=sp.default_sort_key)
        return cls(PolyRing(gens or [sp.Dummy("one")], QQ))

    def convert(self, m: sp.Matrix) -> list:
        """``m`` as a list of rows of ring elements (:data:`NOT_POLYNOMIAL` if an entry is
        not a polynomial in the generators)."""
        R = self.ring
        return [[R.from_expr(m[i, j]) if m[i, j] != 0 else R.zero for j in range(m.cols)]
                for i in range(m.rows)]

    def mul(self, a: list, b: list) -> list:
        R = self.ring
        n, k, p = len(a), len(b), len(b[0])
        out = []
        for i in range(n):
            row = a[i]
            out.append([sum((row[t] * b[t][j] for t in range(k) if row[t] and b[t][j]),
                            R.zero) for j in range(p)])
        return out

    @staticmethod
    def add(a: list, b: list) -> list:
        return [[x + y for x, y in zip(ra, rb)] for ra, rb in zip(a, b)]

    @staticmethod
    def as_expr(a: list) -> sp.Matrix:
        return sp.Matrix([[x.as_expr() for x in row] for row in a])


@dataclass
class Chain:
    """A layout's chain with its symbols; all derived quantities are computed from it."""

    layout: Layout
    factors: list[Factor]
    positions: tuple = field(default_factory=tuple)
    parameters: tuple = field(default_factory=tuple)
    _nominal: tuple | None = field(default=None, repr=False, compare=False)

    @classmethod
    def from_layout(cls, layout: Layout, table_pivot: str = "tool_point") -> "Chain":
        return cls(layout, chain_factors(layout, table_pivot),
                   tuple(position_symbol(a) for a in layout.axis_names),
                   tuple(parameter_symbol(p) for p in layout.parameter_names))

    def nominal_htm(self) -> sp.Matrix:
        """Nominal ``tool2work`` (error factors are identity); computed once per chain (the
        product of sympy's matrix product, entry by entry: :func:`_matmul`), a copy returned."""
        key = tuple(id(f.nominal) for f in self.factors if not f.is_error)
        if self._nominal is None or self._nominal[0] != key:
            m = sp.eye(4)
            for f in self.factors:
                if not f.is_error:
                    m = _matmul(m, f.nominal)
            self._nominal = (key, m)
        return self._nominal[1].copy()

    def exact_htm(self) -> sp.Matrix:
        """Actual ``tool2work`` with exact rotations (not linearised)."""
        m = sp.eye(4)
        for f in self.factors:
            m = _matmul(m, f.exact())
        return m
