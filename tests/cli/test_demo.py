"""``volerr demo``: the README's first command runs the whole pipeline and its figures hold.

The demo runs once, in-process, with matplotlib's ``Figure.savefig`` wrapped: every figure
saved is tagged (a PNG text chunk written by the wrapper) and its texts, dpi and axis labels
recorded, so that each PNG found afterwards -- a file next to ``index.html`` or a data URI
inside a report page -- is traced to the figure it came from.  The pages' ``<img width>``
gives the width each figure is displayed at."""

import base64
import html as htmllib
import json
import re
import struct
import zlib
from pathlib import Path

import pytest

from helpers.in_process import volerr as volerr_command

#: text must be at least this high on the page, px
MIN_PX = 9.0
#: units on axis labels and table headers: 'quantity / unit', never '(mm)', '[mm]', ', mm'
UNIT = r"(?:mm|um|µm|urad|µrad|deg|degC|°C|rad|s|min|h)"
BAD_UNIT = [re.compile(p) for p in (
    rf"\(\s*{UNIT}\s*\)", rf"\[\s*{UNIT}\s*\]", rf",\s*{UNIT}\s*$", r"\bum\b", r"\burad\b",
    r"\bdegC\b")]


def _png_chunks(data: bytes) -> dict:
    """tEXt chunks of a PNG (an independent reader: struct and zlib only)."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    out, i = {}, 8
    while i < len(data):
        n, kind = struct.unpack(">I4s", data[i:i + 8])
        body = data[i + 8:i + 8 + n]
        assert zlib.crc32(kind + body) == struct.unpack(">I", data[i + 8 + n:i + 12 + n])[0]
        if kind == b"tEXt":
            k, _, v = body.partition(b"\0")
            out[k.decode("latin-1")] = v.decode("latin-1")
        elif kind == b"IHDR":
            out["width"], out["height"] = struct.unpack(">II", body[:8])
        i += 12 + n
    return out


def _run_demo(tmp_path_factory):
    """Run ``volerr demo`` once; return (folder, {tag: record of the saved figure})."""
    import matplotlib
    import matplotlib.figure
    import matplotlib.text
    from mpl_toolkits.mplot3d import Axes3D

    from volerr.cli import main

    records = {}
    original = matplotlib.figure.Figure.savefig

    def savefig(fig, fname, *args, **kwargs):
        tag = f"fig{len(records)}"
        fmt = kwargs.get("format") or (Path(str(fname)).suffix[1:] if isinstance(
            fname, (str, Path)) else "png")
        if fmt == "png":
            kwargs["metadata"] = {**(kwargs.get("metadata") or {}), "volerr-test": tag}
        result = original(fig, fname, *args, **kwargs)
        dpi = kwargs.get("dpi")
        dpi = fig.dpi if dpi in (None, "figure") else float(dpi)
        texts = [t for t in fig.findobj(matplotlib.text.Text)
                 if t.get_visible() and t.get_text().strip() and t.figure is not None]
        labels = []
        for ax in fig.axes:
            labels += [ax.get_xlabel(), ax.get_ylabel()]
            if isinstance(ax, Axes3D):
                labels.append(ax.get_zlabel())
        records[tag] = {"dpi": dpi, "labels": [s for s in labels if s.strip()],
                        "min_pt": min(t.get_fontsize() for t in texts),
                        "smallest": min(texts, key=lambda t: t.get_fontsize()).get_text()}
        return result

    out = tmp_path_factory.mktemp("demo") / "demo"
    matplotlib.figure.Figure.savefig = savefig
    try:
        # one process: the wrapped savefig sees every figure (worker processes would keep
        # their records to themselves)
        assert main(["demo", "--out", str(out), "--jobs", "1"]) == 0
    finally:
        matplotlib.figure.Figure.savefig = original
    return out, records


def test_demo(tmp_path_factory):
    """One run of the demo (30 s) for every check: xdist would run a shared fixture once per
    worker."""
    out, records = _run_demo(tmp_path_factory)
    _every_section_and_honest_figures(out)
    _every_figure_has_text_of_at_least_9_px_where_it_is_shown(out, records)
    _one_unit_notation_on_every_axis_and_table_header(out, records)
    _every_figure_drawn_once(out)


def _every_section_and_honest_figures(out):
    from volerr.cli.demo import SECTIONS

    summary = json.loads((out / "summary.json").read_text())
    assert len(summary) == len(SECTIONS)
    for section in summary:
        for f in section["files"]:
            assert (out / f).exists(), f
    loop = json.loads((out / "loop.json").read_text())
    assert loop["effects"] and loop["rms_after_um"] < 0.5 * loop["rms_before_um"]
    assert loop["outliers"]["count"] < 0.005 * loop["n_points"]
    # paths in the report: where the files are, relative to the demo folder; no staging
    assert ".volerr-staging" not in (out / "loop.json").read_text()
    assert (out / loop["augmented_layout"]).is_file()
    cal = json.loads((out / "probe_cal.json").read_text())
    assert 0.99 < cal["r_eff_mm"] < 1.01
    html = (out / "index.html").read_text()
    assert html.count("<section") == len(SECTIONS) and "loop.html" in html
    # the instrument sections recover the planted truth within 3 standard uncertainties
    from volerr.calibrate.examples import BALLBAR_TRUTH, SPHERE_TRUTH

    diag = {d["parameter"]: d for d in json.loads((out / "ballbar.json").read_text())["diagnosis"]}
    for name in ("EC0Y", "EB0Z", "EA0Z"):
        assert abs(diag[name]["value"] - BALLBAR_TRUTH[name]) < 3 * diag[name]["std"], diag[name]
    rot = json.loads((out / "calibrate_rotary.json").read_text())
    assert len(rot["parameters"]) >= 4
    for name, v in rot["parameters"].items():
        assert abs(v["value"] - SPHERE_TRUTH[name]) < 3 * v["std"], (name, v)
    # issue 20: ball plate and multilateration beside their planted truth
    from volerr.calibrate.examples import PLATE_TRUTH, TRACER_STATIONS, TRACER_TRUTH

    for name, truth in (("ballplate", PLATE_TRUTH), ("multilateration", TRACER_TRUTH)):
        rep = json.loads((out / f"calibrate_{name}.json").read_text())
        assert set(rep["parameters"]) == set(truth), (name, rep["unidentifiable"])
        for p, v in rep["parameters"].items():
            assert abs(v["value"] - truth[p]) < 3 * v["std"], (name, p, v)
        assert rep["consistency"]["inconsistent"] == []
    for k, s in TRACER_STATIONS.items():
        e = rep["stations"][f"multilateration_DMU50.csv#{k}"]
        for got, want, u in zip(e["position_mm"], s, e["position_std_um"]):
            assert abs(got - want) * 1e3 < 3 * u, (k, e)
    assert html.count("<figcaption>") == html.count("<img ") > 10
    assert "map_MB1_random.png" in html  # the random component is shown
    # every page the demo wrote is linked from the index
    for page in out.glob("*.html"):
        if page.name != "index.html":
            assert f'href="{page.name}"' in html, page.name
    assert {"audit.html", "uncertainty.html", "iso230_2.html", "loop.html"} <= {
        p.name for p in out.glob("*.html")}
    # the uncertainty is stated for the corrected result: the interval holds the nominal
    q = json.loads((out / "uncertainty.json").read_text())["quantities"]["distance"]
    lo, hi = q["result_interval_mm"]
    assert lo <= q["nominal_mm"] <= hi
    assert q["corrected_estimate_mm"] == pytest.approx(q["estimate_mm"] - q["bias_um"] * 1e-3)
    iso = json.loads((out / "iso230_2.json").read_text())
    assert set(iso["uncertainty_um"]) == set("AEMRB") and iso["verdict"] in (
        "pass", "fail", "undecided")
    # no negative zero in any file the demo wrote (reports, pages, tables)
    negative_zero = re.compile(r"(?<![\w.])[-\u2212]0(?:\.0+)?(?![\d.eE])")
    for f in out.rglob("*"):
        if f.suffix in (".json", ".html", ".csv"):
            text = re.sub(r"data:image/png;base64,[^\"]+", "", f.read_text(encoding="utf-8"))
            assert not negative_zero.search(text), (f.name, negative_zero.search(text))


def _displayed(out: Path):
    """(page, png bytes, displayed width attribute) of every <img> of every page."""
    for page in sorted(out.glob("*.html")):
        text = page.read_text(encoding="utf-8")
        for tag in re.findall(r"<img\b[^>]*>", text):
            src = htmllib.unescape(re.search(r'src="([^"]+)"', tag).group(1))
            w = re.search(r'\bwidth="(\d+)"', tag)
            data = (base64.b64decode(src.split(",", 1)[1]) if src.startswith("data:")
                    else (out / src).read_bytes())
            yield page.name, src[:40], data, int(w.group(1)) if w else None


def _every_figure_has_text_of_at_least_9_px_where_it_is_shown(out, records):
    shown = set()
    n = 0
    for page, src, data, width in _displayed(out):
        chunks = _png_chunks(data)
        assert width is not None, f"{page}: {src} has no width attribute"
        assert width <= 1100, f"{page}: {src} shown wider than the page"
        rec = records[chunks["volerr-test"]]
        assert rec["min_pt"] >= 9.0, f"{page}: {src}: {rec['smallest']!r} below the style's 9 pt"
        px = rec["min_pt"] * rec["dpi"] / 72.0 * width / chunks["width"]
        assert px >= MIN_PX, (f"{page}: {src}: '{rec['smallest']}' is {px:.1f} px high on "
                              f"the page")
        if not src.startswith("data:"):
            shown.add(src)
        n += 1
    assert n >= 20
    # every PNG file of the demo is shown on the index
    assert {p.name for p in out.glob("*.png")} <= shown


def _idat(data: bytes) -> bytes:
    """The image data of a PNG (its IDAT chunks joined; the tEXt tag left out)."""
    out, i = [], 8
    while i < len(data):
        n, kind = struct.unpack(">I4s", data[i:i + 8])
        if kind == b"IDAT":
            out.append(data[i + 8:i + 8 + n])
        i += 12 + n
    return b"".join(out)


def _every_figure_drawn_once(out):
    """Issue 42 item 7: an image shown twice (the PNG file on the index and the page that
    embeds it: ballbar, ISO 230-2, uncertainty) comes from one drawing -- one savefig, one
    tag -- not from the same figure drawn again."""
    tags: dict = {}
    for page, src, data, _ in _displayed(out):
        tags.setdefault(_idat(data), set()).add(_png_chunks(data)["volerr-test"])
    assert sum(len(t) > 1 for t in tags.values()) == 0, [
        sorted(t) for t in tags.values() if len(t) > 1]
    assert sum(len(t) for t in tags.values()) == len(tags) > 20


def _one_unit_notation_on_every_axis_and_table_header(out, records):
    labels = [lab for r in records.values() for lab in r["labels"]]
    assert len(labels) > 60
    for lab in labels:
        for rx in BAD_UNIT:
            assert not rx.search(lab), f"axis label {lab!r}"
        if re.search(rf"\b{UNIT}$", lab) and " / " not in lab:
            pytest.fail(f"axis label {lab!r}: unit without ' / '")
    assert any(lab.endswith(" / µm") for lab in labels)
    assert any(lab.endswith(" / mm") for lab in labels)
    for page in out.glob("*.html"):
        for th in re.findall(r"<th\b[^>]*>(.*?)</th>", page.read_text(encoding="utf-8"), re.S):
            text = htmllib.unescape(re.sub(r"<[^>]+>", "", th)).strip()
            for rx in BAD_UNIT:
                assert not rx.search(text), f"{page.name}: table header {text!r}"


def test_demo_refuses_to_write_over_a_file(tmp_path):
    target = tmp_path / "file"
    target.write_text("keep")
    proc = volerr_command("demo", "--out", target, "--only", "cmm_a")   # main, in-process
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1
    assert target.read_text() == "keep"


#: cheap sections for the checks of the API and of the worker processes (a few seconds)
QUICK = ["probe", "iso230_2"]


def _files(folder: Path) -> dict:
    """Every file's bytes, the wall times ('seconds' and the index's '[1.2 s]') blanked."""
    out = {}
    for f in sorted(folder.rglob("*")):
        if f.is_file():
            data = f.read_bytes()
            data = re.sub(rb'"seconds": [0-9.]+', b'"seconds": T', data)
            out[str(f.relative_to(folder))] = re.sub(rb"\[[0-9.]+ s\]", b"[T s]", data)
    return out


def test_api_result_is_what_the_command_prints(tmp_path, capsys):
    """volerr.demo returns a result whose summary() is the console text of 'volerr demo',
    and the worker processes write the same files as one process."""
    import volerr
    from volerr.cli import main

    res = volerr.demo(out=tmp_path / "api", only=QUICK, jobs=1)
    assert [r["section"] for r in res.data] == QUICK
    lines = res.summary().splitlines()
    assert len(lines) == len(QUICK) + 1 and lines[-1].startswith("report: ")
    assert "R_eff 0.99" in lines[0] and "verdict against" in lines[1]
    assert len(repr(res).splitlines()) == 1
    capsys.readouterr()
    assert main(["demo", "--out", str(tmp_path / "cli"), "--only", *QUICK, "--jobs", "2"]) == 0
    printed = capsys.readouterr().out.splitlines()
    strip = re.compile(r"\[[0-9.]+ s\]$|\([0-9]+ s\)$")
    assert [strip.sub("", x) for x in printed[:-1]] == [strip.sub("", x) for x in lines[:-1]]
    assert _files(tmp_path / "api") == _files(tmp_path / "cli")


def test_only_names_a_section(tmp_path):
    import volerr

    with pytest.raises(volerr.InputError, match="not a section"):
        volerr.demo(out=tmp_path / "x", only=["probe", "nothing"])
    assert not (tmp_path / "x").exists()
