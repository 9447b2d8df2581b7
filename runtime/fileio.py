"""Safe output: never overwrite an input file, create parent folders, write atomically."""

from __future__ import annotations

import csv
import io
import os
import tempfile
from pathlib import Path

from volerr.errors import InputError, require


def check_output(path, inputs=()) -> Path:
    """Refuse an output path that is one of the input files; return it as a Path."""
    out = Path(path)
    require(not out.is_dir(), f"{out} is a folder: give a file name for the output")
    for parent in out.parents:
        if parent.exists():
            require(parent.is_dir(), f"cannot write {out}: {parent} is a file, not a folder")
            break
    for p in inputs:
        if p is None:
            continue
        p = Path(p)
        if p.exists() and out.exists():
            require(not os.path.samefile(out, p), f"refusing to overwrite input file {p}")
        else:
            require(out.resolve() != p.resolve(), f"refusing to overwrite input file {p}")
    return out


def check_plot(path, inputs=()) -> Path:
    """:func:`check_output` for a plot, which must be a ``.png`` file (checked before any write)."""
    out = check_output(path, inputs)
    require(out.suffix.lower() == ".png", f"plot file must end in .png, got {out.name}")
    return out


def check_folder(path) -> Path:
    """An output folder: refuse a path that is an existing file (or lies below one)."""
    d = Path(path)
    require(not d.exists() or d.is_dir(), f"{d} is a file, not a folder")
    for parent in d.parents:
        if parent.exists():
            require(parent.is_dir(), f"cannot write {d}: {parent} is a file, not a folder")
            break
    return d


def write_text(path, text: str, inputs=()) -> Path:
    """Write ``text`` (UTF-8, line endings kept) to ``path`` atomically."""
    return write_bytes(path, text.encode("utf-8"), inputs)


def default_mode() -> int:
    """Permissions of a new file under the current umask (mkstemp alone would give 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_bytes(path, data: bytes, inputs=()) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + rename), refusing inputs."""
    out = check_output(path, inputs)
    try:
        out.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=out.parent, prefix=f".{out.name}.", suffix=".tmp")
    except OSError as exc:
        raise InputError(f"cannot write {out}: {exc.strerror or exc}") from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.chmod(tmp, default_mode())
        os.replace(tmp, out)
    except BaseException as exc:
        if os.path.exists(tmp):
            os.unlink(tmp)
        if isinstance(exc, OSError):
            raise InputError(f"cannot write {out}: {exc.strerror or exc}") from None
        raise
    return out


def read_csv_rows(path, missing: str = "", empty: str = "") -> list:
    """(line number, stripped cells) of every row of a UTF-8 CSV file (a BOM is allowed);
    blank rows and rows whose first cell starts with '#' are skipped.  ``missing``/``empty``:
    the error lines for a file that does not exist / has no rows."""
    path = Path(path)
    require(path.is_file(), missing or f"{path}: no such file")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None
    rows = []
    for lineno, cells in enumerate(csv.reader(io.StringIO(text)), start=1):
        cells = [c.strip() for c in cells]
        if not cells or all(c == "" for c in cells) or cells[0].startswith("#"):
            continue
        rows.append((lineno, cells))
    require(rows, empty or f"{path}: empty file")
    return rows


class AtomicFile:
    """An output written in pieces (streamed) and put in place at the end, all or nothing:
    a temporary file next to ``path``; :meth:`commit` renames it over ``path``,
    :meth:`discard` removes it.  Checked with :func:`check_output` first."""

    def __init__(self, path, inputs=(), mode: str = "wb"):
        self.path = check_output(path, inputs)
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            fd, self.tmp = tempfile.mkstemp(dir=self.path.parent, prefix=f".{self.path.name}.",
                                            suffix=".tmp")
        except OSError as exc:
            raise InputError(f"cannot write {self.path}: {exc.strerror or exc}") from None
        self.fh = os.fdopen(fd, mode)

    def write(self, data) -> None:
        self.fh.write(data)

    def truncate(self) -> None:
        self.fh.seek(0)
        self.fh.truncate()

    def commit(self) -> Path:
        try:
            self.fh.close()
            os.chmod(self.tmp, default_mode())
            os.replace(self.tmp, self.path)
        except OSError as exc:
            self.discard()
            raise InputError(f"cannot write {self.path}: {exc.strerror or exc}") from None
        return self.path

    def discard(self) -> None:
        if not self.fh.closed:
            self.fh.close()
        if os.path.exists(self.tmp):
            os.unlink(self.tmp)
