"""Step 6 of the compensation (:mod:`volerr.fiveaxis.program`): the output text of a chunk.

Only the numbers of the words that carry positions change (axes; under TCPM the tool tip and
the orientation; the centre words of an arc kept as an arc); a word is added to a block only
where the value the controller would hold differs from the one to write (in ``G91``, a
non-zero increment).  A linearised arc (:mod:`volerr.nc.arcs`) becomes its own line
turned into the first straight move (``G2``/``G3`` -> ``G1``, the centre words dropped) and one
new line per further segment.  A :class:`~volerr.nc.gcode.ControllerState` follows the
program as written (the same rule the interpreter applies to the program as read), and the
modal motion as written: an arc block that relied on a modal ``G2``/``G3`` gets the word again
after a linearised arc has left the output in ``G1``.

Lines interpreted together (runs of plain lines) are written together: their number spans are
replaced in the chunk's bytes at once (:class:`Edits`).
"""

from __future__ import annotations

import numpy as np

from . import chunkscan, gcode
from .arcs import CENTRE_WORD, PLANES


def _straight(m: int) -> bool:
    return m in (0, 1)


def _letter_words(letters, want_row, nd_row, words: dict, pos: dict, incremental: bool,
                  extra_inc=frozenset(), plus: str = ""):
    """The words of one block: for every letter with a value to write (not NaN), the
    programmed word rewritten where the value moves by half a step or more, a word added
    where the controller holds another value (written with a ``+`` when ``plus``) -> (new
    number texts, added number texts, the (letter, value) pairs the controller reads)."""
    fmt = gcode.format_number
    new_values, added, values = {}, {}, []
    for a, want, nd in zip(letters, want_row, nd_row):
        if want != want:
            continue
        half = 0.5 * 10.0 ** (-nd)
        w = words.get(a)
        if (incremental and a not in gcode.VECTOR) or a in extra_inc:
            prev = pos[a]
            if prev is None:
                if w is not None:
                    values.append((a, w[0]))
                continue
            inc = want - prev
            if w is not None:
                if abs(inc - w[0]) >= half:
                    txt = fmt(inc, nd, w[1])
                    new_values[a] = txt
                    values.append((a, float(txt)))
                else:
                    values.append((a, w[0]))
            elif abs(inc) >= half:
                txt = fmt(inc, nd, plus)
                added[a] = txt
                values.append((a, float(txt)))
        else:
            if w is not None:
                if abs(want - w[0]) >= half:
                    txt = fmt(want, nd, w[1])
                    new_values[a] = txt
                    values.append((a, float(txt)))
                else:
                    values.append((a, w[0]))
            elif pos[a] is None or abs(want - pos[a]) >= half:
                txt = fmt(want, nd, plus)
                added[a] = txt
                values.append((a, float(txt)))
    return new_values, added, values


class Writer:
    """Writes the chunks of one program: ``written`` the controller state of the output,
    ``letters`` the columns of the values to write (axes, then ``I J K``), ``spaced`` the
    program's word separation, ``vector_words`` the spelling of added tool-vector words
    (``{"I": "I", ...}`` or ``{"I": "A3=", ...}``), ``plus`` "+" where added words carry a
    sign."""

    def __init__(self, written: gcode.ControllerState, axes, spaced: bool,
                 vector_words: dict | None = None, plus: str = ""):
        self.written = written
        self.axes = tuple(axes)
        self.letters = (*self.axes, *gcode.VECTOR)
        self.spaced = spaced
        self.vector_words = vector_words or {v: v for v in gcode.VECTOR}
        #: modal motion of the output (0 1 straight, 2 3 arcs)
        self.motion = 0
        #: "+": added words carry an explicit sign (Heidenhain)
        self.plus = plus

    # -----------------------------------------------------------------------------------
    def chunk(self, b, w_out: np.ndarray, arcs: dict) -> str:
        """The chunk's output text (:class:`~volerr.nc.interpret.Blocks` ``b``): original
        bytes except the changed / added words.  ``arcs``: row -> (ArcPath, ArcResult)."""
        edits = Edits()
        w_list = nd_list = None
        starts = b.scan.start
        runs = iter(b.runs)
        nxt = next(runs, None)
        i, n = 0, len(b.segs)
        while i < n:
            if nxt is not None and nxt[0] == i:
                self.run(b, nxt[0], nxt[1], w_out, edits, nxt[2])
                self.motion = 1 if not _straight(self.motion) else self.motion
                i = nxt[1]
                nxt = next(runs, None)
                continue
            line, step = b.slow[i]
            r = int(b.row[i])
            if r >= 0 and w_list is None:
                w_list, nd_list = w_out.tolist(), b.nd.tolist()
            arc = arcs.get(r) if r >= 0 else None
            if arc is not None and not arc[1].kept:
                t = self.linearised(line, step, arc, r, b, w_list, nd_list)
            else:
                t = self.line(line, step, r, w_list, nd_list, arc)
            if t != b.segs[i]:
                edits.add(int(starts[i]), int(starts[i]) + len(b.segs[i]), t)
            i += 1
        return edits.apply(b.scan.text)

    # -----------------------------------------------------------------------------------
    def _motion_word(self, step, added: dict) -> None:
        """An arc block that relies on a modal G2 / G3 the output no longer holds gets it."""
        if step.kind in ("motion", "arc") and not step.motion_word:
            if _straight(self.motion) != _straight(step.motion) or \
                    (not _straight(step.motion) and self.motion != step.motion):
                added["G"] = str(step.motion)
        if step.kind in ("motion", "arc") or step.motion_word:
            self.motion = step.motion

    def line(self, line, step, r, w_list, nd_list, arc=None) -> str:
        """One line written block by block (the exact rule; :meth:`run` does the same for a
        run of plain lines in absolute mode at once)."""
        written = self.written
        pos = written.position
        added_g = {}
        if step is not None:
            self._motion_word(step, added_g)
        if r < 0:
            if step is not None:
                written.apply(step)
            if added_g:
                return gcode.rewrite_line(line, {}, added_g, self.spaced)
            return line.body + line.ending
        letters = self.letters
        items = line.items()
        words = {a: (v, txt) for a, v, txt in items if a in letters}
        if step.kind == "arc":
            # I J K of an arc are its centre, not a tool vector
            words = {a: w for a, w in words.items() if a not in gcode.VECTOR}
        written.apply(gcode.Step("none", [], False, forget=step.forget))
        start = {a: pos[a] for a in self.axes}
        new_values, added, values = _letter_words(letters, w_list[r], nd_list[r], words, pos,
                                                  step.incremental, step.incremental_words,
                                                  self.plus)
        for a in list(added):
            if a in gcode.VECTOR:
                added[self.vector_words[a]] = added.pop(a)
        written.apply(gcode.Step("motion", values, step.incremental,
                                 incremental_words=step.incremental_words))
        if arc is not None:
            self._centre_words(line, step, arc[0], arc[1], start, items, nd_list[r],
                               new_values, added)
        added.update(added_g)
        return (gcode.rewrite_line(line, new_values, added, self.spaced)
                if (new_values or added) else line.body + line.ending)

    def _centre_words(self, line, step, path, res, start, items, nd_row, new_values,
                      added) -> None:
        """Centre words of an arc kept as an arc: ``I J K`` the corrected centre minus the
        start as written, or ``R`` the mean of the corrected radii at start and end."""
        fmt = gcode.format_number
        names = PLANES[step.arc.plane]
        a, b = names[0], names[1]
        end = {x: self.written.position[x] for x in (a, b)}
        cw = {t[0]: (t[1], t[2]) for t in items if t[0] in ("I", "J", "K", "R")}
        nd = max(int(nd_row[self.axes.index(a)]), int(nd_row[self.axes.index(b)]))
        half = 0.5 * 10.0 ** (-nd)
        if step.arc.radius is not None and not step.arc.centre:
            c = res.centre
            r_end = float(np.hypot(end[a] - c[0], end[b] - c[1]))
            r_start = float(np.hypot(start[a] - c[0], start[b] - c[1]))
            want = np.sign(step.arc.radius) * 0.5 * (r_end + r_start)
            v, txt = cw["R"]
            if abs(want - v) >= half:
                new_values["R"] = fmt(want, max(nd, gcode.decimals(txt)), txt)
            return
        for k, ax in enumerate((a, b)):
            letter = CENTRE_WORD[ax]
            want = float(res.centre[k] - start[ax])
            w = cw.get(letter)
            if w is not None:
                d = max(nd, gcode.decimals(w[1]))
                if abs(want - w[0]) >= 0.5 * 10.0 ** (-d):
                    new_values[letter] = fmt(want, d, w[1])
            elif abs(want) >= half:
                added[letter] = fmt(want, nd)

    def linearised(self, line, step, arc, r, b, w_list, nd_list) -> str:
        """An arc block written as straight moves through the compensated points: its own
        line the first (``G1``, centre words dropped), one new line per further point."""
        path, res = arc
        written = self.written
        pos = written.position
        nd_row = nd_list[r]
        points = res.points
        axes = self.axes
        end = w_list[r]
        texts = []
        for k, p in enumerate(points):
            want = list(end[:len(axes)]) if k == len(points) - 1 else list(p)
            if k == 0:
                words = {a: (v, txt) for a, v, txt in line.items() if a in axes}
                new_values, added, values = _letter_words(axes, want, nd_row, words, pos,
                                                          step.incremental)
                has_g = any(t.kind == "word" and t.letter == "G" and round(t.value) in (2, 3)
                            for t in line.tokens)

                def edit(t, nv=new_values):
                    if t.letter == "G" and round(t.value) in (2, 3):
                        num = line.body[t.num_start:t.num_end]
                        return "0" * (len(num) - 1) + "1" if num.isdigit() else "1"
                    if t.letter in ("I", "J", "K", "R"):
                        return gcode.REMOVE
                    return nv.get(t.letter)
                if not has_g:
                    added = {"G": "1", **added}
                text = gcode.rewrite_tokens(line, edit, added, self.spaced)
                ending = line.ending or "\n"
                text = text[:len(text) - len(line.ending)]
            else:
                _, added, values = _letter_words(axes, want, nd_row, {}, pos, step.incremental)
                if not added:
                    continue        # the point rounds to where the controller is
                sep = " " if self.spaced else ""
                lower = line.body.lstrip()[:1].islower()
                text = sep.join(f"{a.lower() if lower else a}{v}" for a, v in added.items())
            written.apply(gcode.Step("motion", values, step.incremental))
            texts.append(text)
        self.motion = 1
        return ending.join(texts) + line.ending

    # -----------------------------------------------------------------------------------
    def run(self, b, i0: int, i1: int, w_out: np.ndarray, edits, cols: int | None = None
            ) -> None:
        """The plain lines ``i0 .. i1 - 1`` (absolute mode) written together: ``edits`` gets
        (start, end, text) replacements of the chunk text; ``written`` is updated.  ``cols``:
        the columns of the words (the axes, or with the tool vector ``I J K``).

        A programmed word is rewritten where the value to write differs from it by half a
        step or more (:meth:`_programmed`); an axis the line does not program gets a word
        where the controller (as written so far) holds another value (:meth:`_added`)."""
        sc = b.scan
        cols = len(self.axes) if cols is None else cols
        letters = self.letters[:cols]
        w = sc.words(i0, i1)
        ax = (sc.axis[w] >= 0) & (sc.axis[w] < cols)
        words = {k: getattr(sc, k)[w][ax] for k in ("axis", "value", "num_start", "num_end",
                                                     "frac", "plus")}
        words["line"] = sc.line[w][ax] - i0
        m = i1 - i0
        row = b.row[i0:i1]
        ci, flat, lens, wvals = self._programmed(b, words, row, w_out, sc.text)
        # positions held after every line from the programmed words (as written)
        wl, wa = words["line"], words["axis"]
        val = np.full((m, cols), np.nan)
        val[wl, wa] = wvals
        has = np.zeros((m, cols), dtype=bool)
        has[wl, wa] = True
        last = np.where(has, np.arange(m)[:, None], -1)
        np.maximum.accumulate(last, axis=0, out=last)
        added, last_add = self._added(b, row, has, val, last, w_out)
        pos = self.written.position
        for c, a in enumerate(letters):
            li = int(last[m - 1, c]) if m else -1
            la = last_add.get(c)
            if la is not None and la[0] > li:
                pos[a] = la[1]
            elif li >= 0:
                pos[a] = float(val[li, c])
        span_s, span_e = words["num_start"][ci], words["num_end"][ci]
        if not added:
            edits.add_bytes(span_s, span_e, flat, lens)
            return
        # a line that gets a word is rewritten whole, else its numbers are replaced
        texts = chunkscan.split_texts(flat, lens)
        line_of = wl[ci]
        by_line = {}
        for k, li in enumerate(line_of.tolist()):
            if li in added:
                by_line.setdefault(li, {})[letters[int(wa[ci[k]])]] = texts[k]
        own = [(s0, e0, t) for k, (s0, e0, t) in enumerate(zip(span_s.tolist(), span_e.tolist(),
                                                              texts))
               if int(line_of[k]) not in added]
        for li, add in added.items():
            i = i0 + li
            s0 = int(sc.start[i])
            own.append((s0, s0 + len(b.segs[i]), gcode.rewrite_line(
                b.line(i), by_line.get(li, {}), add, self.spaced)))
        own.sort()
        for s0, e0, t in own:
            edits.add(s0, e0, t)

    @staticmethod
    def _programmed(b, words, row, w_out, text):
        """The programmed words of known blocks rewritten where the value moves by half a
        step -> (indices of the words that change, their texts as bytes and lengths
        (:func:`volerr.nc.chunkscan.format_bytes`), every word's value as written)."""
        wr = row[words["line"]]
        known = wr >= 0
        kr, ka = wr[known], words["axis"][known]
        want = w_out[kr, ka]
        nd = b.nd[kr, ka]
        wv = words["value"]
        change = np.abs(want - wv[known]) >= 0.5 * 10.0 ** (-nd.astype(float))
        ci = np.flatnonzero(known)[change]
        span_s, span_e = words["num_start"][ci], words["num_end"][ci]
        flat, lens, new_vals = chunkscan.format_bytes(
            want[change], nd[change], words["frac"][ci], words["plus"][ci],
            lambda k: text[span_s[k]:span_e[k]])
        wvals = wv.copy()
        wvals[ci] = new_vals
        return ci, flat, lens, wvals

    def _added(self, b, row, has, val, last, w_out):
        """Words added for the axes without a word in a known block, where the controller
        (as written so far) holds another value: a chain along the lines, followed one entry
        at a time -> (line -> {axis: text}, axis index -> (line, value) of its last added
        word)."""
        absent = np.argwhere((row >= 0)[:, None] & ~has)
        absent = absent[~np.isnan(w_out[row[absent[:, 0]], absent[:, 1]])]
        added, last_add = {}, {}
        if not len(absent):
            return added, last_add
        names = [self.vector_words.get(a, a) for a in self.letters]
        cand_w = w_out[row[absent[:, 0]], absent[:, 1]]
        cand_nd = b.nd[row[absent[:, 0]], absent[:, 1]]
        li_prev = last[absent[:, 0], absent[:, 1]]
        held = val[np.maximum(li_prev, 0), absent[:, 1]]
        start = [self.written.position[a] for a in self.letters]
        fmt = gcode.format_number
        for (li, c), want_a, nd_a, pi, h in zip(absent.tolist(), cand_w.tolist(),
                                                cand_nd.tolist(), li_prev.tolist(),
                                                held.tolist()):
            la = last_add.get(c)
            if la is not None and la[0] > pi:
                prev = la[1]
            elif pi >= 0:
                prev = h
            else:
                prev = start[c] if la is None else la[1]
            if prev is None or abs(want_a - prev) >= 0.5 * 10.0 ** (-nd_a):
                txt = fmt(want_a, nd_a)
                added.setdefault(li, {})[names[c]] = txt
                last_add[c] = (li, float(txt))
        return added, last_add


class Edits:
    """Replacements (start, end, new text) of a chunk's text, in text order; most come as
    arrays of spans with their new texts as ASCII bytes (:meth:`Writer.run`), the others one
    by one as strings (lines written by the rule, lines that get a word)."""

    def __init__(self):
        self.batches = []   # (starts, ends, new texts: (flat uint8, lengths) or list of str)
        self.one = []       # pending single edits (start, end, str)

    def add(self, start: int, end: int, text: str) -> None:
        self.one.append((start, end, text))

    def add_bytes(self, starts, ends, flat, lens) -> None:
        self._flush()
        self.batches.append((np.asarray(starts, np.int64), np.asarray(ends, np.int64),
                             (flat, np.asarray(lens, np.int64))))

    def _flush(self) -> None:
        if self.one:
            s0, e0, t = zip(*self.one)
            self.batches.append((np.array(s0, np.int64), np.array(e0, np.int64), list(t)))
            self.one = []

    def apply(self, text: str) -> str:
        """``text`` with the replacements made (spans in text order, not overlapping)."""
        self._flush()
        if not self.batches:
            return text
        starts = np.concatenate([s0 for s0, _, _ in self.batches])
        ends = np.concatenate([e0 for _, e0, _ in self.batches])
        try:
            b = np.frombuffer(text.encode("latin-1"), np.uint8)
            new = [t if isinstance(t, tuple) else
                   (np.frombuffer("".join(t).encode("latin-1"), np.uint8),
                    np.array([len(x) for x in t], np.int64))
                   for _, _, t in self.batches]
        except UnicodeEncodeError:      # a str program with characters beyond latin-1
            return self._apply_str(text, starts, ends)
        flat = np.concatenate([f for f, _ in new])
        lens = np.concatenate([n for _, n in new])
        # where each new text begins in the output: its start in the text plus the bytes the
        # edits before it added (numpy.insert would do the same, but sorts its positions)
        grow = lens - (ends - starts)
        first = starts + np.cumsum(grow) - grow
        at = np.repeat(first - (np.cumsum(lens) - lens), lens) + np.arange(len(flat))
        out = np.empty(len(b) + int(grow.sum()), dtype=np.uint8)
        is_new = np.zeros(len(out), dtype=bool)
        is_new[at] = True
        out[at] = flat
        keep = np.ones(len(b), dtype=bool)
        keep[chunkscan._spans(starts, ends)] = False
        out[~is_new] = b[keep]
        return out.tobytes().decode("latin-1")

    def _apply_str(self, text: str, starts, ends) -> str:
        new = []
        for _, _, t in self.batches:
            if isinstance(t, tuple):
                new += chunkscan.split_texts(*t)
            else:
                new += t
        out, prev = [], 0
        for s0, e0, t in zip(starts.tolist(), ends.tolist(), new):
            out += [text[prev:s0], t]
            prev = e0
        out.append(text[prev:])
        return "".join(out)
