"""``volerr derive`` never replaces a generated file the user edited unless ``--force``: a
file is replaced while its last line is the sha256 of the text above it (as volerr derive
wrote it, however stale: ``volerr derive --all`` refreshes generated/ without --force); an
edited file, or one without that line, is refused with one line naming it, exit 2, nothing
written."""

from __future__ import annotations

from volerr.cli import main
from volerr.derive.seal import GENERATED_TAG, seal, unseal


def _derive(out, capsys, *extra) -> tuple:
    rc = main(["derive", "MB1", "--out", str(out), *extra])
    return rc, capsys.readouterr().err


def test_edited_refused_stale_replaced_force_replaces(tmp_path, capsys):
    out = tmp_path / "gen"
    assert _derive(out, capsys)[0] == 0
    f = out / "mb1.py"
    fresh = f.read_text(encoding="utf-8")
    assert unseal(fresh) is not None

    # stale but untouched (an older derivation, sealed as volerr wrote it): replaced
    stale = seal(fresh.replace("Error model of layout MB1.", "Older text."))
    f.write_text(stale, encoding="utf-8")
    rc, err = _derive(out, capsys)
    assert rc == 0 and f.read_text(encoding="utf-8") == fresh

    # edited by hand: refused, one line naming the file and the reason, nothing written
    edited = fresh.replace("import numpy\n", "import numpy\nMY_FIX = 1\n")
    f.write_text(edited, encoding="utf-8")
    rc, err = _derive(out, capsys)
    assert rc == 2 and len(err.strip().splitlines()) == 1 and "Traceback" not in err
    assert str(f) in err and "was edited after volerr derive wrote it" in err
    assert "--force" in err
    assert f.read_text(encoding="utf-8") == edited

    # without the sha256 line (by hand, or an older volerr): refused too
    f.write_text(fresh.rpartition(GENERATED_TAG)[0], encoding="utf-8")
    rc, err = _derive(out, capsys)
    assert rc == 2 and "was not written by this volerr derive" in err

    # --force replaces
    f.write_text(edited, encoding="utf-8")
    assert _derive(out, capsys, "--force")[0] == 0
    assert f.read_text(encoding="utf-8") == fresh
