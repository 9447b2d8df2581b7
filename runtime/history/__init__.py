"""A machine's history between calibrations (``volerr history add`` / ``show``).

* :mod:`~volerr.history.results`: a calibrate or check result as one entry;
* :mod:`~volerr.history.store`: the store (SQLite file or PostgreSQL URL, SQLAlchemy Core);
* :mod:`~volerr.history.analysis`: control charts (ISO 7870-2, 7870-6), change points,
  trends, forecasts;
* :mod:`~volerr.history.volume`: the volumetric error over the travel (``map=``);
* :mod:`~volerr.history.report`: :class:`History` (JSON, console, HTML);
* :mod:`~volerr.history.run`: :func:`add` and :func:`show`, the commands' functions.
"""

from .run import add, show

__all__ = ["add", "show"]

from ..results import callable_package  # noqa: E402

# volerr.history(db, machine, ...) is volerr.history.show(...) (the History of `volerr history
# show`), whatever was imported before; volerr.history.add / show stay
callable_package(__name__, show)
