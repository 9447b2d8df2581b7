"""``volerr plan`` designs computed once per test process (issue 42 item 7).

A plan's design (candidates, exchange, predictions) is most of a ``volerr plan`` run and
depends only on the arguments of the API call (layout, instruments, readings, parameters,
minutes, criterion, seed); the NC dialect, ``--out``, ``--json``, ``--force`` are applied when
the command writes the result (``Plan.write``).  Inside :func:`designed_once`, the command
(``volerr.cli.main(["plan", ...])``: its parser, option checks, outputs and files) runs as
always, except that an API call with the arguments of an earlier one in this process returns
that call's design, so that two tests -- or two dialects -- asking for the same design share it
(the tests sharing one are in one xdist group).  The written files equal a fresh run's byte for
byte (checked on MB1-artifact, DMU50-sphere and MB1-interferometer, both dialects: every file
of ``--out`` and ``--json``)."""

from __future__ import annotations

import contextlib

#: repr of the API call's arguments -> its Plan
_DESIGNS: dict = {}


@contextlib.contextmanager
def designed_once():
    """``volerr.plan.api.plan`` (the function the command calls) replaced, for the block, by
    one that designs each request once per process."""
    import pytest

    import volerr.plan.api

    plan = volerr.plan.api.plan

    def once(*args, **kwargs):
        key = repr((args, sorted(kwargs.items())))
        if key not in _DESIGNS:
            _DESIGNS[key] = plan(*args, **kwargs)
        return _DESIGNS[key]

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(volerr.plan.api, "plan", once)
        yield
