"""Pahk's eq. (4), the MB1 volumetric error, written by hand in numpy: the independent
reference of the Model API's tests and the baseline of ``benchmarks/bench_volumetric.py``."""

import numpy as np

#: eq. (4)'s parameters in ISO names (EC0Y = alpha, EB0Z = -beta1, EA0Z = beta2)
NAMES = tuple(p + a for a in "XYZ" for p in ("EX", "EY", "EZ", "EA", "EB", "EC")) + \
    ("EC0Y", "EB0Z", "EA0Z")


def hand_eq4(pos, g, probe):
    """(N, 3) mm at positions ``pos`` (N, 3) mm for errors ``g`` (name -> scalar or (N,);
    missing names are 0) and probe offset ``probe`` (3,) or (N, 3) mm."""
    g = {k: g.get(k, 0.0) for k in NAMES}
    x, y, z = pos.T
    xp, yp, zp = probe if np.ndim(probe) == 1 else np.asarray(probe, float).T
    ez = g["ECX"] + g["ECY"] + g["ECZ"]
    ey = g["EBX"] + g["EBY"] + g["EBZ"]
    ex = g["EAX"] + g["EAY"] + g["EAZ"]
    dx = (g["EXX"] + g["EXY"] + g["EXZ"] + z * (g["EB0Z"] + g["EBX"] + g["EBY"])
          - yp * ez + zp * ey)
    dy = (g["EYX"] + g["EYY"] + g["EYZ"] + x * (-g["EC0Y"] + g["ECY"])
          - z * (g["EA0Z"] + g["EAY"] + g["EAX"]) + xp * ez - zp * ex)
    dz = g["EZX"] + g["EZY"] + g["EZZ"] - x * g["EBY"] - xp * ey + yp * ex
    return np.stack(np.broadcast_arrays(dx, dy, dz), axis=-1)
