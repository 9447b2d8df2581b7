"""An exact DMU 50 for the acceptance tests of issue 37 (interim checks and history), written
for them alone: it never calls volerr's model, instruments, plan or check code.

The machine (the layout's description, ISO 841 directions): X, Y, Z ideal on the tool side
(the tool point in the machine frame is ``(X + Xp, Y + Yp, Z + Zp)``); on the workpiece side a
swivelling table: B about ``(0, 1, -1)/sqrt 2`` through ``(0, 0, d)``, C about ``+z`` through
the origin on B; the table turns by ``-B`` and ``-C`` (so the tool turns by ``+B``, ``+C``
relative to it).  A rotary axis' location errors ``EX0R EY0R EZ0R`` (mm) and ``EA0R EB0R EC0R``
(rad) are a rigid motion ``L = T(EX0, EY0, EZ0) Rz(EC0) Ry(EB0) Rx(EA0)`` of the axis relative to
its carrier, tool-relative: the table's motion is ``T(c) L^-1 R(dir, -angle) T(-c)``, so a
point of the machine frame is in the workpiece frame at

    p_work = T(c_C) R(z, C) L_C T(-c_C) . T(c_B) R(dir_B, B) L_B T(-c_B) . p_machine

exactly (finite rotations, Rodrigues).  An R-test / touch-probe sphere reading (``sphere``
format) is the tool point minus the sphere's true centre in the workpiece frame, in um: the
true centre is the file's nominal centre plus an offset per placement (the set-up; drawn
once per placement from ``rng``), plus the reading's noise ``N(0, u_um)``.
"""

from __future__ import annotations

import csv
import io

import numpy as np

#: height of the B pivot above the table, mm (the DMU50 layout's d)
D = 154.996
LOCATION = ("EX0B", "EY0B", "EA0B", "EB0B", "EX0C", "EY0C", "EA0C", "EB0C")


def _rodrigues(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, float)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + np.sin(angle) * K + (1.0 - np.cos(angle)) * (K @ K)


def _location(errors: dict, axis: str):
    """(R, t) of L = T(t) Rz Ry Rx for the location errors of ``axis`` (mm, rad)."""
    g = lambda p: float(errors.get(f"{p}0{axis}", 0.0))  # noqa: E731
    R = _rodrigues([0, 0, 1], g("EC")) @ _rodrigues([0, 1, 0], g("EB")) @ \
        _rodrigues([1, 0, 0], g("EA"))
    return R, np.array([g("EX"), g("EY"), g("EZ")])


def machine_to_work(p: np.ndarray, b_deg: float, c_deg: float, errors: dict) -> np.ndarray:
    """A point of the machine frame (mm) in the workpiece frame (mm), exactly (module doc)."""
    cB = np.array([0.0, 0.0, D])
    RB, tB = _location(errors, "B")
    RC, tC = _location(errors, "C")
    q = p - cB
    q = RB @ q + tB
    q = _rodrigues([0, 1, -1], np.deg2rad(b_deg)) @ q + cB
    q = RC @ q + tC
    return _rodrigues([0, 0, 1], np.deg2rad(c_deg)) @ q


def tool_in_work(row: dict, errors: dict) -> np.ndarray:
    p = np.array([row["X"] + row.get("Xp", 0.0), row["Y"] + row.get("Yp", 0.0),
                  row["Z"] + row.get("Zp", 0.0)])
    return machine_to_work(p, row.get("B", 0.0), row.get("C", 0.0), errors)


def fill_sphere(path, errors_um_urad: dict, rng, u_um: float | None = None,
                offsets_um: float = 10.0) -> None:
    """Fill the reading columns of the ``sphere`` plan file ``path`` in place: the machine's
    location errors ``errors_um_urad`` (um for EX0/EY0/EZ0, urad for EA0/EB0/EC0), set-up
    offsets of the spheres ``N(0, offsets_um)`` per placement and noise of ``u_um`` (default:
    the file's ``u_um`` column)."""
    errors = {n: v * (1e-6 if n[1] in "ABC" else 1e-3) for n, v in errors_um_urad.items()}
    text = path.read_text()
    lines = text.splitlines(keepends=True)
    head = [ln for ln in lines if ln.startswith("#")]
    body = "".join(ln for ln in lines if not ln.startswith("#"))
    rows = list(csv.DictReader(io.StringIO(body)))
    fields = list(rows[0].keys())
    placements = list(dict.fromkeys(r["placement"] for r in rows))
    offset = {p: rng.normal(0.0, offsets_um, 3) for p in placements}
    for r in rows:
        num = {k: float(r[k]) for k in ("X", "Y", "Z", "B", "C", "Xp", "Yp", "Zp") if r.get(k)}
        centre = np.array([float(r[f"sphere_{a}"]) for a in "xyz"])
        u = float(r["u_um"]) if u_um is None else u_um
        d = (tool_in_work(num, errors) - centre) * 1e3 - offset[r["placement"]] \
            + rng.normal(0.0, u, 3)
        r["dx_um"], r["dy_um"], r["dz_um"] = (f"{v:.5f}" for v in d)
    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=fields, lineterminator="\n")
    w.writeheader()
    w.writerows(rows)
    path.write_text("".join(head) + out.getvalue())
