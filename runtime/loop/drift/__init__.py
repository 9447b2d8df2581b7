"""The loop on drift runs (one machine position held while the machine heats and cools), a
room of its own on the selection core (:mod:`volerr.selection`).  One data type in
(:class:`~volerr.loop.drift.series.DriftSeries`), a result out
(:class:`~volerr.loop.drift.report.DriftReport`).

Modules: ``series`` (the data type, reading drift files into it), ``split`` (which readings
are held out), ``basis`` (the columns a channel may vary with: sensors, the heat input,
lags; the blocked folds), ``engine`` (blocked cross-validation from cross-products),
``select`` (forward selection of a channel's terms), ``fit`` (the steps of one channel:
selection, backward check, time constants refined, jackknife, significance), ``rows`` (the
directed channels as rows of the layout's model), ``run`` (the whole loop:
:func:`~volerr.loop.drift.run.loop_drift`), ``report`` (the result: JSON, console, table,
predictions), ``figure`` (the figures and the page).  ``volerr.loop(...)`` sends drift files
here (:func:`volerr.loop.api.loop`).
"""
