"""Probe frame, its transform Tp and the probing-direction angles (Pahk sec. 3, eq. 11-16).

Frames and direction of every matrix
------------------------------------
The probe frame (x', y', z') of a two-axis (tilt A, roll B) probe head is built as in Pahk
eq. (11): ``e'_z`` is the probe axis (pointing from the stylus ball towards the head, so +z for
a vertical probe, A = 0),

    e'_z = (-sin A cos B, -sin A sin B, cos A)
    e'_y = e'_z x e_z / |e'_z x e_z|
    e'_x = e'_y x e'_z / |e'_y x e'_z|

all written in the (local) machine frame (x, y, z).  ``probe2machine`` is the 3x3 matrix whose
*columns* are e'_x, e'_y, e'_z (machine coordinates of a vector given in probe coordinates);
``machine2probe`` is its transpose, whose *rows* are the basis vectors.  Pahk eq. (12) states
``[x', y', z']^T = Tp [x, y, z]^T``, which makes Tp = machine2probe; the matrix printed under
eq. (12) is however probe2machine (its columns are the vectors of eq. 11), which is also what
eq. (14) ``M' = Tp^-1 M`` needs.  :func:`printed_tp` keeps the printed matrix for the audit.

Vertical probe and the sign of A
--------------------------------
The normalisation ``|e'_z x e_z| = |sin A|``.  For the physical tilt range 0 < A < 180 deg the
construction gives the closed form of :func:`probe2machine`; it has a continuous extension to
every A.  At A = 0 the cross product vanishes and eq. (11) is undefined: the closed form's
limit A -> 0+ is the machine frame turned by the roll B about z (the machine frame itself for
B = 0), which is also what a motorised head does -- the roll turns the stylus, and with it the
lobing pattern, about its own axis.  :func:`construction_limit_at_vertical` checks that limit.
At exactly A = 0 the runtime (``volerr.probe.calibration``) takes the machine frame itself, whatever B.

Probing direction and angles (eq. 14-16)
----------------------------------------
A probing direction ``M`` is the unit outward normal of the probed surface at the contact,
i.e. the direction from the contact point to the stylus-ball centre (on the master sphere: from
the sphere centre to the ball centre; the pole phi = 0 is probed along the stylus axis).  This
is the direction for which eq. (17) ``dXc = dX - Probe(phi, theta) M`` has the right sign.
``M' = machine2probe M``; phi = acos(Mz' / |M'|) (eq. 15) is generated in the equivalent,
rounding-safe form atan2(sqrt(Mx'^2 + My'^2), Mz'); theta = atan2(My', Mx') (eq. 16 with the
quadrant resolved) wrapped to [0, 2 pi).  Angles in rad.
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import sympy as sp

from .codegen import Function, render_module

A, B = sp.symbols("A B", real=True)
PHI, THETA = sp.symbols("phi theta", real=True)
MX, MY, MZ = sp.symbols("Mx My Mz", real=True)
MXP, MYP, MZP = sp.symbols("Mxp Myp Mzp", real=True)

E_X = sp.Matrix([1, 0, 0])
E_Y = sp.Matrix([0, 1, 0])
E_Z = sp.Matrix([0, 0, 1])


def probe_axis(a=A, b=B) -> sp.Matrix:
    """e'_z of eq. (11): the probe axis for tilt ``a`` and roll ``b`` (rad)."""
    return sp.Matrix([-sp.sin(a) * sp.cos(b), -sp.sin(a) * sp.sin(b), sp.cos(a)])


def _pythagoras(expr, angles=(A, B)) -> sp.Expr:
    """``expr`` (a polynomial in sines and cosines) expanded with every ``cos(q)**k``, k >= 2,
    written as ``cos(q)**(k mod 2) (1 - sin(q)**2)**(k // 2)`` for q in ``angles``: a
    canonical form, at most linear in each cosine, so two such polynomials are equal as
    functions iff the forms are equal.  Polynomial arithmetic only (no ``simplify``)."""
    e = sp.expand(expr)
    cosines = {sp.cos(q) for q in angles}
    rep = {p: p.base ** (p.exp % 2) * (1 - sp.sin(p.base.args[0]) ** 2) ** (p.exp // 2)
           for p in e.atoms(sp.Pow) if p.base in cosines and p.exp.is_Integer and p.exp >= 2}
    return sp.expand(e.xreplace(rep)) if rep else e


def _unit(v: sp.Matrix, norm_sq, norm, angles) -> sp.Matrix:
    """``v / |v|`` with ``|v|^2`` proven equal to ``norm**2`` (so the norm is replaced)."""
    assert _pythagoras(v.dot(v) - norm_sq, angles) == 0
    return v.applyfunc(lambda c: _pythagoras(sp.cancel(c / norm), angles))


def basis(a=A, b=B) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The probe-frame basis (e'_x, e'_y, e'_z) built by the cross products of eq. (11).

    The normalisation ``|e'_z x e_z| = |sin a|`` is taken as ``sin a`` (0 < a < pi)."""
    ez = probe_axis(a, b)
    cross_y = ez.cross(E_Z)
    ey = _unit(cross_y, sp.sin(a) ** 2, sp.sin(a), (a, b))
    cross_x = ey.cross(ez)
    ex = _unit(cross_x, 1, 1, (a, b))
    return ex, ey, ez


def probe2machine(a=A, b=B) -> sp.Matrix:
    """3x3 matrix with columns e'_x, e'_y, e'_z: ``v_machine = probe2machine @ v_probe``."""
    return sp.Matrix.hstack(*basis(a, b))


def machine2probe(a=A, b=B) -> sp.Matrix:
    """Tp of eq. (12) as the equation states it: ``[x', y', z'] = Tp [x, y, z]`` (rows = basis)."""
    return probe2machine(a, b).T


def printed_tp(a=A, b=B) -> sp.Matrix:
    """The matrix printed under eq. (12), with the OCR artefact ``cos B = 0`` read as cos B."""
    return sp.Matrix([[sp.cos(a) * sp.cos(b), -sp.sin(b), -sp.sin(a) * sp.cos(b)],
                      [sp.cos(a) * sp.sin(b), sp.cos(b), -sp.sin(a) * sp.sin(b)],
                      [sp.sin(a), 0, sp.cos(a)]])


def printed_basis(a=A, b=B) -> tuple[sp.Matrix, sp.Matrix, sp.Matrix]:
    """The closed forms printed in eq. (11) for e'_x, e'_y, e'_z."""
    return (sp.Matrix([sp.cos(a) * sp.cos(b), sp.cos(a) * sp.sin(b), sp.sin(a)]),
            sp.Matrix([-sp.sin(b), sp.cos(b), 0]),
            probe_axis(a, b))


def construction_limit_at_vertical(b=B) -> sp.Matrix:
    """lim A -> 0+ of the eq. (11) construction: Rz(b) (the machine frame for b = 0)."""
    return probe2machine(A, b).limit(A, 0, "+")


def direction_in_probe_frame(a=A, b=B, m=(MX, MY, MZ)) -> sp.Matrix:
    """Eq. (14): the probing direction in probe coordinates, ``M' = machine2probe M``
    (= Tp^-1 M with the printed Tp, whose inverse is its transpose)."""
    return (machine2probe(a, b) * sp.Matrix(m)).applyfunc(sp.expand)


def direction_angles(m=(MXP, MYP, MZP)) -> tuple:
    """Eq. (15)-(16): phi from the probe axis and azimuth theta of a probe-frame direction.

    phi = acos(Mz'/|M'|) is returned as atan2(rho, Mz') (equal for every non-zero M', exact
    near the pole); theta = atan2(My', Mx') mod 2 pi."""
    mx, my, mz = m
    rho = sp.sqrt(mx ** 2 + my ** 2)
    phi = sp.atan2(rho, mz)
    theta = sp.Mod(sp.atan2(my, mx), 2 * sp.pi)
    return phi, theta


def eq15_phi(m=(MXP, MYP, MZP)):
    """Eq. (15) as printed: phi = acos(Mz' / |M'|)."""
    mx, my, mz = m
    return sp.acos(mz / sp.sqrt(mx ** 2 + my ** 2 + mz ** 2))


def unit_direction(phi=PHI, theta=THETA) -> sp.Matrix:
    """The probe-frame unit vector of angles (phi, theta): inverse of eq. (15)-(16)."""
    return sp.Matrix([sp.sin(phi) * sp.cos(theta), sp.sin(phi) * sp.sin(theta), sp.cos(phi)])


def direction_in_machine_frame(a=A, b=B, phi=PHI, theta=THETA) -> sp.Matrix:
    """Machine-frame probing direction of probe-frame angles (phi, theta)."""
    return (probe2machine(a, b) * unit_direction(phi, theta)).applyfunc(sp.expand)


def functions() -> list[Function]:
    """The generated functions of ``volerr.generated.probe``."""
    args_ab = [str(A), str(B)]
    return [
        Function("probe2machine", args_ab, list(probe2machine()),
                 "Probe frame -> machine frame, array (3, 3, *shape): columns e'_x, e'_y, e'_z "
                 "(Pahk eq. 11; the matrix printed under eq. 12). A, B: tilt, roll (rad).",
                 shape=(3, 3)),
        Function("machine2probe", args_ab, list(machine2probe()),
                 "Machine frame -> probe frame, array (3, 3, *shape): Tp of eq. (12) as stated "
                 "[x', y', z'] = Tp [x, y, z] (rows e'_x, e'_y, e'_z).", shape=(3, 3)),
        Function("direction_to_probe", args_ab + [str(MX), str(MY), str(MZ)],
                 list(direction_in_probe_frame()),
                 "Eq. (14): machine-frame direction (Mx, My, Mz) -> probe frame (Mx', My', Mz')."),
        Function("direction_angles", [str(MXP), str(MYP), str(MZP)], list(direction_angles()),
                 "Eq. (15)-(16): (phi, theta) in rad of a probe-frame direction; phi from the "
                 "probe axis in [0, pi], theta azimuth in [0, 2 pi] (2 pi only by rounding "
                 "of a tiny negative My')."),
        Function("unit_direction", [str(PHI), str(THETA)], list(unit_direction()),
                 "Probe-frame unit vector (Mx', My', Mz') of the angles (phi, theta), rad."),
        Function("direction_to_machine", args_ab + [str(PHI), str(THETA)],
                 list(direction_in_machine_frame()),
                 "Machine-frame unit vector (Mx, My, Mz) of probe-frame angles (phi, theta); "
                 "A, B, phi, theta in rad."),
    ]


def source_sha256() -> str:
    """sha256 of this derivation's source text (recorded in the generated header)."""
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


def generate_module() -> str:
    """Text of ``generated/probe.py`` (deterministic; registered in ``volerr derive --all``)."""
    header = {
        "title": "Probe frame of a tilt/roll probe head and probing-direction angles "
                 "(Pahk sec. 3, eq. 11-16).",
        "layout": "--all",
        "layout_file": "derive/probe.py",
        "sha256": source_sha256(),
        "sources": ("derive/probe.py",),
        "units": "Angles A (tilt), B (roll) of the probe head and the probing-direction "
                 "angles phi (from the probe axis) and theta (azimuth) in rad; directions "
                 "(Mx, My, Mz) and (Mx', My', Mz') unit vectors, frame matrices rotations "
                 "(dimensionless).  No lengths.",
    }
    constants = {"DERIVATION": repr("volerr.derive.probe")}
    return render_module(header, constants, functions())
