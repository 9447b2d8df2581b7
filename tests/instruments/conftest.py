"""Instrument tests: BLAS limited to one thread while they run (the design matrices are
small; several threads on a shared 2-core machine only oversubscribe it)."""

import pytest
from threadpoolctl import threadpool_limits


@pytest.fixture(autouse=True, scope="module")
def _one_blas_thread():
    with threadpool_limits(limits=1):
        yield
