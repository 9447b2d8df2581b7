"""The ``deviations`` instrument: 3-D deviations of the tool point (a CMM against a reference, a
laser tracker, any instrument that gives the actual minus the nominal position).

Reading: ``dx, dy, dz`` = actual minus nominal position of the probe tip / tool point in the
workpiece frame (the instrument's frame), um or mm; the projection is the identity and the
set-up is the instrument's rigid placement (three translations, three small rotations of the
workpiece end of the chain, through the layout's generated ``setup_sensitivity``).
Optional ``u_um`` (or ``u_mm``): the standard uncertainty of each coordinate of the row's
reading (k = 1, > 0); it weighs the row (``1 / u^2``) and is the ``u`` of the residual rule's
``chi2 = sum (r / u)^2`` (:mod:`volerr.fit_quality`); without it 1 um is assumed
(:data:`DEFAULT_U_UM`).
File format: ``volerr formats deviations``.
"""

from __future__ import annotations

from ..machine.model import Model
from . import _fields as f
from ._csv import read_columns
from .observations import FileInfo, Observations

KIND = "deviations"
#: standard uncertainty (um, per coordinate) assumed for a file without ``u_um``
DEFAULT_U_UM = 1.0


def read_deviations(path, model: Model) -> Observations:
    """Read a measured-deviation CSV and check it against ``model`` (InputError on defects)."""
    c = read_columns(path)
    f.refuse_duplicate_rows(c, c.name)
    obs = columns_to_data(c.numbers, model, c.name, c.text)
    obs.files = (FileInfo(c.name, KIND, "um", 3),)
    return obs


def detect(names) -> bool:
    """A deviations file has the three deviation columns."""
    low = {n.lower() for n in names}
    return all(any(f"{d}_{u}" in low for u in ("um", "mm")) for d in ("dx", "dy", "dz"))


read = read_deviations


def columns_to_data(cols: dict, model: Model, where: str = "data", text=None) -> Observations:
    """Column dict (CSV names) -> :class:`Observations`, checking axes, units and ranges.

    ``text``: columns that are not all numbers (name -> the first bad cell's message, None for a
    label column): an error when the column is needed, else a warning and left out.  A
    covariate with NaN is left out with a warning; positions, offsets and deviations must be
    finite."""
    cols, text = f.drop_nonfinite(cols, text, where)
    needed = {a + u for a in model.axes for u in ("", "_mm", "_deg")}
    needed |= {c + u for c in ("Xp", "Yp", "Zp") for u in ("", "_mm")}
    needed |= {f"{d}_{u}" for d in ("dx", "dy", "dz") for u in ("um", "mm")}
    needed |= set(model.covariates) | {"u_um", "u_mm"}
    warnings = f.text_columns(text, needed, where)
    find = f.Finder(cols, where)
    positions = f.positions(find, model, where, min_points=20, needs="the loop")
    n = len(next(iter(positions.values())))
    probe = f.probe(find, n, where)
    dev = f.readings(find, ("dx", "dy", "dz"), n, where)
    declared = find.name("u_um") or find.name("u_mm")
    # no u column: sigma None (1 um alone, or the campaign's median beside other files)
    u = f.uncertainty(find, n, DEFAULT_U_UM, where) if declared else None
    covs = f.covariates(find, model, where, skip=[c for c in cols if c.lower().startswith(
        ("dx", "dy", "dz"))])
    return Observations(positions, probe, dev, covs, warnings, sigma=u)
