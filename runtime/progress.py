"""Progress on a terminal, nothing otherwise: every long step of volerr (audit, loop, demo,
Monte Carlo, derive ...) shows a ``tqdm`` bar on stderr when stderr is a terminal and prints
nothing when it is not (pipes, files, tests).  One place for the rule: :func:`on_terminal`."""

from __future__ import annotations

import sys


def on_terminal() -> bool:
    """True when stderr is an interactive terminal."""
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False


def progress(iterable, total=None, **kw):
    """``tqdm(iterable)`` on stderr when it is a terminal; the plain iterable otherwise."""
    if not on_terminal():
        return iterable
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return iterable
    kw.setdefault("leave", False)
    return tqdm(iterable, total=total, file=sys.stderr, **kw)


class _Quiet:
    """A bar that shows nothing (not on a terminal)."""

    def update(self, n=1):
        pass

    def set_postfix_str(self, *a, **k):
        pass

    def set_description_str(self, *a, **k):
        pass

    def close(self):
        pass

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False


def bar(total: int, desc: str, **kw):
    """A manual ``tqdm`` bar (``update``, ``set_postfix_str``, ``close``) on a terminal; an
    object with the same methods that prints nothing otherwise."""
    if not on_terminal():
        return _Quiet()
    from tqdm import tqdm

    kw.setdefault("leave", False)
    return tqdm(total=total, desc=desc, file=sys.stderr, **kw)
