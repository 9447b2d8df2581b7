"""Issue 42 item 7: ``derivation.fit_source`` derives a layout's reduced module once per
process (a loop run again on the same data augments the layout the same way); another
layout, or the same text under another path, is derived anew, and the text reused is the
one the derivation gives."""

import pytest

from volerr.machine import derivation
from volerr.machine.layout import parse_layout


@pytest.fixture
def counted(monkeypatch):
    import volerr.derive.generate as gen

    calls = []
    original = gen.generate_fit_module

    def counting(layout):
        calls.append(layout.name)
        return original(layout)

    monkeypatch.setattr(gen, "generate_fit_module", counting)
    monkeypatch.setattr(derivation, "_FIT_SOURCES", {})
    return calls, original


def _mb1_text():
    import volerr.machine.layout as L

    return L.shipped_layout_dir().joinpath("MB1.toml").read_text(encoding="utf-8")


def test_same_layout_derived_once(counted):
    calls, original = counted
    lay = parse_layout(_mb1_text(), "a/MB1.toml")
    first = derivation.fit_source(lay)
    again = derivation.fit_source(parse_layout(_mb1_text(), "a/MB1.toml"))
    assert calls == ["MB1"]
    assert again == first == original(lay)


def test_other_text_or_path_derived_anew(counted):
    calls, _ = counted
    text = _mb1_text()
    derivation.fit_source(parse_layout(text, "a/MB1.toml"))
    derivation.fit_source(parse_layout(text, "b/MB1.toml"))
    derivation.fit_source(parse_layout(text + "\n# another text\n", "a/MB1.toml"))
    assert calls == ["MB1", "MB1", "MB1"]


def test_memory_bounded(counted, monkeypatch):
    calls, _ = counted
    monkeypatch.setattr(derivation, "FIT_SOURCES_KEPT", 2)
    lays = [parse_layout(_mb1_text() + f"\n# {i}\n", "MB1.toml") for i in range(3)]
    for lay in lays:
        derivation.fit_source(lay)
    assert len(derivation._FIT_SOURCES) == 2
    derivation.fit_source(lays[0])          # the oldest was let go: derived again
    assert len(calls) == 4
