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


class progress_bar:
    """``with progress_bar(path, what) as tick:`` -- a ``tqdm`` bar over the lines of the
    file ``path`` (total estimated from its size and first lines) on stderr when stderr is a
    terminal; ``tick(n)`` advances it by ``n`` lines.  Off a terminal ``tick`` does nothing
    (no bar in logs and pipes)."""

    def __init__(self, path, what: str, total=None, unit: str = "lines"):
        self.path, self.what, self.total, self.unit = path, what, total, unit
        self.bar = None

    def __enter__(self):
        if not on_terminal():
            return lambda n: None
        try:
            from tqdm import tqdm
        except ImportError:  # pragma: no cover
            return lambda n: None
        total = self.total
        if total is None and self.path is not None:
            total = _estimated_lines(self.path)
        self.bar = tqdm(total=total, file=sys.stderr, leave=False, unit=self.unit,
                        unit_scale=True, desc=self.what)
        return self.bar.update

    def __exit__(self, *exc):
        if self.bar is not None:
            self.bar.close()
        return False


def _estimated_lines(path) -> int | None:
    """Lines of a text file, estimated from its size and the length of its first lines."""
    from pathlib import Path

    try:
        size = Path(path).stat().st_size
        with open(path, "rb") as fh:
            head = fh.read(65536)
    except OSError:
        return None
    n = head.count(b"\n") or head.count(b"\r")
    if not n:
        return None
    return int(round(size / (len(head) / n)))
