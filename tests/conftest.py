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
