"""ISO 10360-2 length measuring errors of the identified model, and the measured step-gauge
lengths beside the model's prediction.

* ``predicted``: the ISO 10360-2 test (:mod:`volerr.uncertainty.iso10360`: 4 space diagonals
  and the 3 axis lines through the centre, 5 lengths each, bidirectional probing) in the box
  of the measured range, evaluated on the identified model: ``E = -u . (e_far - e_near)``
  (um; ``u`` the line's unit vector, ``e`` the identified volumetric error; positive when the
  machine indicates a length longer than the gauge), with its standard uncertainty from the
  calibration's covariance (:mod:`volerr.calibrate.mapping`, correlations included).  The
  probing error (PFTU) and repeatability are not in it: this is the geometric part.
* ``step_gauges``: every placement of an ``artifact`` file whose features are all faces: the
  measured length errors ``E_i = (x_i - x_0) . n - (u_i - u_0)`` (reported points ``x``, the
  gauge's calibrated face positions ``u``, ``n`` its direction, face 0 the first along it) and
  the identified model's ``-n . (e_i - e_0)`` with their uncertainties and the normalised
  error ``En = (E_meas - E_pred) / sqrt(u_meas^2 + u_pred^2)``.  The gauge's readings are
  part of the fit (the prediction is not independent of them: an ``|En|`` well below 1 is
  expected); leave the file out of the campaign for an independent check.
"""

from __future__ import annotations

import numpy as np

from . import mapping


#: predicted length errors and their uncertainties all below this (um): the determined
#: parameters do not act on lengths, the ISO 10360-2 table is left out
NO_LENGTH_UM = 1e-4


def report(cal) -> dict | None:
    """The report's ``iso10360`` entry, or None for a layout whose linear axes are not X, Y,
    Z."""
    from ..errors import InputError
    from ..uncertainty import iso10360

    model = cal.model
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    if sorted(lin) != ["X", "Y", "Z"]:
        return None
    box = {}
    for a in "XYZ":
        lo, hi = cal.ranges[a]
        t_lo, t_hi = model.travel[a]
        box[a] = (max(lo, t_lo), min(hi, t_hi))
        if box[a][1] - box[a][0] < 1.0:
            return None
    out = {}
    try:
        test = iso10360.length_test(model, box)
    except InputError:
        test = None
    if test is not None:
        pos = {a: (np.rad2deg(v) if a in model.rotary_axes else v)
               for a, v in test.positions.items()}
        n = len(next(iter(pos.values())))
        A, cols = mapping.rows_at(cal, pos, np.zeros((n, 3)))
        C = mapping.covariance(cal, cols)
        shape = test.targets.shape[:3]                              # (7, 5, 2)
        A = A.reshape((len(cols), 3) + shape)
        J = -np.einsum("kifl,fi->kfl", A[..., 1] - A[..., 0], test.u)   # (k, 7, 5)
        E = 1e3 * np.einsum("k,kfl->fl", cal.coef_written[cols], J)
        uE = 1e3 * np.sqrt(np.maximum(np.einsum("kfl,km,mfl->fl", J, C, J), 0.0))
        out["predicted"] = [{"line": name, "lengths_mm": [round(float(v), 4) for v in
                                                          test.lengths[i]],
                             "E_um": [round(float(v), 4) + 0.0 for v in E[i]],
                             "u_um": [round(float(v), 5) for v in uE[i]]}
                            for i, name in enumerate(test.names)]
        out["max_abs_E_um"] = round(float(np.max(np.abs(E))), 4)
        out["box_mm"] = {a: [round(v, 4) for v in box[a]] for a in "XYZ"}
        if max(float(np.max(np.abs(E))), float(np.max(uE))) < NO_LENGTH_UM:
            del out["predicted"], out["max_abs_E_um"]
            out["predicted_omitted"] = (
                "the determined parameters do not change lengths measured along lines at "
                "fixed rotary-axis positions (the location errors of rotary axes move the "
                "workpiece frame rigidly): no ISO 10360-2 length error follows from them")
    gauges = step_gauges(cal)
    if gauges:
        out["step_gauges"] = gauges
    if not out:
        return None
    out["note"] = ("E = indicated minus true length (um), geometric part predicted by the "
                   "identified model (probing error not included); u: standard uncertainty "
                   "(k = 1) from the calibration's covariance; step gauges: measured beside "
                   "predicted, En = difference / combined standard uncertainty (the gauge's "
                   "readings are in the fit); parameters not determined are 0 in it "
                   "(undetermined), combinations enter under their written_as name")
    out.update(mapping.what_enters(cal))
    return out


def step_gauges(cal) -> list:
    """Measured step-gauge length errors beside the identified model's (module docstring)."""
    out = []
    for part in cal.parts:
        if not part.files or part.files[0].kind != "artifact" or "feature" not in part.info:
            continue
        info = part.info
        for name in dict.fromkeys(info["placement"].tolist()):
            m = np.flatnonzero(info["placement"] == name)
            if not np.all(info["feature"][m] == "face") or len(m) < 2:
                continue
            order = m[np.argsort(info["point"][m, 0])]
            n_dir = info["rotation"][order[0]][:, 0]
            x = info["measured"][order]
            u = info["point"][order, 0]
            L = u - u[0]
            meas = 1e3 * ((x - x[0]) @ n_dir - L)
            sub = part.subset(order)
            e, _, A, cols = mapping.predict(cal, sub.positions, sub.probe)
            J = -np.einsum("kin,i->kn", A - A[:, :, :1], n_dir)           # (k, faces)
            pred = 1e3 * (cal.coef_written[cols] @ J)
            C = mapping.covariance(cal, cols)
            u_pred = 1e3 * np.sqrt(np.maximum(np.einsum("kn,km,mn->n", J, C, J), 0.0))
            s = np.asarray(part.sigma)[order] if part.sigma is not None else np.zeros(len(m))
            cal_u = info.get("u_std")
            c = np.asarray(cal_u)[order] if cal_u is not None else np.zeros(len(m))
            u_meas = 1e3 * np.sqrt(s ** 2 + s[0] ** 2 + c ** 2 + c[0] ** 2)
            u_meas[0] = 0.0
            comb = np.sqrt(u_meas ** 2 + u_pred ** 2)
            en = np.where(comb > 0, (meas - pred) / np.where(comb > 0, comb, 1.0), 0.0)
            out.append({"file": part.files[0].name, "placement": str(name),
                        "direction": [round(float(v), 6) for v in n_dir],
                        "lengths_mm": [round(float(v), 4) for v in L],
                        "measured_um": [round(float(v), 4) for v in meas],
                        "u_measured_um": [round(float(v), 4) for v in u_meas],
                        "predicted_um": [round(float(v), 4) for v in pred],
                        "u_predicted_um": [round(float(v), 5) for v in u_pred],
                        "En": [round(float(v), 3) for v in en],
                        "max_abs_En": round(float(np.max(np.abs(en))), 3)})
    return out
