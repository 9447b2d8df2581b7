"""Helpers of the tutorials: a scratch folder with the example files (``volerr examples``)."""

import os
import tempfile
from pathlib import Path


def examples() -> Path:
    """A temporary folder holding every example file; the current directory becomes it."""
    from volerr.example_files import write_examples

    d = Path(tempfile.mkdtemp(prefix="volerr-tutorial-"))
    write_examples(d)
    os.chdir(d)
    return d
