"""Process memory policy of the ``volerr`` command (not of the library).

The numerical kernels work in blocks: every block allocates and frees arrays of 0.1-10 MB
(temporaries of the generated code, CSV byte matrices).  glibc's malloc serves such sizes with
fresh ``mmap`` pages or trims the heap top after each free, so every block pays page faults
again: on a 10^6-point map 94 000 minor faults, 0.4-0.6 s of system time out of ~1.8 s.
Raising the mmap and trim thresholds keeps freed blocks for reuse (13 500 faults, same peak
RSS).  Only the command sets this -- it is a choice for the whole process, which a library
imported by somebody else's program must not make.  Other C libraries: nothing is done.
"""

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
    if _done:
        return True
    try:
        libc = ctypes.CDLL(ctypes.util.find_library("c") or "libc.so.6")
        mallopt = libc.mallopt
    except (OSError, AttributeError):       # not glibc (musl, macOS, Windows)
        return False
    ok = mallopt(_M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
    ok = mallopt(_M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1 and ok
    _done = ok
    return ok
