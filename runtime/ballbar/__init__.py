"""Ballbar tests: the ISO 230-4 evaluation of traces (circular deviation G, circular
hysteresis H, radial deviation F), the polar plot, and a diagnosis in ISO 230-1 parameters from
the layout's observation model.  The ballbar as an instrument of ``calibrate`` and ``loop``, its
plans and simulated traces (ISO 230-4 circles, ISO 10791-6 rotary sweeps) are
:mod:`volerr.instruments.ballbar`."""
