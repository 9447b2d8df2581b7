"""Three-point (laser-tracker) identification of the six error motions of one axis.

Source: Ellingsdalen (2021), NTNU thesis, Appendix B sec. 3.1 (linear axes, eq. 27-37) and
ch. 3.2 (rotary axes, eq. 3.1-3.8), after Zhang & Hu (2011, 2013).

Model
-----
Points ``P, Q, K, ...`` are fixed on the moving component (spindle head for a linear axis,
table for a rotary axis).  At the reference position (the first commanded position of a round)
a point sits at ``r`` (mm) in the measurement frame.  At a later position the component has
moved nominally (translation along the axis, or rotation about the axis through the frame
origin) and, in addition, by its six error motions: the translation ``t = (EX, EY, EZ)`` of
the body point that coincided with the frame origin at the reference position, and the small
rotation ``e = (EA, EB, EC)`` about the frame axes.  To first order (small angles, the error
twist ``I + D`` of :func:`volerr.derive.kinematics.twist`) the deviation of a point from its
nominal position is::

    Delta = t + e x r_hat        r_hat = r (linear axis) or R_axis(theta) r (rotary axis)

which is thesis eq. 30 (linear) and eq. 3.4 (rotary, the lever arm in rotated coordinates
``x_hat = x cos C - y sin C``, ``y_hat = x sin C + y cos C``).  Every point gives three
equations, linear in the six unknowns: ``n`` points give the ``3n x 6`` system of eq. 31 /
eq. 3.5.  Zhang & Hu pick six of the nine rows (eq. 32, 36, 37, 3.6) and solve them in closed
form (eq. 33-34, 3.7-3.8 and the Appendix Z-axis solution); :func:`closed_form` does the same
symbolically, and :func:`generate_module` emits those solutions as numpy code
(``generated/three_point.py``).  The runtime (``volerr.identify.solve``) defaults to weighted least
squares over all ``3n`` rows and uses the closed forms as a cross-check.
"""

from __future__ import annotations

import functools
import hashlib
import inspect

import sympy as sp

from .codegen import Function, render_module
from .kinematics import rotation, translation, twist

#: the six error motions, in the order of the unknown vector (ISO 230-1 without the axis letter)
MOTIONS = ("EX", "EY", "EZ", "EA", "EB", "EC")
COORDS = ("x", "y", "z")

#: Zhang & Hu row selections from the 9 x 6 system of points P, Q, K (thesis eq. 32 for the
#: X axis and eq. 3.6 for the C axis, eq. 36 for Y, eq. 37 for Z): (point, coordinate) per row.
SELECTIONS = {
    "x": (("P", "x"), ("P", "y"), ("Q", "x"), ("Q", "z"), ("K", "y"), ("K", "z")),
    "y": (("P", "y"), ("P", "z"), ("Q", "y"), ("K", "x"), ("K", "z"), ("P", "x")),
    "z": (("P", "z"), ("Q", "x"), ("Q", "z"), ("K", "y"), ("P", "x"), ("P", "y")),
}
#: which selection the thesis uses for which axis
AXIS_SELECTION = {"X": "x", "Y": "y", "Z": "z", "C": "x"}


def motion_symbols() -> tuple[sp.Symbol, ...]:
    """The six unknowns ``EX EY EZ EA EB EC`` (mm, mm, mm, rad, rad, rad)."""
    return tuple(sp.Symbol(m, real=True) for m in MOTIONS)


def point_symbols(label: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
    """Lever arm of a point in the frame used by the equations: ``x_P, y_P, z_P`` (mm)."""
    return tuple(sp.Symbol(f"{c}_{label}", real=True) for c in COORDS)


def delta_symbols(label: str) -> tuple[sp.Symbol, sp.Symbol, sp.Symbol]:
    """Measured deviation of a point from its nominal position: ``d_xP, d_yP, d_zP`` (mm)."""
    return tuple(sp.Symbol(f"d_{c}{label}", real=True) for c in COORDS)


def point_displacement(r) -> sp.Matrix:
    """First-order deviation (3-vector) of a body point with lever arm ``r`` under the error
    motions: ``(I + D) r - r`` with the error twist ``D`` of the six motions."""
    ex, ey, ez, ea, eb, ec = motion_symbols()
    D = twist(ea, eb, ec, ex, ey, ez)
    rh = sp.Matrix([r[0], r[1], r[2], 1])
    return sp.expand((D * rh)[0:3, 0])


def rotated_lever_arm(r, axis=(0, 0, 1), angle=sp.Symbol("theta", real=True)) -> sp.Matrix:
    """Lever arm of a table point after the nominal rotation by ``angle`` about ``axis``
    through the frame origin (thesis eq. 3.2): ``R_axis(angle) r``."""
    return (rotation(axis, angle) * sp.Matrix([r[0], r[1], r[2], 1]))[0:3, 0]


def system(labels, rotary_axis=None, angle=sp.Symbol("theta", real=True)):
    """The ``3n x 6`` coefficient matrix of the identification equations.

    ``labels``: point labels; lever arms are :func:`point_symbols`.  With ``rotary_axis`` (a unit
    3-vector) the lever arms are first turned by ``angle`` (rotary axis, eq. 3.5); otherwise they
    are used as they are (linear axis, eq. 31).  Returns ``(A, rows)`` with ``rows`` the
    (label, coordinate) of every row."""
    unknowns = motion_symbols()
    blocks, rows = [], []
    for lab in labels:
        r = sp.Matrix(point_symbols(lab))
        if rotary_axis is not None:
            r = rotated_lever_arm(r, rotary_axis, angle)
        disp = point_displacement(r)
        blocks.append(disp.jacobian(unknowns))
        rows.extend((lab, c) for c in COORDS)
    return sp.Matrix.vstack(*blocks), rows


@functools.lru_cache(maxsize=1)
def _system_pqk():
    """:func:`system` of the points P, Q, K (shared by the three selections; immutable)."""
    A, rows = system(("P", "Q", "K"))
    return sp.ImmutableMatrix(A), tuple(rows)


def selected_system(selection: str):
    """The 6 x 6 system of one Zhang & Hu selection in the lever arms of P, Q, K:
    ``(A, b)`` with ``b`` the corresponding :func:`delta_symbols`."""
    A, rows = _system_pqk()
    index = [rows.index(row) for row in SELECTIONS[selection]]
    b = sp.Matrix([delta_symbols(lab)[COORDS.index(c)] for lab, c in SELECTIONS[selection]])
    return sp.Matrix(A.extract(index, list(range(6)))), b


def _det(m: sp.Matrix, domain=None):
    """Determinant of a polynomial matrix: computed in the polynomial ring (fraction-free
    elimination on ring elements, ~20x faster than Berkowitz on expressions).  Returns the
    ring element when ``domain`` (a polynomial ring domain holding the entries) is given,
    else the expanded expression (the same polynomial whatever the method)."""
    from sympy.polys.matrices import DomainMatrix

    if domain is not None:
        rows = [[domain.from_sympy(m[i, j]) for j in range(m.cols)] for i in range(m.rows)]
        return DomainMatrix(rows, m.shape, domain).det()
    dm = DomainMatrix.from_Matrix(m)
    return sp.expand(dm.domain.to_sympy(dm.det()))


def closed_form(selection: str) -> dict:
    """Closed-form solution of a selected 6 x 6 system.

    Returns ``{"EX": expr, ..., "EC": expr, "N": determinant}``: each motion as a function of
    the lever arms and the six selected deviations (Cramer's rule, factored).

    The determinants and the cancellation of their common factors are done on elements of
    one polynomial ring over ZZ, its generators in the order ``sympy.cancel`` gives them, so
    each quotient is ``sympy.cancel(numerator / determinant)`` without converting the
    polynomials to expressions and back."""
    from sympy.polys.domains import ZZ
    from sympy.polys.polyutils import _sort_gens
    from sympy.polys.rings import ring

    A, b = selected_system(selection)
    R, *_ = ring(_sort_gens(sorted(A.free_symbols | b.free_symbols, key=str)), ZZ)
    K = R.to_domain()
    det = _det(A, K)
    out = {}
    for j, name in enumerate(MOTIONS):
        Aj = sp.Matrix(A)
        Aj[:, j] = b
        # cancel the common polynomial factors of numerator and determinant
        num, den = _det(Aj, K).cancel(det)
        out[name] = num.as_expr() / den.as_expr()
    out["N"] = sp.factor(det.as_expr())
    return out


@functools.lru_cache(maxsize=None)
def closed_form_once(selection: str) -> dict:
    """:func:`closed_form` derived once per process and shared by its readers (the audits of
    the thesis' equations and of its scripts solve the same selections); the dict is shared:
    read it, never change it."""
    return closed_form(selection)


def _args(selection: str) -> list[str]:
    pts = [str(s) for lab in ("P", "Q", "K") for s in point_symbols(lab)]
    ds = [str(delta_symbols(lab)[COORDS.index(c)]) for lab, c in SELECTIONS[selection]]
    return pts + ds


def derive_functions() -> list[Function]:
    """Generated functions: one closed-form solver and one determinant per selection."""
    funcs = []
    for sel in sorted(SELECTIONS):
        sol = closed_form(sel)
        rows = ", ".join(f"{c}{lab}" for lab, c in SELECTIONS[sel])
        funcs.append(Function(
            f"solve_{sel}", _args(sel), [sol[m] for m in MOTIONS],
            f"Zhang & Hu closed form, selection {sel!r} (rows {rows}): the six error motions "
            f"(EX, EY, EZ mm; EA, EB, EC rad) as array (6, *shape) from the lever arms of P, Q, K "
            f"and the six selected deviations d (mm).", shape=(6,)))
        funcs.append(Function(
            f"det_{sel}", [str(s) for lab in ("P", "Q", "K") for s in point_symbols(lab)],
            [sol["N"]],
            f"Determinant of the selected 6 x 6 system {sel!r} (mm^3): zero means the "
            f"selection is singular for these points even if the full system is not.",
            output_names=["N"]))
    return funcs


# ---- numeric building blocks of the runtime identification ---------------------------------
LEVER = sp.symbols("x y z", real=True)
AXIS_DIR = sp.symbols("ux uy uz", real=True)
ANGLE = sp.Symbol("angle", real=True)


def design_block(r=LEVER) -> sp.Matrix:
    """3 x 6 coefficient block of one point: ``d Delta / d(EX, EY, EZ, EA, EB, EC)`` at the
    lever arm ``r`` (mm), i.e. ``[I, -[r]x]`` (thesis eq. 31; one block of :func:`system`)."""
    return point_displacement(sp.Matrix(r)).jacobian(motion_symbols())


def axis_rotation(axis=AXIS_DIR, angle=ANGLE) -> sp.Matrix:
    """3 x 3 right-hand rotation by ``angle`` (rad) about the unit vector ``axis`` (Rodrigues,
    the nominal motion of a rotary axis, thesis eq. 3.2)."""
    return rotation(axis, angle)[0:3, 0:3]


def moved_pivot(motions, p_from, p_to) -> sp.Matrix:
    """The six motions of a body given about the pivot ``p_from`` re-expressed about the pivot
    ``p_to`` (first order): the rotation stays, the translation becomes the displacement of the
    body point at ``p_to`` under ``Trans(p_from) (I + D) Trans(-p_from)``."""
    ex, ey, ez, ea, eb, ec = motions
    D = twist(ea, eb, ec, ex, ey, ez)
    T = translation(p_from) * (sp.eye(4) + D) * translation(-sp.Matrix(p_from))
    x = sp.Matrix([*p_to, 1])
    t_new = sp.expand((T * x - x)[0:3, 0])
    return sp.Matrix([*t_new, ea, eb, ec])


def relative_motion(motions) -> sp.Matrix:
    """First-order motions of the tool relative to a table that moves by ``motions`` (about the
    same pivot): ``(I + D)^-1 = I - D + O(D^2)``, i.e. all six negated."""
    ex, ey, ez, ea, eb, ec = motions
    D = twist(ea, eb, ec, ex, ey, ez)
    first = sp.eye(4) - D
    assert sp.expand((sp.eye(4) + D) * first - sp.eye(4) + D * D) == sp.zeros(4)
    return sp.Matrix([first[0, 3], first[1, 3], first[2, 3],
                      first[2, 1], first[0, 2], first[1, 0]])


def tool_side_signs(q0=sp.Symbol("q0", real=True), u=AXIS_DIR) -> sp.Matrix:
    """Tool-side linear axis measured from the reference position ``q0`` (mm): the tracker's
    pivot is the carriage point at the frame origin at ``q0``, which travels to ``(q - q0) u``;
    the model's is the one there at ``q = 0``, at ``q u``.  Result ``t + q0 (e x u)``, ``e``."""
    q = sp.Symbol("q", real=True)
    u = sp.Matrix(u)
    out = moved_pivot(motion_symbols(), (q - q0) * u, q * u)
    assert not out.has(q)
    return out


def table_side_signs(travel=sp.Symbol("travel", real=True), u=AXIS_DIR) -> sp.Matrix:
    """Table (workpiece-side) axis, ``travel = q - q0`` (mm; 0 for a rotary axis with the frame
    origin on it): the table's pivot, the table point at the origin at the reference position,
    is at ``-travel u`` (the table moves opposite to the tool's relative motion); the model
    gives the tool relative to the table about the tool point at the origin:
    ``-t - travel (e x u)``, ``-e``."""
    u = sp.Matrix(u)
    return relative_motion(moved_pivot(motion_symbols(), -travel * u, (0, 0, 0)))


def runtime_functions() -> list[Function]:
    """Generated numeric blocks of ``volerr.identify.solve`` (design, rotation, model signs)."""
    motions = [str(s) for s in motion_symbols()]
    udir = [str(s) for s in AXIS_DIR]
    return [
        Function("design_block", [str(s) for s in LEVER], list(design_block()),
                 "Coefficient block [I, -[r]x] of one point, array (3, 6, *shape): "
                 "Delta (mm) = block @ (EX, EY, EZ mm, EA, EB, EC rad); lever arm x, y, z mm "
                 "(thesis eq. 31).", shape=(3, 6)),
        Function("axis_rotation", udir + [str(ANGLE)], list(axis_rotation()),
                 "Right-hand rotation about the unit vector (ux, uy, uz) by angle (rad), "
                 "array (3, 3, *shape) (thesis eq. 3.2, Rodrigues).", shape=(3, 3)),
        Function("tool_side_signs", ["q0"] + motions + udir, list(tool_side_signs()),
                 "Identified motions (EX, EY, EZ mm; EA, EB, EC rad) of a tool-side linear axis "
                 "measured from the reference position q0 (mm) in the model's convention, "
                 "array (6, *shape): t + q0 (e x u), e.", shape=(6,)),
        Function("table_side_signs", ["travel"] + motions + udir, list(table_side_signs()),
                 "Identified motions of a table axis (the table's own motions, EX, EY, EZ mm; "
                 "EA, EB, EC rad) in the model's convention (tool relative to the table), "
                 "array (6, *shape): -t - travel (e x u), -e; travel = q - q0 (mm), 0 for a "
                 "rotary axis with the frame origin on it.", shape=(6,)),
    ]


def generate_module() -> str:
    """Text of ``generated/three_point.py`` (deterministic)."""
    src = inspect.getsource(inspect.getmodule(generate_module))
    header = {
        "title": "Three-point identification: Zhang & Hu closed-form solutions.",
        "layout": "--all",
        "layout_file": "derive/three_point.py",
        "sha256": hashlib.sha256(src.encode()).hexdigest(),
        "sources": ("derive/htm.py", "derive/kinematics.py", "derive/three_point.py"),
        "units": "Lever arms x, y, z and measured deviations d mm; error motions EX, EY, EZ "
                 "mm and EA, EB, EC rad (small rotations about the frame axes); determinants "
                 "N mm^3; angles rad; axis directions (ux, uy, uz) unit vectors; q0 and "
                 "travel mm.  design_block maps (mm, rad) to mm.",
    }
    constants = {
        "MOTIONS": repr(MOTIONS),
        "SELECTIONS": repr({k: SELECTIONS[k] for k in sorted(SELECTIONS)}),
        "AXIS_SELECTION": repr(AXIS_SELECTION),
    }
    return render_module(header, constants, derive_functions() + runtime_functions())
