"""One full ``volerr audit --json --html`` run shared by the tests that need every verdict
(the full audit takes tens of seconds): the tests that use it run in one xdist group."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest


@pytest.fixture(scope="session")
def full_audit(tmp_path_factory):
    """(completed process, JSON entries, HTML page) of ``volerr audit --json F --html F``."""
    d = tmp_path_factory.mktemp("full_audit")
    js, page = d / "all.json", d / "all.html"
    r = subprocess.run([sys.executable, "-m", "volerr", "audit", "--json", str(js),
                        "--html", str(page)], capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    return r, json.loads(js.read_text("utf-8")), page.read_text("utf-8")
