"""The one exception type for bad user input.

Every public entry point raises :class:`InputError` for input that is wrong (unknown
layout, malformed file, missing column, NaN, degenerate geometry, extrapolation).  The
command line turns it into one line on stderr and exit code 2; nothing else in volerr
catches it.
"""


class InputError(ValueError):
    """Bad input: the message is one line a user can act on."""


def require(condition: bool, message: str) -> None:
    """Raise :class:`InputError` with ``message`` unless ``condition`` holds."""
    if not condition:
        raise InputError(message)


def require_file(path, missing: str, label: str = "") -> None:
    """Raise :class:`InputError` unless ``path`` is a file: ``missing`` when nothing is
    there, '<label>: is a folder, not a file' when a folder is (``label``: the path unless
    given), rather than calling an existing folder missing."""
    from pathlib import Path

    if Path(path).is_dir():
        raise InputError(f"{label or path}: is a folder, not a file")
    require(Path(path).is_file(), missing)
