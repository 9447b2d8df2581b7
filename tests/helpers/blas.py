"""BLAS held to one thread while a module's tests run (issue 42 item 7), for the folders whose
tests solve many small systems (plans, checks, calibrations): their matrices are tens to a few
hundred columns wide, where a second OpenBLAS thread on this shared 2-core machine (two xdist
workers already) mostly spins.  Measured (``-p no:xdist``, CPU of the pytest process, loaded
machine, the same test files with OPENBLAS_NUM_THREADS unset / 1): tests/planning/test_plan.py
21.4 -> 14.6 s, tests/check/test_check.py 14.1 -> 12.9 s; on tests/outputs, acceptance,
uncertainty, identify and cmm it made no difference (52.6 / 52.2 s), so they are left as they
are.  The folder's conftest.py imports :func:`one_blas_thread` (autouse), as tests/instruments'
conftest does for the instrument tests."""

import pytest
from threadpoolctl import threadpool_limits


@pytest.fixture(autouse=True, scope="module")
def one_blas_thread():
    with threadpool_limits(limits=1):
        yield
