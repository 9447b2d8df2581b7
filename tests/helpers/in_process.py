"""``volerr ARGS`` through ``volerr.cli.main`` in the test's own process (issue 42 item 7).

A ``python -m volerr`` subprocess costs an interpreter start and the imports of numpy, scipy,
sympy ... (0.5-1 s of CPU each); where a test checks the command's parser, files, exit code and
the text it prints -- not the process itself (startup imports: tests/cli/test_startup.py; a
real process's signals or environment) -- :func:`volerr` is the same claim:
``python -m volerr`` is ``sys.exit(volerr.cli.main())``, whose exit code and stderr lines come
from ``main``.  Two things a process shows that ``main`` alone would hide are put back:

* warnings (a ``RuntimeWarning`` of numpy ...) are printed to stderr by a process; pytest would
  collect them instead.  They are recorded here and appended to ``stderr`` in the text Python
  prints them in, so a test that wants one error line still fails on a stray warning (the
  categories Python hides by default outside ``__main__`` -- ``DeprecationWarning``,
  ``PendingDeprecationWarning``, ``ImportWarning`` -- are left to pytest, as a process hides
  them);
* an exception ``main`` does not turn into its one line would print a traceback and exit 1;
  here it propagates and fails the test (no less strict).

BLAS runs on one thread here as in the tests' subprocesses (tests/conftest.py sets it for every
test process and the processes they start)."""

from __future__ import annotations

import contextlib
import io
import warnings
from types import SimpleNamespace

#: warning categories a Python process does not print by default (outside ``__main__``)
HIDDEN = (DeprecationWarning, PendingDeprecationWarning, ImportWarning)


def volerr(*args, cwd=None) -> SimpleNamespace:
    """``volerr ARGS`` in this process: ``returncode``, ``stdout``, ``stderr`` (str), as
    ``subprocess.run([sys.executable, "-m", "volerr", *ARGS], capture_output=True,
    text=True)`` gives them.  ``cwd``: the working directory of the run (restored after)."""
    from volerr.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.ExitStack() as stack:
        if cwd is not None:
            stack.enter_context(contextlib.chdir(cwd))
        seen = stack.enter_context(warnings.catch_warnings(record=True))
        warnings.simplefilter("default")
        for category in HIDDEN:
            warnings.simplefilter("ignore", category)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main([str(a) for a in args])
    shown = "".join(warnings.formatwarning(w.message, w.category, w.filename, w.lineno, w.line)
                    for w in seen)
    return SimpleNamespace(returncode=code, stdout=out.getvalue(),
                           stderr=err.getvalue() + shown)
