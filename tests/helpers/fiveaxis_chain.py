"""An independent exact chain of the five-axis families (DMU50, TT_AC, HH_BC, TH_BC): tool ->
workpiece homogeneous transforms built from rotations (Rodrigues) and translations with the
six tool-relative errors and location errors of every axis, written without volerr's model or
generated code (it never calls them)."""

import numpy as np

#: the DMU 50's B-axis pivot height above the table, mm (thesis)
D = 154.996


def rot(axis, angle):
    """Right-hand rotation HTM (Rodrigues), angle in rad.  A zero angle (every absent error)
    is the identity, which Rodrigues gives exactly (0 * K and (1 - cos 0) * K K are zeros):
    returned without the arithmetic, the same bits, ~20 of a chain's ~23 rotations."""
    if np.ndim(angle) == 0 and angle == 0:
        return np.eye(4)
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    kx = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    m = np.eye(4)
    m[:3, :3] = np.eye(3) + np.sin(angle) * kx + (1 - np.cos(angle)) * kx @ kx
    return m


def trans(v):
    m = np.eye(4)
    m[:3, 3] = v
    return m


def err_htm(e, axis):
    """Exact rigid motion of the six tool-relative errors of ``axis`` (dict of ISO names)."""
    g = lambda p: e.get(p + axis, 0.0)  # noqa: E731
    return (trans([g("EX"), g("EY"), g("EZ")]) @ rot([0, 0, 1], g("EC")) @ rot([0, 1, 0], g("EB"))
            @ rot([1, 0, 0], g("EA")))


def loc_htm(e, axis):
    g = lambda p: e.get(p + "0" + axis, 0.0)  # noqa: E731
    return (trans([g("EX"), g("EY"), g("EZ")]) @ rot([0, 0, 1], g("EC")) @ rot([0, 1, 0], g("EB"))
            @ rot([1, 0, 0], g("EA")))


def tool_side_linear(q, e):
    """base <- tool of X on the bed, Y on X, Z on Y (tool side), squareness on Y (EC0Y) and Z."""
    x, y, z = q["X"], q["Y"], q["Z"]
    sq_y = trans([-e.get("EC0Y", 0.0) * y, 0, 0])
    sq_z = trans([e.get("EB0Z", 0.0) * z, -e.get("EA0Z", 0.0) * z, 0])
    return (trans([x, 0, 0]) @ err_htm(e, "X") @ trans([0, y, 0]) @ sq_y @ err_htm(e, "Y")
            @ trans([0, 0, z]) @ sq_z @ err_htm(e, "Z"))


def table_stage(point, tool_dir, angle, e, axis):
    """carrier <- table of a table rotary axis: the table turns by -angle about the tool-relative
    direction; its error (tool-relative E, location L, both in the carrier frame) is the inverse
    motion of the table."""
    c = np.asarray(point, float)
    return trans(c) @ np.linalg.inv(loc_htm(e, axis) @ err_htm(e, axis)) @ rot(tool_dir, -angle) \
        @ trans(-c)


def head_stage(point, direction, angle, e, axis):
    c = np.asarray(point, float)
    return trans(c) @ loc_htm(e, axis) @ err_htm(e, axis) @ rot(direction, angle) @ trans(-c)


def tool2work(name, q, e):
    """Independent exact tool -> workpiece HTM of each family (angles of q in deg)."""
    r = {a: np.deg2rad(q[a]) for a in "ABC" if a in q}
    if name == "DMU50":
        base2work = np.linalg.inv(table_stage([0, 0, D], [0, 1, -1], r["B"], e, "B")
                                  @ table_stage([0, 0, 0], [0, 0, 1], r["C"], e, "C"))
        return base2work @ tool_side_linear(q, e)
    if name == "TT_AC":
        base2work = np.linalg.inv(table_stage([0, 0, -150.0], [1, 0, 0], r["A"], e, "A")
                                  @ table_stage([0, 0, 0], [0, 0, 1], r["C"], e, "C"))
        return base2work @ tool_side_linear(q, e)
    if name == "HH_BC":
        return (tool_side_linear(q, e) @ head_stage([0, 0, 0], [0, 0, 1], r["C"], e, "C")
                @ head_stage([0, 0, 250.0], [0, 1, 0], r["B"], e, "B"))
    if name == "TH_BC":
        base2work = np.linalg.inv(table_stage([0, 0, 0], [0, 0, 1], r["C"], e, "C"))
        return base2work @ tool_side_linear(q, e) @ head_stage([0, 0, 200.0], [0, 1, 0], r["B"],
                                                               e, "B")
    raise KeyError(name)


