"""Shared test set-up.  The independent references (exact numpy chains, rigid-body and tracker
simulators) live in ``tests/helpers/`` and are imported as ``helpers.<module>``
(``pythonpath = ["tests"]`` in pyproject.toml)."""

import matplotlib

matplotlib.use("Agg")  # no display on CI; every plot goes to a file
