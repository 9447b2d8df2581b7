"""generated/ is exactly what `volerr derive --all` produces now, and is deterministic."""

import os
import subprocess
import sys
from pathlib import Path

import volerr.generated
from volerr.derive.generate import all_generated

GENERATED = Path(volerr.generated.__file__).parent


def test_generated_folder_is_not_stale():
    want = all_generated()
    have = {p.name for p in GENERATED.glob("*.py") if p.name != "__init__.py"}
    assert have == set(want), f"stale file set: run 'volerr derive --all' ({have ^ set(want)})"
    for name, text in want.items():
        assert (GENERATED / name).read_text(encoding="utf-8") == text, \
            f"generated/{name} is stale: run 'volerr derive --all'"


def test_generation_is_byte_identical_across_hash_seeds(tmp_path):
    outs = []
    for seed in ("0", "4242"):
        out = tmp_path / seed
        env = {**os.environ, "PYTHONHASHSEED": seed}
        subprocess.run([sys.executable, "-m", "volerr", "derive", "MB1", "FH1", "CY",
                        "--out", str(out)], check=True, env=env, capture_output=True)
        outs.append({p.name: p.read_bytes() for p in out.iterdir()})
    assert outs[0] == outs[1] and len(outs[0]) == 3


def test_generated_header_names_layout_file_and_hash():
    from volerr.machine.layout import read_layout

    layout = read_layout("MH2")
    text = (GENERATED / "mh2.py").read_text()
    assert layout.sha256 in text and "MH2.toml" in text
