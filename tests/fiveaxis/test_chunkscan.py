"""The whole-chunk path of the compensation against the line-by-line rule: the scanner finds
exactly the lines the word regex accepts and parses their numbers as Python's float does; the
array formatter writes what gcode.format_number writes; random programs mixing plain lines,
G90/G91, G28, comments, lower case, unknown axes and missing words compensate to the same
bytes with the whole-chunk path on and off, at several chunk sizes."""

import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis import program
from volerr.nc import chunkscan, gcode
from volerr.errors import InputError
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

AXES = ("X", "Y", "Z", "B", "C")
NUM = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)")

number = st.one_of(
    st.decimals(min_value=-1000, max_value=1000, allow_nan=False, places=4).map(str),
    st.sampled_from(["1.", ".5", "+2", "-0", "+.25", "007", "12.3456789012345678", "1.2.3",
                     "--1", "+", ".", "0", "1", "00", "01", "2", "3", "98", "128", "129.",
                     "6", "-0000000000000000012.5", "123456789012345678.5",
                     "1234567890123456789.1.2", "12345678901234567-8", "+1234567890123456"]))
word = st.tuples(st.sampled_from([*"XYZBCxyzbNFGgMmAUSTHDIJKk", "A3=", "b3 =", "C3= ", "B3"]),
                 st.sampled_from(["", " ", "\t"]), number)
comment = st.sampled_from(["(cut X1)", "(a;b)", "; fin (x", ";", "()", "(", ")", "(G2 M98)",
                           "(\u00d810 \u2014)"])
piece = st.one_of(word.map(lambda w: "".join(w)), comment)
plain = st.lists(st.tuples(st.sampled_from(["", " ", "  "]), piece), min_size=0,
                 max_size=6).map(lambda ws: "".join(sp + w for sp, w in ws))
line = st.one_of(plain, plain.map(lambda s: s + " "), st.sampled_from(
    ["(comment X1)", "X1 (c)", "%", "G90", "G91", "X1 ; c", "X1 #1", "  ", "/X1", "X(c)1",
     "G1 X1 (a) Y2 ; b", "N10 G01 X1. F500 S1200 M8 T3"]))


def reference_fast(body: str) -> list | None:
    """The words of a line the interpreter would read as a plain line (a motion block in the
    mode in force, or nothing): tokens of the line-by-line tokenizer, G only 0 / 1, M not one
    the interpreter acts on, no foreign axis, no axis twice; None for any other line."""
    try:
        toks = gcode.tokenize(body)
    except InputError:
        return None
    if any(t.kind == "other" for t in toks) and body.strip():
        return None
    words = [t for t in toks if t.kind == "word"]
    axes_ = [t.letter for t in words if t.letter in AXES + gcode.VECTOR]
    if len(set(axes_)) != len(axes_) or any(t.letter in "AU" for t in words):
        return None
    for t in words:
        if t.letter == "G" and t.value not in (0.0, 1.0):
            return None
        if t.letter == "M" and round(t.value) in gcode.SPECIAL_M:
            return None
    return words


@settings(max_examples=200, deadline=None)
@given(st.lists(st.tuples(line, st.sampled_from(["\n", "\r\n", "\r"])), max_size=8))
def test_scan_finds_the_plain_lines_and_their_numbers(lines):
    segs = [a + b for a, b in lines]
    sc = chunkscan.scan(segs, AXES)
    codes = {"T": chunkscan.TRACKED["T"], "H": chunkscan.TRACKED["H"],
             "D": chunkscan.TRACKED["D"], "G": chunkscan.G_WORD, "M": chunkscan.M_WORD}
    for i, (body, _) in enumerate(lines):
        words = reference_fast(body)
        assert bool(sc.fast[i]) == (words is not None), body
        if words is not None:
            k = sc.line == i
            cols = AXES + gcode.VECTOR          # the tool vector I J K (A3= B3= C3=) after the axes
            words = [t for t in words if t.letter in cols or t.letter in codes]
            assert list(sc.axis[k]) == [cols.index(t.letter) if t.letter in cols else
                                        codes[t.letter] for t in words]
            texts = [body[t.num_start:t.num_end] for t in words]
            assert [sc.text[s:e] for s, e in zip(sc.num_start[k], sc.num_end[k])] == texts
            vals = sc.value[k]
            for t, v in zip(texts, vals):
                assert v == float(t) and np.signbit(v) == np.signbit(float(t)), t
            assert list(sc.frac[k]) == [len(t.split(".")[1]) if "." in t else -1 for t in texts]
            assert list(sc.plus[k]) == [t.startswith("+") for t in texts]


@settings(max_examples=300, deadline=None)
@given(st.lists(st.tuples(
    st.one_of(st.floats(-1e4, 1e4), st.integers(-10 ** 6, 10 ** 6).map(lambda i: i / 2000),
              st.sampled_from([0.5, 2.5, -0.0, 1e-9, -4.9999e-5, 0.00015, 1e16])),
    st.integers(0, 9), st.sampled_from(["", "1.", "+1.25", "10", "-3.1234", "+7", ".5"])),
    min_size=1, max_size=20))
def test_format_numbers_is_format_number(items):
    v = [a for a, _, _ in items]
    nd = [d for _, d, _ in items]
    t = [s for _, _, s in items]
    keep = [len(s) - s.index(".") - 1 if "." in s else -1 for s in t]
    plus = [s.startswith("+") for s in t]
    got = chunkscan.format_numbers(v, nd, keep, plus, lambda i: t[i])
    want = [gcode.format_number(a, d, s) for a, d, s in items]
    assert got == want
    # the values of the texts come without parsing them: what float() of the text gives
    _, lens, vals = chunkscan.format_bytes(v, nd, keep, plus, lambda i: t[i])
    assert list(lens) == [len(w) for w in want]
    for w, x in zip(want, vals):
        assert x == float(w) and np.signbit(x) == np.signbit(float(w)), w


@settings(max_examples=200, deadline=None)
@given(st.text("ab \n\r;(", max_size=40), st.data())
def test_edits_replace_their_spans(text, data):
    """writer.Edits (spans replaced in the chunk's bytes, some as byte arrays, some as
    strings) against slicing the text piece by piece."""
    from volerr.nc.writer import Edits

    cuts = sorted(data.draw(st.lists(st.integers(0, len(text)), max_size=12)))
    spans = list(zip(cuts[0::2], cuts[1::2]))
    new = [data.draw(st.text("0123456789.-+XYZ\n", max_size=6)) for _ in spans]
    as_bytes = [data.draw(st.booleans()) for _ in spans]
    edits = Edits()
    k = 0
    while k < len(spans):
        if as_bytes[k]:             # a run of byte edits, as Writer.run adds them
            j = k
            while j < len(spans) and as_bytes[j]:
                j += 1
            texts = new[k:j]
            edits.add_bytes([s0 for s0, _ in spans[k:j]], [e0 for _, e0 in spans[k:j]],
                            np.frombuffer("".join(texts).encode("ascii"), np.uint8),
                            [len(t) for t in texts])
            k = j
        else:
            edits.add(*spans[k], new[k])
            k += 1
    want, prev = [], 0
    for (s0, e0), t in zip(spans, new):
        want += [text[prev:s0], t]
        prev = e0
    assert edits.apply(text) == "".join(want) + text[prev:]


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=5)
    return m, ErrorFunctions.from_dir(d, m)


def _range(a):
    return {"X": (-200, 200), "Y": (-200, 200), "Z": (20, 380), "B": (1, 100),
            "C": (0, 359)}[a]


def _value(rng, a):
    return rng.uniform(*_range(a))


def random_program(seed: int, n_lines: int = 120) -> str:
    """A program of ``n_lines`` random lines (plus its head and tail); a shorter program's
    random lines begin the longer one of the same seed."""
    rng = np.random.default_rng(seed)
    out = ["%", "G90 G1 X0 Y0 Z100 F500" if seed % 2 else "G90 G1 X0 Y0 Z100 B10 C5"]
    incr = False
    cur = {"X": 0.0, "Y": 0.0, "Z": 100.0, "B": 10.0, "C": 5.0}
    for i in range(n_lines):
        r = rng.uniform()
        if r < 0.04:
            out.append("G91" if not incr else "G90")
            incr = not incr
            continue
        if r < 0.06 and not incr:
            out.append("G28 Z0")
            continue
        if r < 0.08:
            out.append("(plain comment)")
            continue
        axes = [a for a in AXES if rng.uniform() < 0.55] or ["X"]
        words = []
        for a in axes:
            target = float(np.clip(cur[a] + rng.uniform(-2, 2), *_range(a))) if incr \
                else _value(rng, a)
            nd = int(rng.integers(0, 5))
            v = round(target - cur[a], nd) if incr else target
            cur[a] = cur[a] + v if incr else round(target, nd)
            txt = f"{v:.{nd}f}" + ("." if nd == 0 and rng.uniform() < 0.2 else "")
            gap = " " if seed % 4 == 2 and rng.uniform() < 0.3 else ""
            words.append((a.lower() if seed % 3 == 0 else a) + gap + txt)
        # what post-processors write: a motion word on every line, N F S T M words,
        # comments in ( ) and after ;
        if rng.uniform() < 0.6:
            words.insert(0, str(rng.choice(["G1", "G01", "G0", "g00", "G1.0"])))
        if rng.uniform() < 0.3:
            words.append(str(rng.choice(["F1500.", "S12000", "M8", "T3", "F800 M3", "H2"])))
        if rng.uniform() < 0.2:
            words.insert(int(rng.integers(0, len(words) + 1)), "(cut X1)")
        if rng.uniform() < 0.2:
            words.insert(0, f"N{i}")
        sep = "" if seed % 4 == 1 else " "
        tail = "  " if rng.uniform() < 0.1 else (" ; fin (x" if rng.uniform() < 0.15 else "")
        out.append(sep.join(words) + tail)
    if incr:
        out.append("G90")
    if seed >= 8:       # a TCPM program (rotary angles): the words are tool tip and angles
        out = out[:2] + ["G43.4 H1 (TCPM)"] + out[2:] + ["G49"]
    end = ["\n", "\r\n", "\r"][seed % 3]
    return end.join(out) + end


@pytest.mark.parametrize("seed", range(10))
@pytest.mark.parametrize("orientation", [False, True])
def test_whole_chunk_path_writes_the_line_by_line_bytes(setup, seed, orientation, monkeypatch):
    """The plain programs (seeds 0-7) have 60 random lines, the TCPM programs 120 (the
    suite's time, session 9: 120 plain lines before).  A chunk of one line costs a solve per
    line (most of this test's time); at 60 lines the eight plain programs still hold 11
    switches to G91 and 11 back, 7 G28 blocks, 19 comment-only lines and 48 T / H words (18,
    18, 12, 30, 96 at 120 lines), chunks of 7 and 25 lines still end 8 and 2 times inside
    every program, and each deliberate break of the whole-chunk path tried
    (benchmarks/suite_time/session9_nonloop.md) fails here as it did at 120 lines.  The TCPM
    programs keep 120 lines: at 60, seed 8 has 10 TCPM blocks."""
    m, funcs = setup
    text = random_program(seed, 120 if seed >= 8 else 60)
    init = {"B": 10.0, "C": 5.0} if seed % 2 else {}
    kw = {}
    if seed >= 8:       # TCPM: the axis positions may leave the travel and the tables
        funcs = ErrorFunctions(funcs.tables, funcs.constants, m, extrapolate=True)
        kw = {"tool_length": 100.0, "check_travel": False}
    monkeypatch.setattr(program, "WHOLE_CHUNK", False)
    ref = compensate_program(m, funcs, text, orientation=orientation, initial=init, **kw)
    monkeypatch.setattr(program, "WHOLE_CHUNK", True)
    assert ref.text != text
    if seed >= 8:
        assert ref.summary()["tcpm_blocks"] > 50
    for k in (None, 1, 7, 25) if seed < 8 else (None, 13):
        got = compensate_program(m, funcs, text, orientation=orientation, initial=init,
                                 chunk_lines=k, **kw)
        assert got.text == ref.text, k
        assert [(r.line, r.status, r.output) for r in got.reports] == \
            [(r.line, r.status, r.output) for r in ref.reports]


def test_text_beyond_latin1_keeps_its_characters(setup, monkeypatch):
    """A program given as a str may hold characters a latin-1 file cannot (an em dash, a
    Greek letter in a comment): the edits are then made on the string, with the same result
    as the line-by-line path, and the characters stay."""
    m, funcs = setup
    text = random_program(3).replace("(plain comment)", "(Ø10 — Ω roughing)")
    assert "Ω" in text
    monkeypatch.setattr(program, "WHOLE_CHUNK", False)
    ref = compensate_program(m, funcs, text)
    monkeypatch.setattr(program, "WHOLE_CHUNK", True)
    got = compensate_program(m, funcs, text)
    assert got.text == ref.text and got.text != text
    assert got.text.count("(Ø10 — Ω roughing)") == text.count("(Ø10 — Ω roughing)")


def vector_program(m, seed: int, n: int, siemens: bool) -> str:
    """A TCPM tool-vector program as post-processors write it (``G43.5`` with ``I J K``, or
    ``TRAORI`` with ``A3= B3= C3=``): N numbers, G01 / G0, F, comments, the vector not always
    complete or written, vertical tool vectors (the C axis undetermined), a few rotary-angle
    blocks (TRAORI), a switch out of TCPM and back."""
    rng = np.random.default_rng(seed)
    q = np.column_stack([rng.uniform(-150, 150, n), rng.uniform(-150, 150, n),
                         rng.uniform(180, 380, n), rng.uniform(0, 80, n),
                         np.cumsum(rng.uniform(-40, 40, n)) % 720 - 360])
    vertical = rng.uniform(size=n) < 0.1
    q[vertical, 3] = 0.0
    f = m.forward(q, np.tile([0.0, 0.0, -100.0], (n, 1)))
    f[vertical, 3:6] = [0.0, 0.0, 1.0]
    names = ("A3=", "B3=", "C3=") if siemens else ("I", "J", "K")
    on = "TRAORI" if siemens else "G43.5 H1"
    out = ["%", "N1 G90 G17 T1 M6", "N2 G0 X0 Y0 Z300 B0 C0", f"N3 {on}"]
    for i, row in enumerate(f):
        words = [f"X{row[0]:.4f}", f"Y{row[1]:.4f}", f"Z{row[2]:.4f}"]
        keep = rng.uniform(size=3) < 0.9
        words += [f"{a}{v:.6f}" for a, v, k in zip(names, row[3:], keep) if k or i == 0]
        r = rng.uniform()
        if r < 0.01:
            out += ["G49" if not siemens else "TRAFOOF", "G0 Z380", on]
        elif r < 0.02 and siemens:
            words = words[:3] + [f"B{q[i, 3]:.3f}", f"C{q[i, 4]:.3f}"]    # rotary angles
        elif r < 0.04:
            words = words[:2]                    # the tool vector held
        head = f"N{10 + i} " + ("G0 " if r > 0.97 else "G01 ")
        out.append(head + " ".join(words) + (" F1500." if r < 0.5 else "")
                   + (" (cut)" if r < 0.3 else " ; fin" if r < 0.4 else ""))
    return "\n".join(out + ["G49" if not siemens else "TRAFOOF", "M30", "%"]) + "\n"


@pytest.mark.parametrize("siemens", [False, True])
def test_tool_vector_programs_whole_chunk_equal_line_by_line(setup, siemens, monkeypatch):
    """TCPM tool-vector programs go through the whole-chunk path (runs of plain lines with
    the vector words) and give the bytes and reports of the line-by-line path, for any chunk
    size; their rotary axes are set by the vectors (no axis taken at 0 deg).

    2500 blocks (issue 42 item 7: 5000 before, twice the time): chunks of 997 lines still
    end twice inside the program, and the program's occasional blocks still come many times
    each (counted on these two programs: 25 and 26 switches out of TCPM and back, 70-80
    blocks with the vector held, 200-220 vertical vectors, 29 rotary-angle blocks in
    TRAORI)."""
    from volerr.nc import interpret as nc_interpret

    m, funcs = setup
    funcs = ErrorFunctions(funcs.tables, funcs.constants, m, extrapolate=True)
    n = 2500
    text = vector_program(m, 4 + siemens, n, siemens)
    kw = {"tool_length": 100.0, "check_travel": False}
    texts = set()
    for k in (None, 997):
        monkeypatch.setattr(program, "WHOLE_CHUNK", False)
        ref = compensate_program(m, funcs, text, chunk_lines=k, **kw)
        monkeypatch.setattr(program, "WHOLE_CHUNK", True)
        s = ref.summary()
        assert s["tcpm_blocks"] > 0.9 * n and ref.text != text and ref.assumed_zero == ()
        got = compensate_program(m, funcs, text, chunk_lines=k, **kw)
        assert got.text == ref.text, k
        assert [(r.line, r.status, r.output) for r in got.reports] == \
            [(r.line, r.status, r.output) for r in ref.reports], k
        texts.add(got.text)
    assert len(texts) == 1
    # most lines were read in runs with the tool-vector columns
    segs = text.splitlines(keepends=True)
    interp = gcode.Interpreter(m.axes, {}, lambda tools, where: 100.0)
    b = nc_interpret.interpret(segs, 1, interp, m, 4)
    in_runs = sum(j - i for i, j, cols in b.runs if cols == len(m.axes) + 3)
    assert in_runs > 0.9 * len(segs), in_runs


#: tool-vector programs in the shapes posts write (issue 36 item 6): (head, line, ending);
#: the line format gets N, then X Y Z and the vector
POST_SHAPES = {
    "bare": ("G90 G21\nT1 M6\nG43.5 H1\n", "G1 X{:.4f} Y{:.4f} Z{:.4f} I{:.6f} J{:.6f} "
             "K{:.6f} F2000", "\n"),
    "comment": ("G90 G21\nT1 M6\nG43.5 H1\n", "G1 X{:.4f} Y{:.4f} Z{:.4f} I{:.6f} "
                "J{:.6f} K{:.6f} F2000 (cut)", "\n"),
    "n_crlf": ("%\r\nN1 G90 G21\r\nN2 T1 M6\r\nN3 G43.5 H1\r\n", "N{} G01 X{:.4f} Y{:.4f} "
               "Z{:.4f} I{:.6f} J{:.6f} K{:.6f} F2000.", "\r\n"),
    "rotary_first": ("G90 G1 X0 Y0 Z300 B10 C0\nT1 M6\nG43.5 H1\n", "X{:.4f} Y{:.4f} "
                     "Z{:.4f} I{:.6f} J{:.6f} K{:.6f}", "\n"),
    "f_once": ("G90\nT1 M6\nG43.5 H1\nG1 F2000\n", "X{:.4f} Y{:.4f} Z{:.4f} I{:.6f} "
               "J{:.6f} K{:.6f}", "\n"),
    "traori": ("G90\nT1 M6\nTRAORI\n", "N{} G01 X{:.4f} Y{:.4f} Z{:.4f} A3={:.6f} "
               "B3={:.6f} C3={:.6f} F2000", "\n"),
}


def post_program(m, shape: str, n: int, seed: int = 7) -> str:
    head, fmt, end = POST_SHAPES[shape]
    rng = np.random.default_rng(seed)
    q = np.column_stack([rng.uniform(-150, 150, n), rng.uniform(-150, 150, n),
                         rng.uniform(180, 380, n), rng.uniform(1, 80, n),
                         rng.uniform(0, 359, n)])
    f = m.forward(q, np.tile([0.0, 0.0, -100.0], (n, 1)))
    numbered = fmt.startswith("N")
    body = [fmt.format(*(((10 + i,) if numbered else ()) + tuple(r))) for i, r in
            enumerate(f)]
    return head + end.join(body) + end + "M30" + end


@pytest.mark.parametrize("shape", list(POST_SHAPES))
def test_every_post_shape_of_a_vector_program_takes_the_whole_chunk_path(setup, shape,
                                                                         monkeypatch):
    """With or without comments, N numbers, F words, CRLF, rotary words before the TCPM
    block: the lines are read in tool-vector runs (not one by one) and the output is the
    line-by-line path's, byte for byte."""
    from volerr.nc import interpret as nc_interpret

    m, funcs = setup
    funcs = ErrorFunctions(funcs.tables, funcs.constants, m, extrapolate=True)
    text = post_program(m, shape, 300)
    kw = {"tool_length": 100.0, "check_travel": False}
    monkeypatch.setattr(program, "WHOLE_CHUNK", False)
    ref = compensate_program(m, funcs, text, **kw)
    monkeypatch.setattr(program, "WHOLE_CHUNK", True)
    assert ref.summary()["tcpm_blocks"] == 300 and ref.text != text
    got = compensate_program(m, funcs, text, chunk_lines=97, **kw)
    assert got.text == ref.text
    segs = text.splitlines(keepends=True)
    interp = gcode.Interpreter(m.axes, {}, lambda tools, where: 100.0)
    b = nc_interpret.interpret(segs, 1, interp, m, 4)
    in_runs = sum(j - i for i, j, cols in b.runs if cols == len(m.axes) + 3)
    assert in_runs >= 299, (shape, in_runs)
