"""``volerr.demo(out=...)``: every section through the Python API, the pages at the end."""

from __future__ import annotations

import time
from dataclasses import dataclass
from pathlib import Path

from ..errors import require
from ..results import ResultMixin
from .text import SECTIONS


@dataclass(repr=False)
class Demo(ResultMixin):
    """Result of :func:`demo`: ``data`` the sections as ``summary.json`` holds them (``section``,
    ``title``, ``value``: the headline, ``files`` relative to ``out``, ``seconds``: the
    section's wall time, s), ``out`` the folder, ``seconds`` the whole run's wall time, s."""

    data: list
    out: Path
    seconds: float

    def summary(self) -> str:
        """What ``volerr demo`` prints: a line per section, then where the report is."""
        lines = [f"{r['title']}: {r['value']}  [{r['seconds']} s]" for r in self.data]
        return "\n".join(lines + [f"report: {self.out / 'index.html'}  ({self.seconds:.0f} s)"])

    def _rows(self) -> list:
        from ..results import Row

        return [Row(r["section"], r["seconds"], None, "s", None) for r in self.data]


def _steps(w) -> dict:
    """Section name -> the function that runs it on the run's :class:`Work`."""
    from . import calibration_sections as cal, cmm_sections as cmm, machine_sections as mach

    return {"cmm_a": lambda: cmm.cmm(w, "MB1", "CMM A of Pahk"),
            "cmm_b": lambda: cmm.cmm(w, "MH2", "CMM B of Pahk"),
            "audit": lambda: cmm.audit(w), "probe": lambda: cmm.probe(w),
            "identify": lambda: cmm.identify(w), "ballbar": lambda: cal.ballbar(w),
            "rotary": lambda: cal.rotary(w), "ballplate": lambda: cal.ballplate(w),
            "multilateration": lambda: cal.multilateration(w),
            "fiveaxis": lambda: mach.fiveaxis(w), "loop": lambda: mach.loop(w),
            "iso230_2": lambda: mach.iso230_2(w), "uncertainty": lambda: cmm.uncertainty(w),
            "plan": lambda: cal.plan(w), "check": lambda: mach.check(w)}


def refuse_used_folder(folder: Path, force: bool) -> None:
    """Before any computing: the demo writes some hundred files whose names are known only
    once it has run, so a folder that holds any file already is refused without ``force``
    (a second run into the same folder would otherwise compute for 20 s and then refuse)."""
    if force or not folder.is_dir():
        return
    held = sorted(p.name for p in folder.iterdir() if not p.name.startswith(".volerr-"))
    require(not held, f"--out {folder}: the folder holds files already ({held[0]}"
                      f"{f' and {len(held) - 1} more' if len(held) > 1 else ''}); give "
                      f"--force to replace the demo's files, or a new or empty folder")


def demo(out="volerr-demo", *, only=None, force: bool = False, echo=None) -> Demo:
    """The whole pipeline on built-in data (``volerr demo``): every section of
    :data:`volerr.demo.text.SECTIONS` through the Python API, then ``index.html`` (a section
    per step, its figures, captions and headline) and ``summary.json``.

    Parameters
    ----------
    out : path
        The output folder: new, empty, or (with ``force``) one whose files may be replaced.
        Everything is written at the end, all or nothing.
    only : sequence of str, optional
        Run only these sections (names of ``SECTIONS``, in that order of the call).
    force : bool
        Replace the demo's files in a folder that holds files.
    echo : callable, optional
        Called with each section's console line as it is done (the command prints it).

    Returns
    -------
    Demo
        ``summary()`` the console text; ``data`` the sections (headlines with units in their
        text: um, urad, mm).
    """
    import os

    from ..fileio import Outputs, json_text, write_text
    from ..progress import bar
    from .page import index_html
    from .work import Work

    todo = list(only) if only else list(SECTIONS)
    bad = [s for s in todo if s not in SECTIONS]
    require(not bad, f"--only {bad[0] if bad else ''}: not a section ({', '.join(SECTIONS)})")
    final = Path(out)
    outs = Outputs(force=force).folder("--out", final).check()
    refuse_used_folder(final, force)
    results, t0, here = [], time.perf_counter(), os.getcwd()
    with outs:
        os.chdir(outs.path("--out"))  # relative paths: the reports name files as they will be
        try:                          # found
            w = Work(Path("."))
            steps = _steps(w)
            progress = bar(len(todo), "volerr demo", unit="section")
            for name in todo:
                progress.set_postfix_str(name)
                t = time.perf_counter()
                r = steps[name]()
                progress.update()
                r["section"] = name
                r["seconds"] = round(time.perf_counter() - t, 1)
                results.append(r)
                if echo is not None:
                    echo(f"{r['title']}: {r['value']}  [{r['seconds']} s]")
            progress.close()
            w.flush()
            index_html(w.out, results)
            write_text(w.out / "summary.json", json_text(results))
        finally:
            os.chdir(here)
    return Demo(results, final, time.perf_counter() - t0)
