"""A baseline commit of volerr runnable beside this tree: its source exported with
``git archive`` into a temporary package tree, imported through ``PYTHONPATH`` by the same
interpreter (which wins over this tree's editable install; :func:`which_volerr` checks)."""

import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: the commit the session's performance work started from
BASE = "b32e5c7"


def export(rev: str, dest: Path) -> Path:
    """Package tree of commit ``rev`` under ``dest`` (``dest/pkg/volerr``); returns dest/pkg."""
    src = dest / "src"
    src.mkdir(parents=True)
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", rev], check=True,
                             capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(src)], input=archive, check=True)
    pkg = dest / "pkg"
    shutil.copytree(src / "runtime", pkg / "volerr")
    shutil.copytree(src / "derive", pkg / "volerr" / "derive")
    shutil.copytree(src / "generated", pkg / "volerr" / "generated")
    return pkg


def env_for(pythonpath=None) -> dict:
    env = dict(os.environ)
    if pythonpath:
        env["PYTHONPATH"] = str(pythonpath)
    return env


def which_volerr(pythonpath=None) -> str:
    """Folder of the ``volerr`` package a child process imports."""
    return subprocess.run([sys.executable, "-c", "import volerr; print(volerr.__file__)"],
                          check=True, capture_output=True, text=True, env=env_for(pythonpath),
                          cwd=tempfile.gettempdir()).stdout.strip()
