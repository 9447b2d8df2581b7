"""One full ``volerr audit --json --html`` run shared by the tests that need every verdict
(the full audit takes tens of seconds): the tests that use it run in one xdist group."""

from __future__ import annotations

import contextlib
import io
import json
from types import SimpleNamespace

import pytest


@pytest.fixture(scope="session")
def full_audit(tmp_path_factory):
    """(completed command: returncode, stdout, stderr; JSON entries; HTML page) of ``volerr
    audit --json F --html F``, through ``volerr.cli.main`` in this process (the command's parser
    and exit code, without a fresh interpreter importing sympy again)."""
    from volerr.cli import main

    d = tmp_path_factory.mktemp("full_audit")
    js, page = d / "all.json", d / "all.html"
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(["audit", "--json", str(js), "--html", str(page)])
    r = SimpleNamespace(returncode=code, stdout=out.getvalue(), stderr=err.getvalue())
    assert r.returncode == 0, r.stderr
    return r, json.loads(js.read_text("utf-8")), page.read_text("utf-8")
