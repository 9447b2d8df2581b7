"""With ``NESTED_BAND`` set (1: the candidate; log: an observer, nothing changed) and this
folder on PYTHONPATH, every python process (the drivers and the CLI they start) runs with
nested_band.py's patch (RULE.md)."""
import os

if os.environ.get("NESTED_BAND"):
    import nested_band
    nested_band.install()
