"""generated/ is exactly what `volerr derive --all` produces now, and is deterministic."""

import os
import subprocess
import sys
from pathlib import Path

import pytest

import volerr.generated
from volerr.derive.generate import all_generated

GENERATED = Path(volerr.generated.__file__).parent

#: the in-process derivation is shared by the module's tests: one worker computes it
pytestmark = pytest.mark.xdist_group("derive_generated")


@pytest.fixture(scope="module")
def derived_here():
    """File name -> text of every generated file, derived in this process (under this
    process's hash seed)."""
    return all_generated()


def _other_hash_seed() -> str:
    """A PYTHONHASHSEED that differs from this process's: a set seed is avoided; an unset one
    is random (one chance in 2**32 of meeting "0"); no randomization means seed 0."""
    own = os.environ.get("PYTHONHASHSEED")
    if own == "0" or (own is None and not sys.flags.hash_randomization):
        return "4242"
    return "0"


def test_generated_folder_is_not_stale(derived_here):
    want = derived_here
    have = {p.name for p in GENERATED.glob("*.py") if p.name != "__init__.py"}
    assert have == set(want), f"stale file set: run 'volerr derive --all' ({have ^ set(want)})"
    for name, text in want.items():
        assert (GENERATED / name).read_text(encoding="utf-8") == text, \
            f"generated/{name} is stale: run 'volerr derive --all'"


def test_generation_is_byte_identical_across_hash_seeds(tmp_path, derived_here):
    """``volerr derive`` in a process with another hash seed writes, byte for byte, what this
    process derived (the second seed is this process's own: one derivation fewer)."""
    seed = _other_hash_seed()
    out = tmp_path / seed
    env = {**os.environ, "PYTHONHASHSEED": seed}
    subprocess.run([sys.executable, "-m", "volerr", "derive", "MB1", "FH1", "CY",
                    "--out", str(out)], check=True, env=env, capture_output=True)
    there = {p.name: p.read_bytes() for p in out.iterdir()}
    assert set(there) == {"mb1.py", "fh1.py", "cy.py"}
    assert there == {name: derived_here[name].encode("utf-8") for name in there}


def test_generated_header_names_layout_file_and_hash():
    from volerr.machine.layout import read_layout

    layout = read_layout("MH2")
    text = (GENERATED / "mh2.py").read_text()
    assert layout.sha256 in text and "MH2.toml" in text
