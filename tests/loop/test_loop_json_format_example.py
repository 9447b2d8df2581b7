"""formats.md's loop report JSON example is what ``volerr loop MB1 deviations_MB1.csv
--out-dir D --json F`` writes for the example file of ``volerr examples``.  The page showed
600 points, RMS 2.1 -> 0.4 um and ``"KT_X": 1.1e-05`` (a value per kelvin without its unit)
where the command writes 400 points, 9.54 -> 0.54 um and ``"KT_X": 11.5`` in ``um/m/K``
(journey pass, 2026-12-07)."""

from __future__ import annotations

import json
import re
from pathlib import Path

from volerr.cli import main

PAGE = Path(__file__).resolve().parents[2] / "docs" / "formats.md"


def test_loop_json_example_is_the_shipped_example(tmp_path):
    assert main(["examples", "--out", str(tmp_path / "ex")]) == 0
    assert main(["loop", "MB1", str(tmp_path / "ex" / "deviations_MB1.csv"), "--out-dir",
                 str(tmp_path / "D"), "--json", str(tmp_path / "l.json")]) == 0
    d = json.loads((tmp_path / "l.json").read_text())
    e, = d["effects"]
    page = re.sub(r"\s+", " ", PAGE.read_text(encoding="utf-8"))
    expected = (f'{{"layout": "MB1", "n_points": {d["n_points"]}, "rms_before_um": '
                f'{d["rms_before_um"]:.3g}, "rms_after_um": {d["rms_after_um"]:.2g}, '
                f'"max_before_um": {d["max_before_um"]:.3g}, "max_after_um": '
                f'{d["max_after_um"]:.3g}, "effects": [{{"kind": "{e["kind"]}", "name": '
                f'"{e["name"]}", "parameters": {{"KT_X": {e["parameters"]["KT_X"]:.3g}, '
                f'"KT0_X": {e["parameters"]["KT0_X"]:.2g}}}, "units": {{"KT_X": '
                f'"{e["units"]["KT_X"]}", "KT0_X": "{e["units"]["KT0_X"]}"}}')
    assert expected in page, expected
