"""The one door from the runtime to the derivation (sympy, imported only when called).

Shipped layouts are loaded from their committed modules in ``volerr.generated`` and never reach
this door; a layout file given by path, an augmented layout of ``volerr loop`` and the
``volerr derive`` command do.

Cache: a module derived for a layout file is kept on disk, keyed by the layout text's sha256 and
a fingerprint of the generator (the source of ``volerr.derive`` and the sympy version), in
``$VOLERR_CACHE_DIR`` or else ``$XDG_CACHE_HOME/volerr`` (``~/.cache/volerr``), never inside the
package.  The next load of the same layout text reads that file without importing sympy.  An
entry carries the sha256 of its own text in its last line; an entry that does not match (cut
short, edited, not Python) is ignored and rewritten atomically (temporary file + rename).  A
cache folder that cannot be written only costs the derivation.
"""

from __future__ import annotations

import hashlib
import os
import tempfile
import types
from pathlib import Path

from .layout import Layout


def generate_source(layout: Layout) -> str:
    """The generated module text of ``layout`` (deterministic; imports sympy)."""
    from volerr.derive.generate import generate_module

    return generate_module(layout)


#: reduced module texts derived in this process: the layout's repr (every field) -> text
_FIT_SOURCES: dict = {}
#: how many :data:`_FIT_SOURCES` keeps (the most recently derived)
FIT_SOURCES_KEPT = 16


def fit_source(layout: Layout) -> str:
    """A reduced module text of ``layout`` for fitting (imports sympy): the constants of
    :func:`generate_source` and only ``sensitivity`` and ``setup_sensitivity``.  Used by
    ``volerr loop`` for its augmented model during the run; the full text is derived only
    when it is written or asked for.  The derivation is deterministic, so a text derived
    in this process for an equal layout (every field) is reused: a loop run again on the
    same data augments the layout the same way."""
    key = repr(layout)
    if key not in _FIT_SOURCES:
        from volerr.derive.generate import generate_fit_module

        while len(_FIT_SOURCES) >= FIT_SOURCES_KEPT:
            _FIT_SOURCES.pop(next(iter(_FIT_SOURCES)))
        _FIT_SOURCES[key] = generate_fit_module(layout)
    return _FIT_SOURCES[key]


def module_filename(layout: Layout) -> str:
    """File name of ``layout``'s generated module (``MB1`` -> ``mb1.py``)."""
    return f"{layout.name.lower()}.py"


def all_sources(progress=None) -> dict:
    """File name -> text of every file of ``generated/`` (imports sympy); ``progress``: optional
    wrapper of the iterable of shipped layout names."""
    from volerr.derive.generate import all_generated

    return all_generated(progress) if progress else all_generated()


def module_from_source(source: str, layout_name: str) -> types.ModuleType:
    """Load a generated module's text as a module object (not registered in sys.modules)."""
    mod = types.ModuleType(f"volerr_generated_{layout_name.lower()}")
    exec(compile(source, f"<generated {layout_name}>", "exec"), mod.__dict__)
    return mod


def derive_module(layout: Layout, cache: bool = True) -> types.ModuleType:
    """The generated module of ``layout``: from the cache when an entry for this layout text
    and generator exists, else derived (sympy) and stored in the cache."""
    if not cache:
        return module_from_source(generate_source(layout), layout.name)
    path = cache_path(layout)
    source = _read_entry(path)
    if source is not None:
        try:
            mod = module_from_source(source, layout.name)
            if getattr(mod, "LAYOUT_SHA256", None) == layout.sha256:
                return mod
        except Exception:  # noqa: BLE001 - a bad entry is rebuilt below
            pass
    source = generate_source(layout)
    _write_entry(path, source)
    return module_from_source(source, layout.name)


def derive_source(layout: Layout) -> str:
    """:func:`generate_source` of ``layout`` through the cache of :func:`derive_module`: the
    entry's text when it was derived from the same layout text and file name (the module
    names its layout file), else derived and stored, so that loading the file later (``volerr
    loop``'s augmented layout refitted) reads it without sympy.  An entry keeps the text
    without its final newline; the generator's texts end with exactly one (every module of
    ``generated/``), which is given back."""
    path = cache_path(layout)
    body = _read_entry(path)
    if body is not None and f"LAYOUT_SHA256 = {layout.sha256!r}" in body \
            and f" from {layout.path}.\n" in body:
        return body + "\n"
    source = generate_source(layout)
    if source.endswith("\n") and not source.endswith("\n\n"):
        _write_entry(path, source)
    return source


_ENTRY_TAG = "# volerr-cache sha256 "     # an entry's seal (volerr.derive.seal)


def cache_dir() -> Path:
    """Folder of derived modules: ``$VOLERR_CACHE_DIR``, else ``$XDG_CACHE_HOME/volerr``, else
    ``~/.cache/volerr``."""
    if os.environ.get("VOLERR_CACHE_DIR"):
        return Path(os.environ["VOLERR_CACHE_DIR"])
    base = os.environ.get("XDG_CACHE_HOME") or os.path.join(os.path.expanduser("~"), ".cache")
    return Path(base) / "volerr"


_FINGERPRINT = None
#: files of ``volerr.machine`` among the derivation sources of a layout's module
RUNTIME_SOURCES = ("layout.py", "lags.py")


def generator_fingerprint() -> str:
    """sha256 of the generator's source files (``volerr.derive``: *.py and templates, not the
    audit of printed equations in ``audit/``, which shapes no generated code), the runtime's
    derivation sources (``RUNTIME_SOURCES``) and the sympy version, without importing
    either."""
    global _FINGERPRINT
    if _FINGERPRINT is None:
        import importlib.util
        from importlib import metadata

        spec = importlib.util.find_spec("volerr.derive")
        h = hashlib.sha256()
        for folder in spec.submodule_search_locations or ():
            root = Path(folder)
            for f in sorted(p for p in root.rglob("*") if p.is_file()
                            and p.suffix not in (".pyc",) and "__pycache__" not in p.parts
                            and p.relative_to(root).parts[0] != "audit"):
                h.update(str(f.relative_to(root)).encode() + b"\0" + f.read_bytes() + b"\0")
        # the runtime's derivation sources (derive.generate.LAYOUT_SOURCES, derive.lags.SOURCES):
        # a layout module's provenance hashes them, so an entry derived before they changed
        # must not be served after
        machine = Path(importlib.util.find_spec("volerr.machine").submodule_search_locations[0])
        for name in RUNTIME_SOURCES:
            h.update(name.encode() + b"\0" + (machine / name).read_bytes() + b"\0")
        try:
            h.update(metadata.version("sympy").encode())
        except metadata.PackageNotFoundError:  # pragma: no cover
            pass
        _FINGERPRINT = h.hexdigest()
    return _FINGERPRINT


def cache_path(layout: Layout) -> Path:
    """Cache entry of ``layout``: ``<cache_dir>/<name>-<key>.py``, key from the layout text's
    sha256 and :func:`generator_fingerprint`."""
    key = hashlib.sha256(f"{layout.sha256}:{generator_fingerprint()}".encode()).hexdigest()
    safe = "".join(c if c.isalnum() or c in "_-" else "_" for c in layout.name.lower())
    return cache_dir() / f"{safe}-{key[:32]}.py"


def _read_entry(path: Path) -> str | None:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return None
    from volerr.derive.seal import unseal

    return unseal(text, _ENTRY_TAG)


def _write_entry(path: Path, source: str) -> None:
    from volerr.derive.seal import seal

    text = seal(source, _ENTRY_TAG)
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "w", encoding="utf-8") as fh:
                fh.write(text)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.unlink(tmp)
    except OSError:
        pass  # no cache: the next load derives again


def package_generated_dir() -> Path:
    """The installed ``volerr.generated`` folder (where ``volerr derive --all`` writes)."""
    import volerr.generated

    return Path(volerr.generated.__file__).parent


def derive_request(layouts=(), *, all_layouts: bool = False, out=None,
                   in_package: bool = False) -> tuple:
    """A ``volerr derive`` request checked: ``(folder, in_package, layouts)``.  ``layouts``:
    names or layout files; ``all_layouts``: every shipped layout and every layout-independent
    module; ``out``: the folder (default ``./generated``); ``in_package``: the installed
    package's ``generated/`` (developers, with ``all_layouts`` only).  The committed
    ``generated/`` folder is rewritten only as a whole; two layouts that would write the same
    module are refused (one line each)."""
    from ..errors import require
    from ..fileio import is_package_file
    from .layout import layout_names, read_layout

    require(layouts or all_layouts, "name a layout (see 'volerr layouts') or use --all")
    require(not (in_package and out), "give either --out DIR or --in-package")
    folder = package_generated_dir() if in_package else Path(out if out else "generated")
    writes_package = is_package_file(folder)
    if writes_package:
        require(folder.resolve() == package_generated_dir().resolve(),
                f"--out {folder}: refusing to write into the installed volerr package")
        require(all_layouts and not layouts,
                f"{folder} is the installed package's generated/ folder: only 'volerr derive "
                f"--all' rewrites it; give --out DIR for a layout")
    require(not in_package or all_layouts, "--in-package regenerates everything: add --all")
    found = [read_layout(name) for name in layouts]
    names = [module_filename(lay) for lay in found]
    if all_layouts:
        names += [module_filename(read_layout(n)) for n in layout_names()]
    dup = sorted({n for n in names if names.count(n) > 1})
    require(not dup, f"two layouts generate the same module {dup[0] if dup else ''}: give them "
                     f"different names or derive them one at a time")
    return folder, writes_package, found


def target_names(layouts, all_layouts: bool = False) -> list:
    """The file names :func:`derived_sources` gives (known before deriving)."""
    names = [module_filename(lay) for lay in layouts]
    if all_layouts:
        from volerr.derive.generate import EXTRA_MODULES, module_name

        from .layout import layout_names

        names += [f"{module_name(n)}.py" for n in layout_names()] + list(EXTRA_MODULES)
    return list(dict.fromkeys(names))


def not_replaceable(path) -> str | None:
    """Why ``volerr derive`` must not replace the existing file ``path`` without ``--force``
    (the end of a one-line refusal), or None: a file is replaced while it is as volerr
    derive wrote it -- its last line the sha256 of the text above it (:mod:`volerr.derive.seal`),
    however stale its content; an edited file, or one without that line (written by hand, or
    by a volerr from before the line), differs from anything volerr derive writes."""
    from volerr.derive.seal import GENERATED_TAG, unseal

    try:
        text = Path(path).read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError):
        return "is not a text file volerr derive wrote"
    if unseal(text, GENERATED_TAG) is not None:
        return None
    last = text.rstrip("\n").rpartition("\n")[2]
    if last.startswith(GENERATED_TAG):
        return ("was edited after volerr derive wrote it (its text no longer matches the "
                "sha256 of its last line)")
    return (f"was not written by this volerr derive (no '{GENERATED_TAG.strip()}' last "
            f"line: written by hand, or by an older volerr)")


def derived_sources(layouts, all_layouts: bool = False, progress=None) -> dict:
    """File name -> generated text of each layout of ``layouts`` (and with ``all_layouts``
    of every file of ``generated/``); imports sympy.  ``progress``: an optional wrapper of
    an iterable (``progress(items, desc=..., unit=...)``, :func:`volerr.progress.progress`)."""
    def wrap(items, desc):
        return progress(items, desc=desc, unit="layout") if progress else items

    texts = {module_filename(lay): generate_source(lay) for lay in wrap(layouts, "derive")}
    if all_layouts:
        texts.update(all_sources(lambda names: wrap(names, "derive --all")))
    return texts
