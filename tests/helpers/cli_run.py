"""``volerr ARGS`` run in the test's process (issue 42 item 7: the suite's time), for tests
that check what the command computes and writes, not how a process behaves (its startup
imports, its exit status as the shell sees it: those tests keep ``subprocess``).

``volerr.cli.main`` is what ``python -m volerr`` calls; here it runs in the folder ``cwd``
(relative file names as the command line gives them), its stdout and stderr captured, with
one BLAS thread (what the tests' processes had with ``OPENBLAS_NUM_THREADS=1``).  A process
costs about a second of CPU before the command starts (importing numpy, scipy, volerr).
"""

from __future__ import annotations

import contextlib
import io
import subprocess


def run(args, cwd) -> subprocess.CompletedProcess:
    """``volerr *args`` in folder ``cwd``: returncode (``main``'s return value), stdout and
    stderr (text), as ``subprocess.run(..., capture_output=True, text=True)`` gives them."""
    from threadpoolctl import threadpool_limits

    from volerr.cli import main

    out, err = io.StringIO(), io.StringIO()
    with threadpool_limits(limits=1), contextlib.chdir(cwd), \
            contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return subprocess.CompletedProcess(list(args), code, out.getvalue(), err.getvalue())
