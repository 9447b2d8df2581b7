"""The demo report is valid HTML whose links all resolve, and it renders in a real browser
(headless Chromium, when installed: CI does not depend on it)."""

from __future__ import annotations

import shutil
import subprocess
from html.parser import HTMLParser

import pytest

from volerr.cli import main

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("outputs_reports")

VOID = {"meta", "img", "br", "hr", "link", "input", "source", "wbr"}


class _Check(HTMLParser):
    def __init__(self):
        super().__init__()
        self.stack, self.links, self.errors, self.imgs = [], [], [], []

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        for key in ("href", "src"):
            if a.get(key) and not a[key].startswith(("#", "http", "data:")):
                self.links.append(a[key])
        if tag == "img":
            self.imgs.append(a)
        if tag not in VOID:
            self.stack.append(tag)

    def handle_endtag(self, tag):
        if tag in VOID:
            return
        if not self.stack or self.stack[-1] != tag:
            self.errors.append(f"</{tag}> closes <{self.stack[-1] if self.stack else None}>")
        else:
            self.stack.pop()


@pytest.fixture(scope="module")
def demo(tmp_path_factory):
    out = tmp_path_factory.mktemp("demo") / "report"
    assert main(["demo", "--out", str(out), "--only", "iso230_2", "uncertainty"]) == 0
    return out


def test_index_is_well_formed_and_every_link_exists(demo):
    page = (demo / "index.html").read_text(encoding="utf-8")
    chk = _Check()
    chk.feed(page)
    assert chk.errors == [] and chk.stack == [], (chk.errors, chk.stack)
    assert chk.links, "no links"
    for link in chk.links:
        assert (demo / link).exists(), f"broken link {link}"
    # legible figures: shown at their own pixel width (issue 23: the text size on the page is
    # then the size the figure was drawn with), shrinking only in a narrow window; a caption
    # and alt text
    import struct

    for i in chk.imgs:
        w = struct.unpack(">II", (demo / i["src"]).read_bytes()[16:24])[0]
        assert i.get("alt") and int(i["width"]) == min(w, 1000), i
        assert "max-width:100%" in i.get("style", "")
    assert page.count("<figcaption>") == len(chk.imgs)
    assert page.count("<h2>") == 2 and "Result:" in page
    assert not [p for p in demo.parent.rglob(".volerr-*")], "staging left behind"


def test_index_renders_in_headless_chromium(demo, tmp_path):
    exe = shutil.which("chromium") or shutil.which("chromium-browser") \
        or shutil.which("google-chrome")
    if exe is None:
        pytest.skip("no Chromium installed (apt-get install chromium); HTML checked above")
    shot = tmp_path / "shot.png"
    subprocess.run([exe, "--headless", "--no-sandbox", "--disable-gpu",
                    f"--screenshot={shot}", "--window-size=1280,2000",
                    (demo / "index.html").as_uri()], check=True, capture_output=True,
                   timeout=120)
    import matplotlib.image as mpimg

    img = mpimg.imread(shot)
    assert img.shape[0] == 2000 and img.shape[1] == 1280
    # something is drawn: not a blank page
    assert img[..., :3].std() > 0.05
