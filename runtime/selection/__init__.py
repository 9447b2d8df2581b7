"""Model selection, one floor below the loops and the check: the rules stated once
(:mod:`~volerr.selection.rules`: BIC gain, CV gain and its t, ties, significance k, lag
earn), stepwise forward / backward / merge over a scorer (:mod:`~volerr.selection.stepwise`),
the ln-tau profile of a lag (:mod:`~volerr.selection.profile`) and the shared linear algebra
(:mod:`~volerr.selection.linalg`: one symmetric pseudo-inverse, one normal-equations solve).
The 3-D loop (:mod:`volerr.loop.select`), the drift loop (:mod:`volerr.loop.drift`) and the
interim check (:mod:`volerr.check._select`) use it; their scorers stay their own.  numpy
only."""
