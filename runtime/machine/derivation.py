"""The one door from the runtime to the derivation (sympy, imported only when called).

Shipped layouts are loaded from their committed modules in ``volerr.generated`` and never reach
this door; a layout file given by path, an augmented layout of ``volerr loop`` and the
``volerr derive`` command do.
"""

from __future__ import annotations

import types
from pathlib import Path

from volerr.machine.layout import Layout


def generate_source(layout: Layout) -> str:
    """The generated module text of ``layout`` (deterministic; imports sympy)."""
    from volerr.derive.generate import generate_module

    return generate_module(layout)


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


def derive_module(layout: Layout) -> types.ModuleType:
    """Derive and generate ``layout`` in memory and load the module."""
    return module_from_source(generate_source(layout), layout.name)


def package_generated_dir() -> Path:
    """The installed ``volerr.generated`` folder (where ``volerr derive --all`` writes)."""
    import volerr.generated

    return Path(volerr.generated.__file__).parent
