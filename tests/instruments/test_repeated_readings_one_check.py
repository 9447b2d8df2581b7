"""One check of a reading given twice (:func:`volerr.fileio.refuse_repeated_readings`)
for both readers of a positioning run: ``volerr iso230-2`` (long format) and the
``interferometer`` instrument of ``volerr calibrate``.  Both name the target, the cycle, the
direction, the two places and the likely mistake (a row or a block pasted twice), one line,
exit 2, nothing written."""

from __future__ import annotations

import pytest

from volerr.cli import main
from volerr.errors import InputError
from volerr.fileio import refuse_repeated_readings

ROWS = [f"{t},{c},{d},{0.1 * c + 0.01 * t}" for t in (0, 100, 200) for c in (1, 2, 3)
        for d in ("+1", "-1")]
HEAD = "target_mm,cycle,direction,deviation_um"


def _error_line(capsys, rc) -> str:
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    return err.strip()


def test_iso230_2_and_interferometer_refuse_alike(tmp_path, capsys):
    body = "\n".join(ROWS + [ROWS[2]]) + "\n"         # 0,2,+1 pasted again at the end
    run = tmp_path / "run.csv"
    run.write_text(f"{HEAD}\n{body}")
    out = tmp_path / "o.json"
    iso = _error_line(capsys, main(["iso230-2", str(run), "--json", str(out)]))
    lx = tmp_path / "lx.csv"
    lx.write_text(f"# axis: X\n# u_um: 1\n{HEAD}\n{body}")
    cal = _error_line(capsys, main(["calibrate", "MB1", str(lx), "--json", str(out)]))
    assert not out.exists()
    for line in (iso, cal):
        assert "duplicate reading: target 0 mm, cycle 2, forward already given on" in line
        assert line.endswith("(a row or a block pasted twice?)")
    # iso230-2 counts the file's lines, the instrument its data rows (header = row 1)
    assert f"run.csv:{len(ROWS) + 2}: " in iso and "line 4 " in iso
    assert f"lx.csv: row {len(ROWS) + 2}: " in cal and "row 4 " in cal


def test_rule_of_the_check():
    """Targets equal within 1 nm are one target; another cycle or direction is another
    reading; cycle labels compare as text."""
    refuse_repeated_readings([0.0, 0.0, 0.0], [1, -1, 1], ["1", "1", "2"], "f")
    refuse_repeated_readings([0.0, 2e-6], [1, 1], ["1", "1"], "f")
    with pytest.raises(InputError, match=r"^f: row 4: duplicate reading: target 4e-07 mm, "
                                         r"cycle 1, backward already given on row 2 "):
        refuse_repeated_readings([0.0, 0.0, 4e-7], [-1, -1, -1], ["1", "2", "1"], "f")
