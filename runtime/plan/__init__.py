"""Optimal measurement design: ``volerr plan`` chooses, before any machine time is spent, the
set-ups and readings of a campaign of any instruments that minimise the predicted uncertainty
of the volumetric error (I-optimal; D-optimal on request) while every requested parameter
stays determined, writes them as instrument files with empty reading columns and NC programs,
and predicts what ``calibrate`` will report on the filled files.

Steps: :mod:`volerr.plan._run`; candidates :mod:`._candidates`; information (calibrate's
observation model) :mod:`._information`; the design algorithm :mod:`._design`; prediction on
calibrate's path :mod:`._predict`; the conventional plan :mod:`._baseline`; outputs
:mod:`._write`, :mod:`._nc` (programs safe along their whole path; the controller dialects
:mod:`._dialect`, a ball plate's probing :mod:`._probing`), :mod:`._sheet`.
"""

from ._execute import execute
from ._nc import nc_program
from ._run import Plan, default_request, plan
from ._sheet import comparison_png

__all__ = ["Plan", "comparison_png", "default_request", "execute", "nc_program", "plan"]
