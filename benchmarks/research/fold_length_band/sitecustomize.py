"""With ``FOLD_LENGTH=1`` and this folder on PYTHONPATH, every python process (the drivers
and the CLI they start) runs with fold_length.py's patch (RULE.md)."""
import os

if os.environ.get("FOLD_LENGTH"):
    import fold_length
    fold_length.install()
