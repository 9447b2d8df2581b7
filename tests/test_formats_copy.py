"""docs/formats.md and the copy shipped in the package (``volerr formats`` prints the copy) are
the same file: an edit of one alone would show users a text the repository does not hold."""

from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_shipped_formats_is_the_docs_file():
    assert (ROOT / "runtime" / "data" / "formats.md").read_bytes() == \
        (ROOT / "docs" / "formats.md").read_bytes()
