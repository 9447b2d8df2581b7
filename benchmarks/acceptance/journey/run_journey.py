"""Run every documented volerr command line in a fresh temporary folder and record what a user
sees: exit code, traceback, Python warning, stderr lines, wall time, files written.

Usage: python run_journey.py CASES.txt OUT.tsv
CASES.txt: one case a line, ``name | setup | command`` (setup: ``ex`` copies the example files
of ``volerr examples`` into the folder, ``-`` nothing; the command is a bash line run in the folder
with the venv's ``volerr`` first on PATH).  Lines starting with # are skipped.
"""
from __future__ import annotations

import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

VENV_BIN = Path(sys.executable).parent
EXAMPLES = Path(tempfile.mkdtemp(prefix="journey_ex_")) / "ex"


def _examples() -> Path:
    if not EXAMPLES.exists():
        subprocess.run([str(VENV_BIN / "volerr"), "examples", "--out", str(EXAMPLES)],
                       check=True, capture_output=True)
    return EXAMPLES


def run_case(name: str, setup: str, command: str, keep: Path) -> dict:
    work = Path(tempfile.mkdtemp(prefix="journey_"))
    if "ex" in setup.split(","):
        shutil.copytree(_examples(), work, dirs_exist_ok=True)
    before = {p for p in work.rglob("*")}
    env = dict(os.environ, PATH=f"{VENV_BIN}:{os.environ['PATH']}", COLUMNS="100")
    t0 = time.perf_counter()
    proc = subprocess.run(["bash", "-c", command], cwd=work, env=env, capture_output=True,
                          text=True, timeout=900)
    wall = time.perf_counter() - t0
    new = sorted(str(p.relative_to(work)) for p in set(work.rglob("*")) - before)
    err = proc.stderr
    out_dir = keep / name
    out_dir.mkdir(parents=True, exist_ok=True)
    (out_dir / "stdout.txt").write_text(proc.stdout)
    (out_dir / "stderr.txt").write_text(err)
    (out_dir / "new_files.txt").write_text("\n".join(new) + "\n")
    (out_dir / "cmd.txt").write_text(command + "\n" + str(work) + "\n")
    return {"name": name, "rc": proc.returncode, "tb": "Traceback" in err + proc.stdout,
            "warn": any(w in err for w in ("Warning:", "warnings.warn", "RuntimeWarning")),
            "err_lines": len([l for l in err.splitlines() if l.strip()]),
            "wall_s": round(wall, 2), "n_new": len(new), "work": str(work),
            "err1": err.strip().splitlines()[-1][:160] if err.strip() else ""}


def main() -> None:
    cases = Path(sys.argv[1]).read_text().splitlines()
    out = Path(sys.argv[2])
    keep = out.with_suffix("")
    rows = []
    for line in cases:
        if not line.strip() or line.startswith("#"):
            continue
        name, setup, command = (s.strip() for s in line.split("|", 2))
        row = run_case(name, setup, command, keep)
        rows.append(row)
        print("\t".join(str(row[k]) for k in ("name", "rc", "tb", "warn", "err_lines",
                                                "wall_s", "n_new", "err1")), flush=True)
    cols = ["name", "rc", "tb", "warn", "err_lines", "wall_s", "n_new", "err1", "work"]
    out.write_text("\t".join(cols) + "\n" + "".join(
        "\t".join(str(r[c]) for c in cols) + "\n" for r in rows))


if __name__ == "__main__":
    main()
