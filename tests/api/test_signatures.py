"""Real signatures (issue 42 item 5): every public function of the README's table and of
INTERFACE.md shows its keywords with their defaults under ``inspect.signature`` (the callable
packages too, not ``(*args, **kwargs)``); a string where a list of files is expected is one
file; ``volerr.check(layout, files, reference=...)`` is the command's order."""

from __future__ import annotations

import inspect
import re
from pathlib import Path

import pytest

import volerr
from volerr.example_files import shipped_path

ROOT = Path(__file__).resolve().parents[2]
SPHERE = str(shipped_path("sphere_example_DMU50.csv"))


def _public_functions() -> list:
    names = set(re.findall(r"`volerr\.([a-z_0-9]+)", (ROOT / "README.md").read_text()))
    names |= {"controller_export", "controller_import", "iso230_3", "iso10360"}
    return sorted(n for n in names if n not in ("layouts",))


@pytest.mark.parametrize("name", _public_functions())
def test_the_signature_names_the_keywords(name):
    f = getattr(volerr, name)
    assert callable(f), name
    params = inspect.signature(f).parameters.values()
    kinds = {p.kind for p in params}
    assert inspect.Parameter.VAR_POSITIONAL not in kinds, (name, inspect.signature(f))
    assert inspect.Parameter.VAR_KEYWORD not in kinds, (name, inspect.signature(f))
    named = [p.name for p in params]
    assert len(named) >= 1, name
    assert any(p.default is not inspect.Parameter.empty for p in params) or name == "load", \
        (name, inspect.signature(f))
    assert (f.__doc__ or "").strip() and "Parameters" in inspect.getdoc(
        getattr(f, "__api__", f)) or name in ("load", "history"), name


def test_the_callable_packages_show_their_functions_signature():
    for name in ("calibrate", "loop", "check", "plan", "identify", "uncertainty", "history"):
        pkg = getattr(volerr, name)
        assert inspect.signature(pkg) == inspect.signature(pkg.__api__), name


def test_history_is_the_show_function():
    from volerr.history.run import show

    assert volerr.history.__api__ is show
    assert callable(volerr.history) and volerr.history.add.__module__ == "volerr.history.run"
    with pytest.raises(volerr.InputError):
        volerr.history("no such store.sqlite", "M1")


def test_a_string_is_one_file():
    """Before: ``volerr.calibrate("DMU50", "sph.csv")`` read the name's characters as files
    and said "the same file given twice"."""
    one = volerr.calibrate("DMU50", SPHERE)
    assert one.to_dict()["parameters"] == volerr.calibrate("DMU50", [SPHERE]).to_dict()[
        "parameters"]
    assert [i["file"] for i in one.to_dict()["instruments"]] == [Path(SPHERE).name]


def test_check_takes_the_reference_by_keyword(tmp_path):
    """Before: ``TypeError: got multiple values for argument 'reference'``; now the
    reference is read (here: a missing file, refused with the one-line InputError)."""
    missing = tmp_path / "no_cal.json"
    with pytest.raises(volerr.InputError) as e:
        volerr.check("DMU50", SPHERE, reference=missing)
    assert "\n" not in str(e.value)
    assert list(inspect.signature(volerr.check).parameters)[:3] == ["layout", "files",
                                                                    "reference"]
