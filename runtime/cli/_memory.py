"""Process memory policy of the ``volerr`` command (not of the library): glibc's malloc serves
the 0.1-10 MB arrays of every block with fresh ``mmap`` pages or trims the heap after each free,
so every block pays page faults again (a 10^6-point map: 94 000 minor faults, 0.4-0.6 s of
system time of ~1.8 s).  Higher mmap and trim thresholds keep freed blocks for reuse (13 500
faults, same peak RSS).  A choice for the whole process, which a library imported by somebody
else's program must not make; other C libraries: nothing is done."""

from __future__ import annotations

import ctypes
import ctypes.util

#: glibc mallopt parameters (malloc.h) and the values set
_M_TRIM_THRESHOLD, _M_MMAP_THRESHOLD = -1, -3
MMAP_THRESHOLD = 64 * 2 ** 20
TRIM_THRESHOLD = 256 * 2 ** 20

_done = False


def keep_freed_blocks() -> bool:
    """Set the thresholds once per process; True when glibc took them."""
    global _done
    if not _done:
        try:
            mallopt = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6").mallopt
        except (OSError, AttributeError):       # not glibc (musl, macOS, Windows)
            return False
        mmap_taken = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
        _done = mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1 and mmap_taken
    return _done
