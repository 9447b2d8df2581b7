"""BLAS held to one thread while these tests run (``helpers.blas``: small systems, a shared
2-core machine)."""

from helpers.blas import one_blas_thread  # noqa: F401  (an autouse fixture)
