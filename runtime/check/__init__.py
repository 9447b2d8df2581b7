"""Between calibrations: the interim check (``volerr check plan``, ``volerr check``).

``check plan``: from a reference calibration (values and covariance), the shortest check
with the instruments named that detects a change of the reference's parameters -- or of the
volumetric error by D um anywhere in the working volume -- with 95 % probability at a false-
alarm rate below 5 % (:mod:`._plan`, :mod:`._power`; files and NC programs through
:mod:`volerr.plan`).

``check``: the check's readings against the reference's prediction; which parameters changed,
by how much, with uncertainties that hold the reference's covariance (:mod:`._system`), the
smallest set that explains the readings by the loop's rule (:mod:`._select`), the verdict,
the volumetric change (:mod:`._volume`), the tolerance decisions (:mod:`._tolerance`).
Steps: :mod:`._run`; the reference: :mod:`._reference`; the result: :mod:`._result`.
"""

from ._plan import CheckPlan, plan_check
from ._reference import Reference, load as load_reference
from ._result import CheckResult
from ._run import check

__all__ = ["CheckPlan", "CheckResult", "Reference", "check", "load_reference", "plan_check"]

from ..results import callable_package  # noqa: E402

# volerr.check(...) is volerr.check.check(...), whatever was imported before
callable_package(__name__, check)
