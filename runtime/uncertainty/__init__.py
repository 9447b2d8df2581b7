"""Task-specific measurement uncertainty by Monte Carlo (ISO/TS 15530-4 "virtual CMM",
JCGM 101 / GUM Supplement 1) and the simulated ISO 10360-2 length measuring test.

Plausible machines (:mod:`.ensemble`) x a measurement task (:mod:`.tasks`) -> chunked, seeded
Monte Carlo (:mod:`.montecarlo`, optionally on dask) -> estimate, u, U, coverage interval.
"""

from .ensemble import Ensemble, Temperature, parse_spec  # noqa: F401
from .montecarlo import Problem, run, run_adaptive, summarize  # noqa: F401
from .tasks import EVALUATIONS, Task, evaluate, read_task  # noqa: F401

from . import api as _api  # noqa: E402
from ..results import callable_package  # noqa: E402

# volerr.uncertainty(...) is volerr.uncertainty.api.uncertainty(...), whatever was imported
callable_package(__name__, _api.uncertainty)
