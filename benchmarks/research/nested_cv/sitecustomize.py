"""With ``NESTED_CV=1`` and this folder on PYTHONPATH, every python process (the drivers and
the CLI they start) runs with nested.py's lag residuals (RULE.md)."""
import os

if os.environ.get("NESTED_CV"):
    import nested
    nested.install()
