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


#: the sections by their CPU time on the demo's data, longest first (measured with cProfile
#: on main, 2026-12-07): the order the workers take them in, so that the two halves end
#: together (longest processing time first)
BY_COST = ("loop", "check", "audit", "fiveaxis", "cmm_a", "plan", "cmm_b", "multilateration",
           "identify", "ballbar", "rotary", "probe", "ballplate", "uncertainty", "iso230_2")


def _settle(on: bool = True) -> None:
    """Collect the garbage, then set every object alive (modules, models, the sections' kept
    results) aside from the cyclic garbage collector (``gc.freeze``): its full collections,
    triggered while the figures are built, then scan the objects made since instead of the
    whole heap again (14 full collections of 0.2-0.4 s each in a run of all sections in one
    process).  Nothing alive is lost and no garbage is kept: :func:`demo` puts the objects
    back (``gc.unfreeze``) at the end.  Called before each section, before the outputs are
    written, and in the parent before the worker processes are forked (the Python
    documentation's advice: the workers then leave the inherited pages alone).  ``on``
    False: nothing (the caller of :func:`demo` froze objects itself; its freeze is left
    alone)."""
    import gc

    if on:
        gc.collect()
        gc.freeze()


def _section(name: str, flush: bool = False, settle: bool = True) -> dict:
    """Run section ``name`` in the current folder; with ``flush`` write its outputs now (a
    worker process: its figures cannot travel back); ``settle``: :func:`_settle` first."""
    from .work import Work

    _settle(settle)
    w = Work(Path("."))
    t = time.perf_counter()
    r = _steps(w)[name]()
    if flush:
        w.flush()
    r["section"] = name
    r["seconds"] = round(time.perf_counter() - t, 1)
    return r if flush else (r, w)


def _in_order(todo: list, progress, settle: bool) -> list:
    """The sections one after the other, their outputs written after the last one."""
    results, works = [], []
    for name in todo:
        progress.set_postfix_str(name)
        r, w = _section(name, settle=settle)
        progress.update()
        results.append(r)
        works.append(w)
    _settle(settle)
    for w in works:
        w.flush()
    return results


def _in_parallel(todo: list, progress, jobs: int, settle: bool) -> list:
    """The sections in ``jobs`` forked worker processes (each writes its own files into the
    staged folder), longest first (:data:`BY_COST`); the results in the order of ``todo``."""
    import multiprocessing
    from concurrent.futures import ProcessPoolExecutor, as_completed

    from ..machine.model import load
    from ..plotstyle import pyplot

    pyplot()          # imported once here, before the fork, not once in every worker
    load("MB1")
    _import_shared(todo)
    order = sorted(todo, key=lambda n: BY_COST.index(n) if n in BY_COST else -1)
    _settle(settle)
    ctx = multiprocessing.get_context("fork")
    with ProcessPoolExecutor(jobs, mp_context=ctx) as pool:
        futures = {pool.submit(_section, name, True, settle): name for name in order}
        for f in as_completed(futures):
            progress.set_postfix_str(futures[f])
            progress.update()
        done = {name: f.result() for f, name in futures.items()}
    return [done[name] for name in todo]


#: the sections that calibrate (``volerr.calibrate``, the fit's chi-square test of
#: scipy.stats; ``plan`` and ``check`` the plans too)
CALIBRATING = ("rotary", "ballplate", "multilateration", "plan", "check")


def _import_shared(todo: list) -> None:
    """Import, before the fork, what sections in both workers import (the calibration, the
    plans, the fit's chi-square test): once in the parent, about 1 s of CPU, instead of once
    per worker; nothing when fewer than two sections of ``todo`` calibrate."""
    if sum(name in CALIBRATING for name in todo) < 2:
        return
    import scipy.stats  # noqa: F401  (volerr.fit_quality's p-values)

    from ..calibrate import run  # noqa: F401
    from ..plan import api  # noqa: F401


def _jobs(jobs, todo: list) -> int:
    """Worker processes: ``jobs``, or by default one per core up to 2; 1 where fork is
    missing (the sections then run in this process)."""
    import multiprocessing
    import os

    if "fork" not in multiprocessing.get_all_start_methods():
        return 1
    n = min(2, os.cpu_count() or 1) if jobs is None else int(jobs)
    require(n >= 1, f"--jobs {jobs}: give 1 or more worker processes")
    return min(n, len(todo))


def demo(out="volerr-demo", *, only=None, force: bool = False, jobs: int | None = None) -> Demo:
    """The whole pipeline on built-in data (``volerr demo``): every section of
    :data:`volerr.demo.text.SECTIONS` through the Python API, then ``index.html`` (a section
    per step, its figures, captions and headline) and ``summary.json``.

    Parameters
    ----------
    out : path
        The output folder: new, empty, or (with ``force``) one whose files may be replaced.
        Everything is written into a staged folder put in place at the end, all or nothing.
    only : sequence of str, optional
        Run only these sections (names of ``SECTIONS``), reported in this order.
    force : bool
        Replace the demo's files in a folder that holds files.
    jobs : int, optional
        Worker processes for the sections (default: one per core, at most 2; 1: all in this
        process, the figures kept in memory until the last section is done).  The files
        written do not depend on it.

    Returns
    -------
    Demo
        ``summary()`` the console text; ``data`` the sections (headlines with units in their
        text: um, urad, mm; ``seconds`` each section's wall time, s).
    """
    import gc
    import os

    from ..fileio import Outputs, json_text, write_text
    from ..progress import bar
    from .page import index_html

    todo = list(only) if only else list(SECTIONS)
    bad = [s for s in todo if s not in SECTIONS]
    require(not bad, f"--only {bad[0] if bad else ''}: not a section ({', '.join(SECTIONS)})")
    n_jobs = _jobs(jobs, todo)
    final = Path(out)
    outs = Outputs(force=force).folder("--out", final).check()
    refuse_used_folder(final, force)
    t0, here = time.perf_counter(), os.getcwd()
    settle = gc.get_freeze_count() == 0  # the caller's own gc.freeze (if any) left alone
    with outs:
        os.chdir(outs.path("--out"))  # relative paths: the reports name files as they will be
        try:                          # found
            progress = bar(len(todo), "volerr demo", unit="section")
            results = (_in_parallel(todo, progress, n_jobs, settle) if n_jobs > 1
                       else _in_order(todo, progress, settle))
            progress.close()
            index_html(Path("."), results)
            write_text(Path("summary.json"), json_text(results))
        finally:
            os.chdir(here)
            if settle:
                gc.unfreeze()         # what _settle set aside: the collector's again
    return Demo(results, final, time.perf_counter() - t0)
