"""One BLAS thread for a test module (issue 42 item 7: the suite's time).

Import the fixture into a test module to use it there (pytest takes the fixtures a module
names): ``from helpers.blas import one_blas_thread  # noqa: F401 (autouse)``.

Why: the suite runs two xdist workers on two cores, and OpenBLAS starts a thread per core in
each, so that its threads outnumber the cores; on the small matrices of these tests (a few
hundred rows, at most about a hundred columns) their waiting costs far more CPU than the
arithmetic.  Measured on this machine (load 12-18), ``numpy.linalg.lstsq`` of a 453 x 94
matrix: 97 ms CPU with the default threads, 3.5 ms with one.  What the tests compute with one
thread is what ``python -m volerr`` computes with ``OPENBLAS_NUM_THREADS=1``; the figures
may differ from the threaded run's in the last digits (summation order; the FL_THERMAL
loop's JSON: the same families and terms, floats within 1e-10 relative).
"""

from __future__ import annotations

import pytest


@pytest.fixture(autouse=True, scope="module")
def one_blas_thread():
    """BLAS and OpenMP limited to one thread while the module's tests run."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        yield
