"""Progress of compensate and tcpmap: chunk by chunk to the callback; a tqdm bar on stderr only
when stderr is a terminal."""

import io
import sys

from volerr.cli._common import progress_bar
from volerr.fiveaxis import program
from volerr.fiveaxis.program import _Collect

import volerr


def test_progress_counts_every_line():
    m = volerr.load("DMU50")
    text = "G90 G1 X0 Y0 Z100 B10 C0\n" + "".join(f"X{k} Y1\n" for k in range(25))
    seen = []
    program.run(lambda: io.StringIO(text, newline=""), m, None, program.Options(),
                _Collect(m), chunk_lines=7, progress=seen.append)
    assert sum(seen) == 26 and len(seen) == 4


class _Tty(io.StringIO):
    def isatty(self):
        return True


def test_bar_only_on_a_terminal(monkeypatch, tmp_path):
    prog = tmp_path / "p.nc"
    prog.write_text("X1\n" * 1000)
    plain = io.StringIO()
    monkeypatch.setattr(sys, "stderr", plain)
    with progress_bar(prog, "compensate") as tick:
        tick(500)
    assert plain.getvalue() == ""
    tty = _Tty()
    monkeypatch.setattr(sys, "stderr", tty)
    with progress_bar(prog, "compensate") as tick:
        tick(1000)
    assert "compensate" in tty.getvalue() and "1.00k" in tty.getvalue()
