"""Plain lines left unread: how a second part reaches its window fast (`ncpp/parts.py`).

A second part's lines before its window are read only to reach the state the
interpreter and the writer are in there.  Most of a CAM program is plain lines:
an optional N, one G0-G3, axis and arc words and F, a trailing comment.  In
absolute G90 such lines leave a state a regular expression can tell: each axis
at its last word, the last motion code, the last feed; the writer has seen the
last motion word and each letter's last number.  `Skim` reads the program's lines
for the parser (`parser.parse_stream`'s `numbered`) and leaves out runs of them
when the interpreter is in a state that allows it (`Interpreter.skimmable`),
telling their effect instead (`Interpreter.skipped`, `IsoWriter.skimmed`).
The expression runs once per shape of line (`_Shapes`: 8k instructions a line
left out, not 18k).

What is left out is checked, not trusted: the first part compares the
interpreter's state at the cut with the second part's (`Interpreter.state`), and
the writer's and the passes' as before; a second part whose state differs is not
used.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Iterable, Iterator, NamedTuple

from ncpp.program.parser import iter_lines

if TYPE_CHECKING:
    from ncpp.motion.interpreter import Interpreter
    from ncpp.pipeline import Part
    from ncpp.program.dialects.iso import IsoWriter


def _word(letter: str) -> bytes:
    """An optional word of `letter` (either case), its number a group."""
    return b"(?:[" + letter.encode() + letter.lower().encode() + rb"][ \t]*+([-+]?+(?>\d++\.?+\d*+|\.\d++))[ \t]*+)?"


LETTERS = "XYZIJKRF"  # the words of a plain line, in this order
# N, a G0-G3 (not G00.1, G10...), the words each at most once in LETTERS' order, a comment.
# Groups: the G code, the text of the axis words and each of them, of the arc words and each, F.
# Possessive: what a word or a blank run takes is never given back (a sixth fewer instructions
# a line), but G's zeros, which may leave the code's own digit (`G00`).
PLAIN_LINE = re.compile(
    rb"[ \t]*+(?:[Nn][ \t]*+\d++[ \t]*+)?(?:[Gg]0*([0-3])(?![\d.])[ \t]*+)?"
    + b"(" + b"".join(map(_word, "XYZ")) + b")(" + b"".join(map(_word, "IJKR")) + b")" + _word("F")
    + rb"(?:\([^()\r\n]*+\)[ \t]*+)?\r?\n?"
)
_CODE, _AXIS_WORDS, _ARC_WORDS = 1, 2, 6  # group numbers
_NUMBERS = (3, 4, 5, 7, 8, 9, 10, 11)  # the group of each letter's number, in LETTERS' order
_F = 7  # F's place in LETTERS (the axes are 0-2: their program position indices)
_RESOLVED = 4096  # plain lines kept before their last numbers are picked out
_SHAPES = 8192  # shapes known at most: memory stays flat (the generated program has 3231)
_ALIKE = bytes.maketrans(b"0123456789", b"0" * 10)  # a line's shape: every digit alike


class _Plain(NamedTuple):
    """What PLAIN_LINE finds in the lines of one shape: where the motion code's digit and
    each letter's number are (`at`: (start, end) or None; the code, then LETTERS), where G's
    digits start (-1: no G word), and whether there are arc words and axis words."""

    at: tuple
    zeros: int
    arc: bool
    axis: bool


_UNKNOWN = _Plain((), -1, False, False)  # a shape not seen yet


class _Shapes:
    """PLAIN_LINE's verdict on a line by its shape, the regular expression run once per shape
    (most lines of a CAM program share a few hundred).  Digits differ only in G's `0*[0-3]`
    within a shape (elsewhere the expression asks `\\d`), which is checked line by line."""

    def __init__(self) -> None:
        self.known: dict[bytes, _Plain | None] = {}

    def plain(self, raw: bytes) -> _Plain | None:
        shape = raw.translate(_ALIKE)
        plain = self.known.get(shape, _UNKNOWN)
        if plain is _UNKNOWN:
            plain = self._learn(raw, shape)
        if plain is not None and plain.zeros >= 0:  # `G0*[0-3]`: zeros, then a code of 0-3 (0x30-0x33)
            code = plain.at[0][0]
            if raw[code] > 0x33 or raw.count(0x30, plain.zeros, code) != code - plain.zeros:
                return None
        return plain

    def _learn(self, raw: bytes, shape: bytes) -> _Plain | None:
        """The verdict on `raw`'s shape from `raw` (not plain: for all of them, the safe side)."""
        if len(self.known) >= _SHAPES:
            self.known.clear()
        found = PLAIN_LINE.fullmatch(raw)
        plain = None
        if found is not None:
            code = found.start(_CODE)
            zeros = -1 if code < 0 else len(raw[:code].rstrip(b"0"))
            at = tuple(None if found.start(g) < 0 else found.span(g) for g in (_CODE, *_NUMBERS))
            plain = _Plain(at, zeros, bool(found.group(_ARC_WORDS)), bool(found.group(_AXIS_WORDS)))
        self.known[shape] = plain
        return plain


class Skim:
    """`numbered` for `parse_stream`: a second part's lines, runs of plain lines before its
    window left out where `interpreter` may skip them (from line `first` on).

    A run stops where the window starts (`Part.window_start`: with the cut undecided, at
    the floor, where the part asks for it).  Without an interpreter (another dialect's
    part) no line is left out."""

    def __init__(self, part: "Part", first: int):
        self.part, self.first = part, first
        self.interpreter: Interpreter | None = None  # given before the first line is read
        self.writer: IsoWriter | None = None
        self.shapes = _Shapes()
        self.done = False  # past the window's first line: no line is left out from here on

    def __call__(self, stream: Iterable[bytes]) -> Iterator[tuple[int, tuple[str, str]]]:
        lines = iter(stream)
        number = 0
        begun = False  # a line with text went by (the parser knows then whether the program has tape marks)
        for raw in lines:
            number += 1
            if number >= self.part.window_start(number):
                yield number, _text(raw)
                break
            if begun and number >= self.first and self.interpreter is not None and self.interpreter.skimmable():
                plain = self.shapes.plain(raw)
                if plain is not None:
                    raw, number = self._skim(raw, plain, lines, number)
                    if raw is None:
                        return
            begun = begun or not raw.isspace() and raw != b""
            yield number, _text(raw)
        self.done = True
        yield from enumerate(iter_lines(lines), start=number + 1)

    def _skim(self, raw: bytes, plain: _Plain, lines: Iterator[bytes], number: int) -> tuple[bytes | None, int]:
        """Leave out the run of plain lines from line `number` (`raw`, what its shape holds
        `plain`): the first line not left out and its number (None: the program ended)."""
        motion = self.interpreter.motion  # type: ignore[union-attr]
        last: list[bytes | None] = [None] * (len(LETTERS) + 1)  # the last motion code, then each letter's last number
        matched: list[tuple[bytes, _Plain]] = []  # the lines since `last` was brought up to date
        first, window, shaped = number, self.part.window_start(number), self.shapes.plain
        while True:
            code = plain.at[0]
            moving = motion if code is None else float(raw[code[0]] - 0x30)
            if (moving is None or moving < 2.0) and (plain.arc or (moving is None and plain.axis)):
                break  # R with G0/G1 is a (Fanuc) corner, IJK an error, axis words with no mode too: the interpreter's
            motion = moving
            matched.append((raw, plain))
            if len(matched) == _RESOLVED:
                _bring_up_to_date(last, matched)
            raw = next(lines, None)  # type: ignore[assignment]
            number += 1
            if raw is None:
                break
            if number >= window:
                window = self.part.window_start(number)
                if number >= window:
                    break
            plain = shaped(raw)  # type: ignore[assignment, arg-type]
            if plain is None:
                break
        if number > first:
            _bring_up_to_date(last, matched)
            self._tell(number - first, motion, last)
        return raw, number

    def _tell(self, lines: int, motion: float | None, last: list[bytes | None]) -> None:
        """The interpreter and the writer as the `lines` left out would have left them."""
        interpreter, numbers = self.interpreter, last[1:]
        ends = {axis: float(numbers[axis]) for axis in (0, 1, 2) if numbers[axis] is not None}  # type: ignore[arg-type]
        feed = interpreter.feed if numbers[_F] is None else float(numbers[_F])  # type: ignore[union-attr, arg-type]
        interpreter.skipped(lines, ends, motion, feed)  # type: ignore[union-attr]
        self.writer.skimmed(None if last[0] is None else int(last[0]),  # type: ignore[union-attr]
                            {LETTERS[i]: text.decode("latin-1") for i, text in enumerate(numbers) if text is not None})  # fmt: skip
        self.part.skipped += lines


def _bring_up_to_date(last: list[bytes | None], matched: list[tuple[bytes, _Plain]]) -> None:
    """`last` (the motion code, each letter's number) after the lines `matched`, which it
    forgets: each is looked for from the end (most are on the last line or so)."""
    for k in range(len(last)):
        for raw, plain in reversed(matched):
            span = plain.at[k]
            if span is not None:
                last[k] = raw[span[0] : span[1]]
                break
    matched.clear()


def _text(raw: bytes) -> tuple[str, str]:
    """(content, eol) of one line, as `parser.iter_lines` reads it."""
    return next(iter_lines((raw,)))
