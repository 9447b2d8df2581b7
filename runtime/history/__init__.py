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
