"""One full ``volerr audit --json --html`` run shared by the tests that need every verdict
(the full audit takes tens of seconds): the tests that use it run in one xdist group.

The run also hands each provider's own verdicts to the provider's test module
(:func:`provider_verdicts`): a module's verdicts are those its provider returned inside the
command, on the same printed material, instead of a second derivation of the same equations
(the tracker's alone takes ~30 s of CPU).  Those modules are in the ``full_audit`` group."""

from __future__ import annotations

import contextlib
import copy
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
    from volerr.derive.audit import providers

    d = tmp_path_factory.mktemp("full_audit")
    js, page = d / "all.json", d / "all.html"
    out, err = io.StringIO(), io.StringIO()
    with pytest.MonkeyPatch.context() as mp:
        for m in providers():     # the command calls each provider's audit once: recorded
            mp.setattr(m, "audit", _recording(m.__name__, m.audit))
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(["audit", "--json", str(js), "--html", str(page)])
    r = SimpleNamespace(returncode=code, stdout=out.getvalue(), stderr=err.getvalue())
    assert r.returncode == 0, r.stderr
    return r, json.loads(js.read_text("utf-8")), page.read_text("utf-8")


#: provider module name -> [(printed, layouts, verdicts)] of its calls inside the full audit
_SEEN: dict = {}


def _recording(name, audit):
    """``audit`` that also keeps its arguments (a copy taken before the call) and verdicts."""
    def recorded(printed, layouts=None):
        before = copy.deepcopy(printed)
        verdicts = audit(printed, layouts)
        _SEEN.setdefault(name, []).append((before, layouts, verdicts))
        return verdicts
    return recorded


@pytest.fixture(scope="session")
def provider_verdicts(full_audit):
    """``verdicts(module, printed, layouts=None)``: the verdicts ``module.audit(printed,
    layouts)`` returned inside the full audit when it was called there with equal printed
    material and layouts, else a call of its own (never a verdict of other input)."""
    def verdicts(module, printed, layouts=None):
        for seen, seen_layouts, out in _SEEN.get(module.__name__, []):
            if seen == printed and seen_layouts == layouts:
                return out
        return module.audit(printed, layouts)
    return verdicts
