"""The augmented layout's generated module through the derivation cache (issue 42 item 7):
``volerr loop --out-dir`` writes the module of its augmented layout with
``derivation.derive_source``, which stores it in the cache of ``derive_module``, so that the
refit of that layout file on another day (``volerr loop D/MB1_aug.toml dayB.csv``) loads it
without sympy, and a run that augments the same way writes it without deriving again.  The
text must be the derivation's byte for byte, and an entry derived for the same layout text
under another file name (the module names its layout file) is not taken for it."""

from volerr.derive.seal import unseal
from volerr.machine import derivation
from volerr.machine.layout import layout_text, parse_layout


def _layout(origin):
    text, _ = layout_text("MB1")
    return parse_layout(text.replace('name = "MB1"', 'name = "MB1C"', 1), origin)


def test_derived_once_then_read_back_byte_for_byte(tmp_path, monkeypatch):
    monkeypatch.setenv("VOLERR_CACHE_DIR", str(tmp_path / "cache"))
    lay = _layout("MB1C.toml")
    calls = []
    generate = derivation.generate_source

    def counted(layout):
        calls.append(layout.path)
        return generate(layout)

    monkeypatch.setattr(derivation, "generate_source", counted)
    first = derivation.derive_source(lay)
    whole = unseal(first)                                    # the module, sealed
    assert calls == ["MB1C.toml"] and whole.endswith("}") and " from MB1C.toml.\n" in first
    assert derivation.derive_source(lay) == first            # read back: no second derivation
    assert calls == ["MB1C.toml"]
    # the file loaded later (the refit of the augmented layout) reads the same entry
    mod = derivation.derive_module(_layout("MB1C.toml"))
    assert calls == ["MB1C.toml"] and mod.LAYOUT_SHA256 == lay.sha256
    # the same text under another file name: its module names that file, derived anew
    monkeypatch.setattr(derivation, "generate_source", lambda layout: "derived anew\n")
    assert derivation.derive_source(_layout("other.toml")) == "derived anew\n"


def test_a_corrupt_entry_is_derived_again(tmp_path, monkeypatch):
    monkeypatch.setenv("VOLERR_CACHE_DIR", str(tmp_path / "cache"))
    lay = _layout("MB1C.toml")
    text = "# a module\nLAYOUT_SHA256 = %r\n# from MB1C.toml.\nX = 1\n" % lay.sha256
    monkeypatch.setattr(derivation, "generate_source", lambda layout: text)
    assert derivation.derive_source(lay) == text
    path = derivation.cache_path(lay)
    path.write_text(path.read_text().replace("X = 1", "X = 2"))     # its own hash no more
    again = text.replace("X = 1", "X = 3")
    monkeypatch.setattr(derivation, "generate_source", lambda layout: again)
    assert derivation.derive_source(lay) == again
    monkeypatch.setattr(derivation, "generate_source", lambda layout: "not asked\n")
    assert derivation.derive_source(lay) == again             # the rewritten entry


def test_the_cache_key_holds_every_runtime_derivation_source():
    """A layout module's provenance hashes runtime files (derive.generate.LAYOUT_SOURCES,
    derive.lags.SOURCES); the cache key must hold each of them, or an entry derived before
    one changed is served after it with the other derivation's sha256 (found when an older
    checkout's test read a newer checkout's entry)."""
    from volerr.derive import generate, lags
    from volerr.machine import derivation

    runtime = {s.split("/", 2)[-1] for s in generate.LAYOUT_SOURCES + lags.SOURCES
               if s.startswith("runtime/machine/")}
    assert runtime and runtime <= set(derivation.RUNTIME_SOURCES), runtime


def test_a_changed_runtime_source_changes_the_cache_key(monkeypatch, tmp_path):
    from volerr.machine import derivation

    before = derivation.generator_fingerprint()
    monkeypatch.setattr(derivation, "_FINGERPRINT", None)
    monkeypatch.setattr(derivation, "RUNTIME_SOURCES", ("lags.py",))
    assert derivation.generator_fingerprint() != before
