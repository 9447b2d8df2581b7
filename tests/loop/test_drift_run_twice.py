"""A run given twice (the same file twice, or a copy under another name held out) would be
judged on its own readings: refused with one line naming both, nothing written.  A run whose
channel is in mm under its ``_um`` header (1000x small against the other runs) likewise."""

from __future__ import annotations

import shutil

import numpy as np

from helpers import in_process


def _run_file(path, seed: int) -> None:
    rng = np.random.default_rng(seed)
    t = np.arange(0.0, 4 * 3600.0, 60.0)
    heat = 1 - np.exp(-t / 1800.0)
    T1 = 20 + 3 * heat + 0.02 * rng.standard_normal(len(t))
    T2 = 20 + 0.5 * np.sin(t / 5000.0) + 0.02 * rng.standard_normal(len(t))
    d = 4 * heat + 0.3 * rng.standard_normal(len(t))
    rows = ["t_s,d_X_um,T_spindle,T_room"] + [f"{a:g},{b:.4f},{c:.4f},{e:.4f}"
                                              for a, b, c, e in zip(t, d, T1, T2)]
    path.write_text("# channel d_X: X\n" + "\n".join(rows) + "\n")


def _loop(tmp_path, *args):
    """``volerr ARGS`` in this process (``helpers.in_process``: ``main``'s exit code and
    lines; a warning a process would print is appended to stderr), without starting an
    interpreter; the entry point's own process is tests/cli/test_cli_core.py's."""
    return in_process.volerr("loop", "DMU50", *args, "--json", tmp_path / "out.json",
                             cwd=tmp_path)


def test_a_copy_held_out_is_refused_naming_both(tmp_path):
    for i in range(3):
        _run_file(tmp_path / f"day{i}.csv", i)
    shutil.copy(tmp_path / "day0.csv", tmp_path / "day9.csv")
    files = [f"drift:{tmp_path / f'day{i}.csv'}" for i in (0, 1, 2, 9)]
    r = _loop(tmp_path, *files, "--holdout-files", tmp_path / "day9.csv")
    assert r.returncode == 2, r.stdout
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "day9.csv" in err[0] and "day0.csv" in err[0], err
    assert "given twice" in err[0]
    assert not (tmp_path / "out.json").exists()


def test_the_same_file_twice_is_refused(tmp_path):
    for i in range(2):
        _run_file(tmp_path / f"day{i}.csv", i)
    f0, f1 = (f"drift:{tmp_path / f'day{i}.csv'}" for i in (0, 1))
    r = _loop(tmp_path, f0, f1, f0)
    assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
    assert "day0.csv" in r.stderr and "given twice" in r.stderr


def test_distinct_runs_pass(tmp_path):
    for i in range(3):
        _run_file(tmp_path / f"day{i}.csv", i)
    files = [f"drift:{tmp_path / f'day{i}.csv'}" for i in range(3)]
    r = _loop(tmp_path, *files, "--holdout-files", tmp_path / "day2.csv")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "out.json").exists()


def test_a_run_in_mm_under_the_um_header_is_refused(tmp_path):
    """One day's channel written in mm (values 1000x small) among days in um: one line naming
    that file and the likely mistake; nothing written."""
    for i in range(4):
        _run_file(tmp_path / f"day{i}.csv", i)
    lines = (tmp_path / "day2.csv").read_text().splitlines()
    head, rows = lines[:2], [r.split(",") for r in lines[2:]]
    rows = [[a, f"{float(b) / 1000:.7f}", c, e] for a, b, c, e in rows]
    (tmp_path / "day2.csv").write_text("\n".join(head + [",".join(r) for r in rows]) + "\n")
    files = [f"drift:{tmp_path / f'day{i}.csv'}" for i in range(4)]
    r = _loop(tmp_path, *files, "--holdout-files", tmp_path / "day3.csv")
    assert r.returncode == 2, r.stdout
    err = r.stderr.strip().splitlines()
    assert len(err) == 1 and "day2.csv" in err[0] and "mm" in err[0], err
    assert not (tmp_path / "out.json").exists()
