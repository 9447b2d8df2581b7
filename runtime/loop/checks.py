"""Plans the closing loop refuses: what cannot show an effect at all.

* a file whose points all stand at one position (every axis at one value, whatever the probe
  offsets): the errors cannot vary from point to point, so every "effect" found in it would be
  the set-up or noise;
* a campaign whose readings determine none of the declared model's parameters (each enters
  only together with the instruments' set-up unknowns, e.g. sphere probing with the rotary
  axes standing still): the axes that no point moves are named.

Both raise :class:`volerr.errors.InputError` (one line, exit 2 at the command line).
Positions in mm / deg; two positions count as one within ``SAME`` (mm or deg).
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError

SAME = 1e-6


def _name(dat, f: int) -> str:
    files = dat.files or ()
    return files[f].name if f < len(files) else "the data"


def _still(positions: dict, idx) -> list:
    return [a for a, v in positions.items() if np.ptp(np.asarray(v)[idx]) <= SAME]


def _axes_text(axes) -> str:
    return axes[0] if len(axes) == 1 else ", ".join(axes[:-1]) + f" or {axes[-1]}"


def one_position(dat) -> None:
    """Refuse a file (or data without files) whose points all share one position."""
    file_of = dat.file if dat.file is not None else np.zeros(dat.n, int)
    for f in np.unique(file_of):
        idx = np.flatnonzero(file_of == f)
        if len(_still(dat.positions, idx)) == len(dat.positions):
            at = ", ".join(f"{a} = {float(v[idx[0]]):g}" for a, v in dat.positions.items())
            raise InputError(
                f"{_name(dat, int(f))}: all {len(idx)} points stand at one position ({at}): a "
                f"point cloud from one position cannot show how errors vary; measure at "
                f"positions spread over the travel")


#: points on which :func:`determined` looks first (all of them when nothing is determined there)
CHECK_POINTS = 2000


def _kept_parameters(model, dat, ranges, points) -> list:
    """Parameter labels of the declared model (component series of degree 2: no term of it is
    gauge-fixed as a whole) that the readings at ``points`` determine beyond the gauge and the
    set-up unknowns."""
    from ..estimate import blocks
    from ..estimate.design import declared_design, gauge_mask, identifiability_gram

    all_labels = declared_design(model, dat.subset(np.arange(1)), 2, ranges).labels
    keep, _ = gauge_mask(model, dat, 2, ranges)
    labels = [lab for lab, k in zip(all_labels, keep) if k]
    G, _, _ = blocks.normal(blocks.Design(model, dat, 2, ranges, keep), points,
                            np.ones(len(points)), dat.deviation.ravel())
    kept, _ = identifiability_gram(G, labels)
    return [lab for lab, k in zip(labels, kept) if k and lab[0] != "setup"]


def determined(model, dat, ranges) -> None:
    """Refuse a campaign whose readings determine none of the declared model's parameters
    (beyond the gauge and the instruments' set-up unknowns), naming the axes no point moves."""
    n = dat.n
    points = np.arange(n)
    if n > CHECK_POINTS:
        sub = np.sort(np.random.default_rng(0).choice(n, CHECK_POINTS, replace=False))
        if _kept_parameters(model, dat, ranges, sub):
            return
    if _kept_parameters(model, dat, ranges, points):
        return
    still = _still(dat.positions, slice(None))
    why = (f"no point moves {_axes_text(still)}" if still else
           "every parameter enters the readings only together with the instruments' set-up "
           "unknowns")
    raise InputError(f"these readings determine none of the declared model's parameters: "
                     f"{why}; measure over the travel of every axis")
