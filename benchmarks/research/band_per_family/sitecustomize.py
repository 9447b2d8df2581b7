"""With ``BAND_RULE`` set (A or B) and this folder on PYTHONPATH, every python process (the
drivers and the CLI they start) runs with band_rule.py's leverage (RULE.md)."""
import os

if os.environ.get("BAND_RULE"):
    import band_rule
    band_rule.install()
