"""The one line of a refusal, from the command (exit 2, stderr) and from the API (InputError):
tests compare the two."""

from __future__ import annotations

import pytest

from volerr.cli import main
from volerr.errors import InputError


def command_error(argv, capsys) -> str:
    """The command's refusal text (after ``volerr CMD: error: ``); asserts exit 2, one line."""
    assert main([str(a) for a in argv]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    prefix = f"volerr {argv[0]}: error: "
    assert err[0].startswith(prefix), err[0]
    return err[0][len(prefix):]


def api_error(call) -> str:
    """The text of the InputError ``call()`` raises."""
    with pytest.raises(InputError) as exc:
        call()
    return str(exc.value)
