"""A ballbar file whose trace (or whole content) is pasted into it a second time is refused
(one line naming the file and the rows; nothing written): without it the copy was cut into
two more traces of the same placement, every reading counted twice and the diagnosis'
standard uncertainties shrank by sqrt 2 (EC0Y +19.3 +/- 0.50 -> +/- 0.35 urad on the shipped
example).  ISO 230-4:2005 circular tests; formats.md "Ballbar traces"."""

from __future__ import annotations

from importlib import resources

import pytest

from volerr.cli import main


def example_lines() -> list[str]:
    text = (resources.files("volerr") / "data" / "ballbar_example_XY.csv").read_text()
    return text.splitlines()


def refused_one_line(capsys, rc, *words):
    err = capsys.readouterr().err.strip().splitlines()
    assert rc == 2 and len(err) == 1, err
    for w in words:
        assert w in err[0], err[0]


def test_ballbar_file_pasted_twice_refused(tmp_path, capsys):
    lines = example_lines()
    f = tmp_path / "bb.csv"
    f.write_text("\n".join(lines + lines[1:]) + "\n")
    out = tmp_path / "b.json"
    rc = main(["ballbar", "evaluate", str(f), "--json", str(out)])
    refused_one_line(capsys, rc, "bb.csv", f"rows {len(lines) + 1} ..", "pasted twice")
    assert not out.exists()


def test_ballbar_trace_pasted_twice_with_placement_refused(tmp_path, capsys):
    """With a placement column the copy falls into the same trace: still refused."""
    lines = example_lines()
    rows = [r + ",P1" for r in lines[1:]]
    ccw = rows[:180]                       # the counter-clockwise trace, pasted again
    f = tmp_path / "bbp.csv"
    f.write_text("\n".join([lines[0] + ",placement"] + ccw + ccw + rows[180:]) + "\n")
    out = tmp_path / "c.json"
    rc = main(["calibrate", "MB1", str(f), "--json", str(out)])
    refused_one_line(capsys, rc, "bbp.csv", "rows 182 ..", "repeat rows 2 ..")
    assert not out.exists()


@pytest.mark.parametrize("copies", [1, 2])
def test_ballbar_one_row_repeated_is_not_a_pasted_block(tmp_path, capsys, copies):
    """The shipped file, and the file with one row repeated in place (a quantised reading met
    again), are read: only a block of readings repeated is refused."""
    lines = example_lines()
    body = lines[1:] if copies == 1 else lines[1:6] + [lines[5]] + lines[6:]
    f = tmp_path / "ok.csv"
    f.write_text("\n".join([lines[0]] + body) + "\n")
    assert main(["ballbar", "evaluate", str(f), "--json", str(tmp_path / "o.json")]) == 0
