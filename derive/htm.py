"""Primitives of small-angle homogeneous transforms (sympy): symbols, HTMs, error twists.

Conventions: 4x4 HTMs act on column vectors, positions in mm, angles in rad; a twist ``D`` is
the first-order part of a small rigid motion, whose HTM is ``I + D`` (Pahk eq. 2).  The
chains built from these live in :mod:`volerr.derive.kinematics`.
"""

from __future__ import annotations

from dataclasses import dataclass

import sympy as sp

PROBE = sp.symbols("Xp Yp Zp", real=True)


def position_symbol(axis: str) -> sp.Symbol:
    """The symbol of an axis position (mm for linear axes, rad for rotary axes)."""
    return sp.Symbol(axis, real=True)


def parameter_symbol(name: str) -> sp.Symbol:
    """The symbol of an error parameter, named as in ISO 230-1 (``EXX``, ``EC0Y`` ...)."""
    return sp.Symbol(name, real=True)


def twist(ex=0, ey=0, ez=0, dx=0, dy=0, dz=0) -> sp.Matrix:
    """The first-order error twist D (the HTM of a small motion is I + D)."""
    return sp.Matrix([[0, -ez, ey, dx], [ez, 0, -ex, dy], [-ey, ex, 0, dz], [0, 0, 0, 0]])


def translation(v) -> sp.Matrix:
    """HTM of a pure translation by the 3-vector ``v``."""
    m = sp.eye(4)
    m[0:3, 3] = sp.Matrix(v)
    return m


def rotation(axis, angle) -> sp.Matrix:
    """HTM of a right-hand rotation by ``angle`` (rad) about the unit vector ``axis``."""
    k = sp.Matrix(axis)
    kx = sp.Matrix([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    r = sp.eye(3) + sp.sin(angle) * kx + (1 - sp.cos(angle)) * kx * kx
    m = sp.eye(4)
    m[0:3, 0:3] = r
    return m


def exact_error_htm(ex=0, ey=0, ez=0, dx=0, dy=0, dz=0) -> sp.Matrix:
    """The exact rigid motion that a twist approximates: Trans(d) Rz(ez) Ry(ey) Rx(ex)
    (sympy's matrix product, entry by entry: :func:`_matmul`)."""
    m = _matmul(translation((dx, dy, dz)), rotation((0, 0, 1), ez))
    return _matmul(_matmul(m, rotation((0, 1, 0), ey)), rotation((1, 0, 0), ex))


def _matmul(a: sp.Matrix, b: sp.Matrix) -> sp.Matrix:
    """``a * b`` built entry by entry as one Add of the non-zero products: the same
    expressions as sympy's product (tested), without its general-domain machinery."""
    n, m, p = a.rows, a.cols, b.cols
    zero = sp.S.Zero
    out = []
    for i in range(n):
        row = [a[i, k] for k in range(m)]
        for j in range(p):
            terms = [x * b[k, j] for k, x in enumerate(row) if x != 0 and b[k, j] != 0]
            out.append(sp.Add(*terms) if terms else zero)
    return sp.Matrix(n, p, out)


@dataclass
class Factor:
    """One factor of the chain: ``nominal`` HTM, or an error twist ``twist_args``."""

    nominal: sp.Matrix | None = None
    twist_args: dict | None = None
    owner: str = ""          # axis or frame the factor belongs to
    role: str = ""           # "motion", "component", "squareness", "location", "fixed"
    #: nominal factors: nominal symbol (``axis.X``, ``param.d``, ``frame.F.x`` ...) -> the
    #: twist ``F^-1 dF/ds`` of a unit change of that symbol (mm or rad), as twist arguments
    #: (:mod:`volerr.derive.symbols`); error factors: None
    variation: dict | None = None

    @property
    def is_error(self) -> bool:
        return self.twist_args is not None

    def first_order(self) -> sp.Matrix:
        return twist(**self.twist_args)

    def exact(self) -> sp.Matrix:
        return exact_error_htm(**self.twist_args) if self.is_error else self.nominal
