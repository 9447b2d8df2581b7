"""A full disk, simulated: every file opened for writing (``open``, ``io.open``, ``os.fdopen``)
accepts the first ``room`` bytes and then fails with ``OSError(ENOSPC, "No space left on
device")``, as a write(2) on a full file system does.  Reading is untouched.

Usage (pytest)::

    with full_disk(monkeypatch):
        code = main([...])
"""

from __future__ import annotations

import builtins
import contextlib
import errno
import io
import os


class _FullFile:
    """A writable file object whose writes fail once ``room`` bytes are used."""

    def __init__(self, fh, room: list):
        self._fh, self._room = fh, room

    def write(self, data):
        n = len(data)
        if n > self._room[0]:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC), getattr(self._fh, "name",
                                                                           None))
        self._room[0] -= n
        return self._fh.write(data)

    def writelines(self, lines):
        for line in lines:
            self.write(line)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self._fh.close()
        return False

    def __iter__(self):
        return iter(self._fh)

    def __getattr__(self, name):
        return getattr(self._fh, name)


def _writing(mode) -> bool:
    return any(c in str(mode) for c in "wax+")


@contextlib.contextmanager
def full_disk(monkeypatch, room: int = 0):
    """Patch the openers so that at most ``room`` bytes in all can be written."""
    left = [room]
    real_open, real_fdopen = builtins.open, os.fdopen

    def fake_open(file, mode="r", *args, **kwargs):
        fh = real_open(file, mode, *args, **kwargs)
        return _FullFile(fh, left) if _writing(mode) else fh

    def fake_fdopen(fd, mode="r", *args, **kwargs):
        fh = real_fdopen(fd, mode, *args, **kwargs)
        return _FullFile(fh, left) if _writing(mode) else fh

    with monkeypatch.context() as m:
        m.setattr(builtins, "open", fake_open)
        m.setattr(io, "open", fake_open)
        m.setattr(os, "fdopen", fake_fdopen)
        yield left
