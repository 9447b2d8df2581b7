"""Shared test set-up.  The independent references (exact numpy chains, rigid-body and tracker
simulators) live in ``tests/helpers/`` and are imported as ``helpers.<module>``
(``pythonpath = ["tests"]`` in pyproject.toml).

Hypothesis runs derandomized, always (profile ``deterministic``): the examples follow from the
test's source, so every run -- a developer's, CI's, another checkout's -- tries the same ones,
and no example database (``database=None``) carries a failure found on one machine into the
runs of that machine only.  A test that fails does so on every run, where it can be fixed; one
that passes cannot fail at random.  It is loaded always, not only when ``CI`` is set, because a
local run must reproduce CI's verdict.  To search for new failing examples on purpose:
``HYPOTHESIS_PROFILE=explore python -m pytest ...`` (random, with a database under
``.hypothesis/``, which .gitignore keeps out of the repository)."""

import gc
import os
import sys

# One BLAS thread in every test process (issue 42 item 7: the suite's time).  Two xdist workers
# already fill this 2-core machine, and OpenBLAS would start a thread per core in each: on the
# tests' small systems (tens to a few hundred columns) the extra threads only wait, at a cost
# (``lstsq`` of 453 x 94: 97 ms CPU with the default threads under load, 3.5 ms with one;
# tests/loop/test_drift_shrink.py 62 -> 3.5 s CPU; tests/planning/test_plan.py 21.4 -> 14.6 s).
# Set before numpy is imported here (matplotlib imports it), so the workers xdist starts and
# every ``python -m volerr`` a test starts inherit it; threadpoolctl holds a numpy imported
# earlier (by a plugin) to the same.  The runtime already runs its loops, calibrations and
# checks on one BLAS thread (threadpool_limits in volerr.loop.run, calibrate.run, check).
for _name in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ[_name] = "1"

import matplotlib  # noqa: E402
import pytest  # noqa: E402
from threadpoolctl import threadpool_limits  # noqa: E402
from hypothesis import settings  # noqa: E402

threadpool_limits(limits=1)

matplotlib.use("Agg")  # no display on CI; every plot goes to a file

# Bytecode caches written by the test processes (issue 42 item 7): where the environment sets
# PYTHONDONTWRITEBYTECODE (this machine's does), every process of a run -- both xdist workers,
# each ``python -m volerr`` a test starts -- compiled volerr and the test files (with pytest's
# assertion rewriting) from source again.  The pytest processes now write them once into the
# checkout's __pycache__ folders (.gitignore); every later process reads them (the processes
# the tests start keep the environment: they read, never write).  Nothing a test checks lists
# those folders.  Measured from a checkout without them (-p no:xdist, 2 pairs, load 6-7):
# tests/fiveaxis/test_compensate.py + tests/cli/test_cli_core.py 20.7 -> 15.9 s CPU.
sys.dont_write_bytecode = False

settings.register_profile("deterministic", derandomize=True, database=None,
                          print_blob=True)
settings.register_profile("explore", derandomize=False)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "deterministic"))


# The cyclic garbage collector (issue 42 follow-up: the suite's time).  Each test process
# (each xdist worker) imports the whole tree at collection -- numpy, scipy, sympy, matplotlib,
# pandas, hypothesis, every volerr and test module: some 240 000 objects the collector tracks
# -- and keeps what the modules it has run cache (models, layouts, sympy's cache).  Every full
# collection scanned all of it again (0.2-0.4 s each, 16-18 per worker on the subset below),
# though none of it is garbage.  Here the garbage is collected once after collection and after
# each test module (when the next test belongs to another module: its fixtures torn down, the
# last test's arguments released), and what is left alive is set aside (``gc.freeze``): later
# collections scan only the objects made since.  No garbage made before a freeze is kept; an
# object alive at a freeze is freed by its reference count alone afterwards (not when it later
# becomes part of a garbage cycle; no test's result depends on when that happens).
# volerr.demo, run inside a test, sees the freeze and leaves it alone.  Measured with -n 2 as
# CI, the whole tree collected, -k of 7 files each (S1: lag acceptance, loop outliers and
# trace, check, api, audit categories and Pahk, 124 tests; S2: demo, race, plan, mixed
# calibration, Monte Carlo, compensate, check acceptance, 114), three interleaved pairs each,
# load 3-5: CPU S1 125.5, 123.2, 92.7 -> 104.6, 117.6, 89.9 s, S2 90.7, 75.2, 66.2 -> 82.1,
# 68.0, 62.5 s; collector time in the workers S1 14.9, 14.6, 12.2 -> 8.7, 11.8, 10.3 s, S2
# 9.8, 8.5, 7.4 -> 10.2, 6.9, 6.7 s; peak RSS not higher (S1 756-793 -> 742-743 MB); the
# outputs of test_lag_acceptance, test_loop_outliers and audit's test_cli_html identical but
# for wall times.
def _settle() -> None:
    """Collect the garbage, then set every object alive aside from later collections."""
    gc.collect()
    gc.freeze()


def pytest_collection_finish(session):
    _settle()


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_protocol(item, nextitem):
    yield   # the test's set-up, call and tear-down, then its arguments released
    if nextitem is not None and getattr(nextitem, "module", None) is not getattr(
            item, "module", None):
        _settle()


# Module fixtures computed once per run, not once per worker (the suite's time, session 8).
# Under ``--dist loadgroup`` the tests of a module without an ``xdist_group`` mark are dealt to
# both workers, and each worker that receives one of them computes the module's module-scoped
# fixtures again (tests/check/test_interim_checks_page.py's weekly demo: 5.3 s of set-up on one
# worker, 5.6 s on the other).  A test that uses a module- or package-scoped fixture of the
# tests (not one of pytest's own) and has no group is put in its module's group, so that one
# worker computes those fixtures once; a group set in the test file is kept.  Session-scoped
# fixtures are left to their files' own groups (tests/audit/conftest.py).  Runs before
# xdist's own hook, which appends the group to the node id.
_SHARED_SCOPES = ("module", "package")


def _uses_a_module_fixture(item) -> bool:
    """Whether ``item`` uses a module- or package-scoped fixture defined under tests/."""
    info = getattr(item, "_fixtureinfo", None)
    if info is None:
        return False
    for defs in info.name2fixturedefs.values():
        for fixturedef in defs:
            if fixturedef.scope in _SHARED_SCOPES and fixturedef.baseid:
                return True
    return False


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    for item in items:
        if item.get_closest_marker("xdist_group") is None and _uses_a_module_fixture(item):
            item.add_marker(pytest.mark.xdist_group(item.nodeid.split("::")[0]))
