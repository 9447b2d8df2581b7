"""Safe output: never overwrite an input or a package file, check every output before
computing, write all outputs of a run at the end, all or nothing.

A command declares its outputs up front in an :class:`Outputs` plan (``file``, ``plot``,
``folder``), calls :meth:`Outputs.check` before any work (writable, not an input, not a file of
the installed package, distinct from each other, a folder's future files included), writes to
the staged paths :meth:`Outputs.path` gives, and :meth:`Outputs.commit` (or leaving the
``with`` block) renames everything into place; any failure removes every staged file and
restores what was replaced.
"""

from __future__ import annotations

import csv
import io
import os
import shutil
import tempfile
from pathlib import Path

from .errors import InputError, require, require_file


def check_output(path, inputs=()) -> Path:
    """Refuse an output path that is one of the input files; return it as a Path."""
    out = Path(path)
    require(str(path).strip() != "", "empty output file name")
    require(not out.is_dir(), f"{out} is a folder: give a file name for the output")
    require(not is_package_file(out) or _staged(out),
            f"refusing to write {out}: it is a file of the installed volerr package")
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
    require(not is_package_file(d) or _staged(d),
            f"refusing to write into {d}: it is a folder of the installed volerr package")
    require(not d.exists() or d.is_dir(), f"{d} is a file, not a folder")
    for parent in d.parents:
        if parent.exists():
            require(parent.is_dir(), f"cannot write {d}: {parent} is a file, not a folder")
            break
    return d


def write_text(path, text: str, inputs=()) -> Path:
    """Write ``text`` (UTF-8, line endings kept) to ``path`` atomically."""
    return write_bytes(path, text.encode("utf-8"), inputs)


def json_text(doc, indent: int = 2, **kwargs) -> str:
    """JSON text of ``doc`` (one trailing newline) without negative zero: every float ``-0.0``
    (a negative value rounded to zero, a product with zero) is written ``0.0``."""
    import json

    def clean(v):
        if isinstance(v, float):
            return v + 0.0
        if isinstance(v, dict):
            return {k: clean(x) for k, x in v.items()}
        if isinstance(v, (list, tuple)):
            return [clean(x) for x in v]
        return v

    return json.dumps(clean(doc), indent=indent, **kwargs) + "\n"


def default_mode() -> int:
    """Permissions of a new file under the current umask (mkstemp alone would give 0600)."""
    mask = os.umask(0)
    os.umask(mask)
    return 0o666 & ~mask


def write_bytes(path, data: bytes, inputs=()) -> Path:
    """Write ``data`` to ``path`` atomically (temporary file + rename), refusing inputs."""
    out = AtomicFile(path, inputs)
    try:
        out.write(data)
    except BaseException as exc:
        out.discard()
        if isinstance(exc, OSError):
            raise InputError(f"cannot write {out.path}: {exc.strerror or exc}") from None
        raise
    return out.commit()


#: the largest magnitude accepted for a number read from a data file (mm, um, urad, deg ...):
#: far beyond any machine, small enough that squares and sums stay finite
MAX_ABS = 1e9


def check_magnitude(value: float, where: str) -> float:
    """Refuse NaN, infinity and magnitudes above :data:`MAX_ABS` (one line)."""
    import math

    require(math.isfinite(value), f"{where} is NaN or infinite")
    require(abs(value) <= MAX_ABS, f"{where} = {value:g} is implausibly large (more than "
                                   f"{MAX_ABS:g} in the file's unit)")
    return value


def check_header(cells, where: str) -> None:
    """Refuse a header with an empty or a repeated column name (the second would be ignored)."""
    names = [c.strip().lower() for c in cells]
    require(all(names), f"{where}: empty column name in header")
    dup = sorted({c for c in names if names.count(c) > 1})
    require(not dup, f"{where}: column {dup[0] if dup else ''!r} appears twice in the header")


#: targets (mm) within this are one target of a positioning run (1 nm)
TARGET_KEY_MM = 1e-6


def refuse_repeated_readings(targets_mm, direction, cycle, where: str, lines=None) -> None:
    """Refuse a positioning run (one reading a row: ``volerr iso230-2``'s long format, the
    ``interferometer`` instrument) in which one target, direction and cycle is read twice
    (a row or a block pasted twice: a copied reading would count twice).  ``targets_mm``
    (n,) mm, equal within :data:`TARGET_KEY_MM`; ``direction`` (n,) +1 forward (approach in
    the positive direction) or -1 backward; ``cycle`` (n,) labels; ``lines``: each reading's
    line in the file (the message says ``where:LINE``), else the data row counted with the
    header as row 1 (``row N``).  The second reading is named, with the first."""
    seen: dict = {}
    for i, key in enumerate(zip((round(float(t) / TARGET_KEY_MM) for t in targets_mm),
                                (1 if float(d) > 0 else -1 for d in direction),
                                (str(c) for c in cycle))):
        if key in seen:
            j = seen[key]
            at, first = ((f"{where}:{lines[i]}", f"line {lines[j]}") if lines is not None
                         else (f"{where}: row {i + 2}", f"row {j + 2}"))
            raise InputError(f"{at}: duplicate reading: target {float(targets_mm[i]):g} mm, "
                             f"cycle {key[2]}, {'forward' if key[1] > 0 else 'backward'} "
                             f"already given on {first} (a row or a block pasted twice?)")
        seen[key] = i


def sniff_delimiter(text: str) -> str:
    """The column separator of a CSV text: ``,`` unless the first line that is neither blank
    nor a ``#`` comment has no comma but a semicolon (``;``, spreadsheet exports with a
    decimal point) or a tab.  Every CSV reader of volerr uses this one rule."""
    for line in text.splitlines():
        if line.strip() and not line.lstrip().startswith("#"):
            if "," in line:
                return ","
            return ";" if ";" in line else "\t" if "\t" in line else ","
    return ","


def read_csv_rows(path, missing: str = "", empty: str = "") -> list:
    """(line number, stripped cells) of every row of a UTF-8 CSV file (a BOM is allowed);
    columns separated by ``,`` (or ``;`` / tab, :func:`sniff_delimiter`); blank rows and rows
    whose first cell starts with '#' are skipped.  ``missing``/``empty``: the error lines for
    a file that does not exist / has no rows."""
    path = Path(path)
    require_file(path, missing or f"{path}: no such file")
    try:
        text = path.read_text(encoding="utf-8-sig")
    except UnicodeDecodeError:
        raise InputError(f"{path}: not a UTF-8 text file") from None
    rows = []
    try:
        for lineno, cells in enumerate(csv.reader(io.StringIO(text),
                                                  delimiter=sniff_delimiter(text)), start=1):
            cells = [c.strip() for c in cells]
            if not cells or all(c == "" for c in cells) or cells[0].startswith("#"):
                continue
            rows.append((lineno, cells))
    except csv.Error as exc:
        raise InputError(f"{path}: not a readable CSV ({exc})") from None
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
        try:
            self.fh.write(data)
        except OSError as exc:      # a full disk, a quota, an I/O error: one line, nothing left
            self.discard()
            raise write_error(self.path, exc) from None

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
            raise write_error(self.path, exc) from None
        return self.path

    def discard(self) -> None:
        if not self.fh.closed:
            try:
                self.fh.close()
            except OSError:         # the buffered rest could not be written: dropped anyway
                pass
        if os.path.exists(self.tmp):
            os.unlink(self.tmp)


def write_error(path, exc: OSError) -> InputError:
    """The one-line error of an OS failure while writing ``path`` (ENOSPC: "no space left on
    the device", EDQUOT, EIO, EACCES ...)."""
    return InputError(f"cannot write {path}: {exc.strerror or exc}")
# ---------------------------------------------------------------------------------------------
# package protection
_PACKAGE_ROOTS: list | None = None
_STAGING: set = set()          # staging folders of open plans: writes there are allowed


def package_roots() -> list:
    """Resolved folders of the installed ``volerr`` package, ``volerr.generated`` and
    ``volerr.derive``: no command writes there (``volerr derive --in-package`` excepted)."""
    global _PACKAGE_ROOTS
    if _PACKAGE_ROOTS is None:
        import importlib.util

        roots = []
        for name in ("volerr", "volerr.generated", "volerr.derive"):
            try:
                spec = importlib.util.find_spec(name)
            except (ImportError, ValueError):
                spec = None
            for loc in (spec.submodule_search_locations or []) if spec else []:
                roots.append(Path(loc).resolve())
        _PACKAGE_ROOTS = roots
    return _PACKAGE_ROOTS


def _within(path: Path, root: Path) -> bool:
    return path == root or root in path.parents


def is_package_file(path) -> bool:
    """True when ``path`` is, or lies inside, a folder of the installed package."""
    p = Path(path).resolve()
    return any(_within(p, r) for r in package_roots())


def _staged(path) -> bool:
    p = Path(path).resolve()
    return any(_within(p, s) for s in _STAGING)


# ---------------------------------------------------------------------------------------------
# staging folders: named after the process that owns them, removed when it is gone
_STAGING_RX = None


def _host() -> str:
    import re
    import socket

    return re.sub(r"[^A-Za-z0-9.]", "_", socket.gethostname() or "host")[:40]


def staging_prefix() -> str:
    """``.volerr-staging-<pid>@<host>-``: the name says which process owns the folder."""
    return f".volerr-staging-{os.getpid()}@{_host()}-"


def _alive(pid: int) -> bool:
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:        # exists, owned by someone else
        return True
    return True


def remove_stale_staging(folder) -> list:
    """Remove the staging folders in ``folder`` left by runs that were killed (SIGKILL, power
    loss): only those named by :func:`staging_prefix` on this host whose process is gone.
    Returns the removed paths."""
    import re

    global _STAGING_RX
    if _STAGING_RX is None:
        _STAGING_RX = re.compile(r"\.volerr-staging-(\d+)@(.+)-[^-]+$")
    removed = []
    try:
        entries = list(Path(folder).iterdir())
    except OSError:
        return removed
    host = _host()
    for d in entries:
        m = _STAGING_RX.match(d.name)
        if not m or m.group(2) != host or not d.is_dir() or d.is_symlink():
            continue
        pid = int(m.group(1))
        if pid == os.getpid() or _alive(pid):
            continue
        shutil.rmtree(d, ignore_errors=True)
        removed.append(d)
    return removed


# ---------------------------------------------------------------------------------------------
# the output plan
def _same(role, other, path) -> str:
    return (f"two outputs are the same file {path}: {role} and {other} would overwrite each "
            f"other")


class Outputs:
    """Every output of one command run: declared and checked before computing, written at the
    end, all or nothing.

    Parameters
    ----------
    inputs : iterable of path-like
        Files (or folders: every file inside) the run reads; never overwritten.  ``None``
        entries are ignored.
    allow_package : bool
        Permit writing into the installed package (only ``volerr derive --in-package``).
    force : bool
        Let a folder output replace files that were there before the run (``--force``).
        Without it a folder output never replaces an existing file: the refusal names it.
        An output named as a file (``--json F``) is the user's explicit choice and replaces
        an existing F either way.

    Every output's folder must exist, except an output folder itself, which is created
    when its parent exists: a mistyped folder name is refused, never created silently.

    Examples
    --------
    >>> outs = Outputs([table]).file("--out", "map.csv").plot("--plot", None)
    >>> outs.check()                      # before any computation: exit 2 on a bad path
    >>> with outs:                        # commit on success, nothing written on failure
    ...     write_text(outs.path("--out"), text)
    """

    def __init__(self, inputs=(), *, allow_package: bool = False, force: bool = False):
        files = []
        for p in inputs:
            if p is None:
                continue
            p = Path(p)
            if p.is_dir():
                files.extend(q for q in p.iterdir() if q.is_file())
            else:
                files.append(p)
        self.inputs = files
        self.allow_package = allow_package
        self.force = force
        self._replace: dict = {}        # folder role -> True or its rule (folder())
        self._items: list = []          # (role, path, kind, files)
        self._stage: dict = {}          # role -> staged path
        self._roots: dict = {}          # target folder -> staging folder
        self._created: list = []        # parent folders created for staging
        self._checked = False
        self._closed = False

    # -- declaration ---------------------------------------------------------------------
    def file(self, role: str, path, *, plot: bool = False) -> "Outputs":
        """Declare an output file (``None``: option not given, ignored)."""
        if path is not None:
            require(not self._checked, "internal: output declared after check()")
            self._items.append((role, Path(path), "plot" if plot else "file", None))
        return self

    def group(self, role: str, paths) -> "Outputs":
        """Declare the files one output name stands for (Heidenhain: the ``.cma`` named by
        ``--out`` and the ``.com`` tables beside it): each checked like a file, and -- as for
        a folder -- none replaces a file that was there before without ``force``, since the
        user named only the first.  Roles: ``role`` for the first, ``role (NAME)`` after."""
        paths = [Path(p) for p in paths]
        require(not self._checked, "internal: output declared after check()")
        for k, p in enumerate(paths):
            self._items.append((self.group_role(role, paths, k), p, "member", None))
        return self

    @staticmethod
    def group_role(role: str, paths, k: int) -> str:
        """The role of the ``k``-th file of a :meth:`group`."""
        return role if k == 0 else f"{role} ({Path(list(paths)[k]).name})"

    def _refuse_replaced_member(self, role, p: Path) -> None:
        if self.force:
            return
        require(not (p.exists() or p.is_symlink()),
                f"{role}: {p} exists already (the output writes several files for one "
                f"name); give --force to replace it, or another name")

    def plot(self, role: str, path) -> "Outputs":
        """Declare a PNG plot (must end in ``.png``)."""
        return self.file(role, path, plot=True)

    def folder(self, role: str, path, files=None, *, replace=False) -> "Outputs":
        """Declare an output folder and, when known, the names of the files it will get
        (relative paths); unknown names are checked at commit, before anything moves.
        ``replace``: files of this folder may be replaced without ``force``: True (every
        file) or a rule ``replace(path) -> None`` (may be replaced) ``| str`` (why not: the
        refusal says ``<path> <why>; give --force ...``), e.g. ``volerr derive``'s, which
        replaces a generated module only while it is as volerr wrote it."""
        if path is not None:
            require(not self._checked, "internal: output declared after check()")
            self._items.append((role, Path(path), "folder",
                                None if files is None else tuple(files)))
            if replace:
                self._replace[role] = replace
        return self

    def _refuse_existing(self, role, folder: Path, f: Path) -> None:
        """A folder output must not replace a file that was there before the run (unless
        ``force``, or its folder's ``replace`` rule allows it)."""
        rule = self._replace.get(role)
        if self.force or rule is True or not (f.exists() or f.is_symlink()):
            return
        why = rule(f) if callable(rule) else "exists already (not written by this run)"
        require(why is None, f"{role} {folder}: {f} {why}; give --force to replace it, or "
                             f"another folder")

    @property
    def declared(self) -> list:
        """(role, final path) of every declared output."""
        return [(r, p) for r, p, _, _ in self._items]

    # -- checks --------------------------------------------------------------------------
    def _refuse_target(self, role, p: Path) -> None:
        require(str(p).strip() != "", f"{role}: empty file name")
        rp = p.resolve()
        for q in self.inputs:  # the more specific reason first: an input of this run
            same = (rp == q.resolve()) or (p.exists() and q.exists() and os.path.samefile(p, q))
            require(not same, f"{role} {p}: refusing to overwrite the input file {q}")
        if not self.allow_package:
            require(not is_package_file(p),
                    f"{role} {p}: refusing to write into the installed volerr package "
                    f"(a shipped file such as a layout or generated module)")

    @staticmethod
    def _probe_writable(role, target_dir: Path, shown: Path, create: bool = False) -> None:
        """``target_dir`` must be a writable folder; with ``create`` (an output folder) it
        may be missing when its parent folder exists."""
        d = target_dir
        if create and not d.exists():
            d = d.parent
        if not d.exists():
            bad = d
            while not bad.parent.exists() and bad.parent != bad:
                bad = bad.parent
            if bad.parent.exists() and not bad.parent.is_dir():
                raise InputError(f"{role} {shown}: cannot write, {bad.parent} is a file, not "
                                 f"a folder")
            raise InputError(f"{role} {shown}: folder {d} does not exist (create it first; "
                             f"a mistyped folder is never created)")
        require(d.is_dir(), f"{role} {shown}: cannot write, {d} is a file, not a folder")
        try:
            fd, tmp = tempfile.mkstemp(dir=d, prefix=".volerr-probe-")
            os.close(fd)
            os.unlink(tmp)
        except OSError as exc:
            raise InputError(f"{role} {shown}: cannot write in {d} "
                             f"({exc.strerror or exc})") from None

    def check(self) -> "Outputs":
        """All checks, before any computation; raises :class:`InputError` (one line)."""
        finals: dict = {}
        folders = []
        existing = []                   # (role, folder, file): checked after the rest
        declared = [p.resolve() for _, p, kind, _ in self._items if kind == "folder"]
        for role, p, kind, files in self._items:
            if kind == "folder":
                require(not p.exists() or p.is_dir(),
                        f"{role} {p}: is a file, not a folder")
                self._refuse_target(role, p)
                for other_role, other in folders:
                    require(p.resolve() != other.resolve(),
                            f"{role} and {other_role} name the same folder {p}")
                folders.append((role, p))
                self._probe_writable(role, p, p, create=True)
                for name in files or ():
                    f = p / name
                    self._refuse_target(role, f)
                    existing.append((role, p, f))
                    key = f.resolve()
                    require(key not in finals, _same(f"{role} {p}", finals.get(key), f))
                    finals[key] = f"{role} {p}"
            else:
                require(not p.is_dir(), f"{role} {p}: is a folder, give a file name")
                if kind == "plot":
                    require(p.suffix.lower() == ".png",
                            f"{role}: plot file must end in .png, got {p.name}")
                self._refuse_target(role, p)
                key = p.resolve()
                require(key not in finals, _same(role, finals.get(key), p))
                finals[key] = role
                # inside an output folder of this run: that folder is created
                inside = next((d for d in declared if _within(p.parent.resolve(), d)), None)
                if inside is None:
                    self._probe_writable(role, p.parent, p)
        for role, p, f in existing:
            self._refuse_existing(role, p, f)
        for role, p, kind, _ in self._items:
            if kind == "member":
                self._refuse_replaced_member(role, p)
        # a file inside a folder whose file names are not known in advance
        for role, p, kind, files in self._items:
            if kind == "folder" and files is None:
                for key, other in finals.items():
                    require(not _within(key, p.resolve()) or str(other).endswith(f" {p}"),
                            f"{other} writes inside the output folder {role} {p}: give "
                            f"another location")
        self._checked = True
        return self

    # -- staging -------------------------------------------------------------------------
    def _staging_root(self, folder: Path) -> Path:
        key = folder.resolve() if folder.exists() else folder.absolute()
        if key not in self._roots:
            missing = []
            d = folder
            while not d.exists():
                missing.append(d)
                d = d.parent
            try:
                for m in reversed(missing):
                    m.mkdir()
                    self._created.append(m)
                remove_stale_staging(folder)
                root = Path(tempfile.mkdtemp(dir=folder, prefix=staging_prefix()))
            except OSError as exc:
                raise InputError(f"cannot write in {folder}: {exc.strerror or exc}") from None
            self._roots[key] = root
            _STAGING.add(root.resolve())
        return self._roots[key]

    def path(self, role: str):
        """Where to write output ``role`` now (a staged path; a folder for folders); ``None``
        when the option was not given."""
        if not self._checked:
            self.check()
        require(not self._closed, "internal: outputs already committed")
        for r, p, kind, _ in self._items:
            if r == role:
                if role not in self._stage:
                    if kind == "folder":
                        root = self._staging_root(p if p.exists() else p.parent)
                        self._stage[role] = root / f".volerr-folder-{len(self._stage)}"
                        self._stage[role].mkdir()
                    else:
                        self._stage[role] = self._staging_root(p.parent) / p.name
                return self._stage[role]
        return None

    __getitem__ = path

    def _moves(self) -> list:
        """(staged file, final file, role) of everything written."""
        moves = []
        for role, p, kind, _ in self._items:
            st = self._stage.get(role)
            if st is None or not st.exists():
                continue
            if kind == "folder":
                for f in sorted(st.rglob("*")):
                    if f.is_file():
                        moves.append((f, p / f.relative_to(st), role))
            else:
                moves.append((st, p, role))
        return moves

    def commit(self) -> list:
        """Move every staged output into place (checked again first); on any failure
        restore what was there and remove everything staged.  Returns the final paths."""
        if self._closed:
            return []
        moves = self._moves()
        try:
            seen = {}
            folders = {r: p for r, p, kind, _ in self._items if kind == "folder"}
            members = {r for r, _, kind, _ in self._items if kind == "member"}
            for _, final, role in moves:
                self._refuse_target(role, final)
                if role in folders:
                    self._refuse_existing(role, folders[role], final)
                if role in members:
                    self._refuse_replaced_member(role, final)
                key = final.resolve()
                require(key not in seen, _same(role, seen.get(key), final))
                seen[key] = role
            done = []      # (final, backup or None)
            try:
                for staged, final, _ in moves:
                    final.parent.mkdir(parents=True, exist_ok=True)
                    backup = None
                    if final.exists():
                        backup = final.with_name(f".volerr-backup-{os.getpid()}-{final.name}")
                        os.replace(final, backup)
                    done.append((final, backup))
                    try:
                        os.replace(staged, final)
                    except OSError:
                        shutil.move(str(staged), str(final))
            except OSError as exc:
                for final, backup in reversed(done):
                    try:
                        if backup is not None:
                            os.replace(backup, final)
                        elif final.exists():
                            final.unlink()
                    except OSError:
                        pass
                raise InputError(f"cannot write {final}: {exc.strerror or exc}") from None
            for _, backup in done:
                if backup is not None and backup.exists():
                    backup.unlink()
        except BaseException:
            self.discard()
            raise
        self._cleanup(keep_created=True)
        return [final for _, final, _ in moves]

    def discard(self) -> None:
        """Remove every staged file and the folders created for them."""
        self._cleanup(keep_created=False)

    def _cleanup(self, keep_created: bool) -> None:
        for root in self._roots.values():
            _STAGING.discard(root.resolve())
            shutil.rmtree(root, ignore_errors=True)
        self._roots.clear()
        self._stage.clear()
        if not keep_created:
            for d in reversed(self._created):
                try:
                    d.rmdir()
                except OSError:
                    pass
        self._created.clear()
        self._closed = True

    def __enter__(self) -> "Outputs":
        if not self._checked:
            self.check()
        return self

    def __exit__(self, exc_type, exc, tb) -> bool:
        if exc_type is None:
            self.commit()
            return False
        where = self._role_of(exc) if isinstance(exc, OSError) else None
        self.discard()
        if where is not None:
            # an OS error while writing a staged output (full disk, quota, I/O error): one
            # line naming the output, nothing written
            raise write_error(where, exc) from None
        return False

    def _role_of(self, exc: OSError) -> str:
        """The declared output an OS error concerns (its final path), else the file it names."""
        name = getattr(exc, "filename", None)
        if name:
            staged = Path(name)
            for role, st in self._stage.items():
                if staged == st or (st in staged.parents):
                    final = dict(self.declared)[role]
                    return f"{role} {final}"
            return str(name)
        return " ".join(f"{r} {p}" for r, p in self.declared) or "the outputs"


def planned_outputs(options: dict, inputs, *, first: dict | None = None, **more) -> Outputs:
    """:class:`Outputs` of a command's run, declared in this order (the order of the refusals)
    and checked: ``first``, the report outputs ``options`` (a plain dict of the run's options)
    gives (``json``, ``html``, ``pdf``, ``plot``: roles ``--json`` ...) and ``more``;
    ``{"--out": path}`` a file (``--plot...`` a PNG), ``{"--errors-out": (path, names)}`` a
    folder (``None`` names: not known yet), ``{"--plot": [paths]}`` a group
    (:meth:`Outputs.group`).  ``options["force"]``: :class:`Outputs`' ``force``."""
    outs = Outputs(inputs, force=options.get("force", False))
    first = first or {}
    report = {r: options.get(r[2:]) for r in ("--json", "--html", "--pdf", "--plot")}
    for targets in (first, {r: p for r, p in report.items() if r not in {**first, **more}}, more):
        for role, target in targets.items():
            if isinstance(target, tuple):
                outs.folder(role, target[0], files=target[1])
            elif isinstance(target, list):     # one option, several files
                outs.group(role, target)
            elif role.startswith("--plot"):
                outs.plot(role, target)
            else:
                outs.file(role, target)
    return outs.check()


def layout_inputs(layout) -> list:
    """``[path]`` when ``layout`` names an existing layout file (an input of a run, never
    overwritten), else ``[]`` (a shipped layout's name)."""
    p = Path(str(layout))
    return [p] if p.is_file() else []
