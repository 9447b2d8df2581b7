"""Calibration from instruments: weighted least squares of a layout's parameters over the files
of any instruments mixed in one campaign, with the uncertainty of every identified value, what
the campaign cannot determine and which file sees what (``volerr calibrate``).  Modules:
``run`` (the named steps), ``terms`` (parameter selection and report names), ``estimability``
(null space, per-file visibility), ``report`` (HTML)."""

from .run import Calibration, calibrate

__all__ = ["Calibration", "calibrate"]

from ..results import callable_package  # noqa: E402

# volerr.calibrate(...) is calibrate(...), whatever was imported before (runtime/results.py)
callable_package(__name__, calibrate)
