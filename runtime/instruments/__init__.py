"""Instruments: each reads its measurement file into :class:`Observations` (rows of the
layout's linear model plus its set-up columns), the one type the estimator
(:mod:`volerr.estimate`), ``volerr calibrate`` and ``volerr loop`` work on."""

from .observations import FileInfo, Observations, Setup, stack

__all__ = ["FileInfo", "Observations", "Setup", "stack"]
