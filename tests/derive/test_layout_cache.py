"""The on-disk cache of modules derived for layout files (volerr.machine.derivation): a second
load reads the entry without sympy; another layout text gets another entry; a corrupt entry is
ignored and rewritten."""

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from volerr.machine import layout as layout_mod

#: the first load (a derivation, ~3 s of CPU in its own process) once, on one xdist worker
pytestmark = pytest.mark.xdist_group("layout_cache")

LOAD = ("import sys, numpy as np, volerr; m = volerr.load(sys.argv[1]); "
        "e = m.volumetric_error([[100.0, 200.0, 300.0]], {'EXX': 1e-3, 'EYY': 2e-3}); "
        "print('sympy' in sys.modules, repr(e[0].tolist()))")


def _layout(tmp_path: Path, name="MYCMM", extra="") -> Path:
    src = Path(layout_mod.__file__).parent.parent / "layouts" / "MB1.toml"
    text = src.read_text()
    lines = [f'name = "{name}"' if ln.startswith("name =") else ln for ln in text.splitlines()]
    p = tmp_path / f"{name.lower()}.toml"
    p.write_text("\n".join(lines) + "\n" + extra)
    return p


def _load(path, cache):
    env = {**os.environ, "VOLERR_CACHE_DIR": str(cache)}
    r = subprocess.run([sys.executable, "-c", LOAD, str(path)], capture_output=True, text=True,
                       env=env, check=True)
    used_sympy, value = r.stdout.split(" ", 1)
    return used_sympy == "True", value.strip()


@pytest.fixture(scope="module")
def first_load(tmp_path_factory):
    """(cache folder, (used sympy, value)) of the first load of the layout of :func:`_layout`
    into an empty cache; each test loads from its own copy of the folder (the key is the
    layout text's sha256, not its path)."""
    root = tmp_path_factory.mktemp("first_load")
    cache = root / "cache"
    return cache, _load(_layout(root), cache)


def _cache_copy(first_load, tmp_path) -> Path:
    cache = tmp_path / "cache"
    shutil.copytree(first_load[0], cache)
    return cache


def test_second_load_reads_the_cache_without_sympy(tmp_path, first_load):
    cache = _cache_copy(first_load, tmp_path)
    path = _layout(tmp_path)
    first = first_load[1]
    assert first[0], "the first load derives (sympy)"
    entries = list(cache.glob("*.py"))
    assert len(entries) == 1 and entries[0].name.startswith("mycmm-")
    second = _load(path, cache)
    assert second == (False, first[1])        # no sympy, same numbers
    # and the numbers are the model's: positioning errors alone move the probe along the axes
    assert eval(first[1]) == [1e-3, 2e-3, 0.0]


def test_changed_layout_text_gets_a_new_entry(tmp_path, first_load):
    cache = _cache_copy(first_load, tmp_path)   # the first load of this layout text
    path = _layout(tmp_path)
    assert len(list(cache.glob("*.py"))) == 1
    path.write_text(path.read_text() + "\n# a comment changes the text, hence the key\n")
    used, _ = _load(path, cache)
    assert used
    assert len(list(cache.glob("*.py"))) == 2


def _flip(text: str, i: int) -> str:
    return text[:i] + ("1" if text[i] != "1" else "2") + text[i + 1:]


def test_corrupt_entry_is_rebuilt(tmp_path, first_load):
    cache = _cache_copy(first_load, tmp_path)   # the first load of this layout text
    path = _layout(tmp_path)
    value = first_load[1][1]
    (entry,) = cache.glob("*.py")
    good = entry.read_text()
    for bad in (good[: len(good) // 2], "not python at all (\n", _flip(good, len(good) // 3)):
        assert bad != good
        entry.write_text(bad)
        used, again = _load(path, cache)
        assert used, bad[:200]
        assert again == value          # derived again, same numbers
        assert entry.read_text() == good        # and the entry rewritten whole
    assert not [p for p in cache.iterdir() if p.suffix == ".tmp"]


def test_cache_is_outside_the_package(tmp_path, monkeypatch):
    from volerr.machine import derivation

    monkeypatch.delenv("VOLERR_CACHE_DIR", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert derivation.cache_dir() == tmp_path / "xdg" / "volerr"
    monkeypatch.setenv("VOLERR_CACHE_DIR", str(tmp_path / "c"))
    assert derivation.cache_dir() == tmp_path / "c"
