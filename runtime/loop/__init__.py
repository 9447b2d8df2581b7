"""Closing the loop: measured deviations in, declared model fitted, residual traced to candidate
effects "parameter P of the chain varies with covariate C", the layout augmented, before/after
reported on held-out points.  Modules: ``api`` (``volerr.loop(...)``, the one entry, drift
files too), ``run`` (the named steps, robust weights, augmentation), ``candidates`` (P x C x
basis generated from the chain), ``select`` (screening, selection, backward check, merge),
``fitting`` (cross-validated residuals and bases over blocks of points,
:mod:`volerr.estimate.blocks`), ``lags`` (time constants, alternatives), ``symbols``,
``thermal``, ``checks``, ``report`` (HTML), ``simulate`` (a virtual machine with undeclared
effects); the sub-package ``drift`` (the loop on drift runs, a room of its own).  The
selection rules and stepwise core: :mod:`volerr.selection`.
"""

from .run import Report, read_deviations, run_loop
from ..results import former_module


def loop_drift(layout, paths, window=None, files=(), differences=False, progress=None):
    """The loop on drift runs: :func:`volerr.loop.drift.run.loop_drift`."""
    from .drift.run import loop_drift as _loop_drift

    return _loop_drift(layout, paths, window=window, files=files, differences=differences,
                       progress=progress)


__all__ = ["Report", "loop_drift", "read_deviations", "run_loop"]


# names of the former flat module volerr.loop, still importable from here
__getattr__ = former_module(__name__, "run")


from . import api as _api  # noqa: E402
from ..results import callable_package  # noqa: E402

# volerr.loop(...) is volerr.loop.api.loop(...), whatever was imported before
callable_package(__name__, _api.loop)
