"""Lossless NC blocks.

A `Block` is one line of a program: its raw text, its line ending and the
items parsed from it.  Every item keeps its span in the raw text, so a block
that nobody changed is written back byte for byte, and a changed block keeps
everything between and around the items it did not touch (libcst-style).

Text is held as `str` decoded with Latin-1, which maps every byte to one
character and back: any byte sequence (UTF-8 comments, Latin-1 accents, stray
control bytes) survives the round trip.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import final

# A line's layout: its Latin-1 bytes with every digit '1'.  Lines of one layout differ only in
# their digits: the parser cuts them into words at the same places, the writer edits them alike.
DIGITS_AS_ONE = bytes.maketrans(b"0123456789", b"1111111111")

# Expression nodes are nested tuples, cheap to build and easy to evaluate:
#   ("num", float) ("param", key) ("neg", x) ("pos", x) ("bin", op, a, b)
#   ("call", name, x) ("atan2", a, b) ("exists", param)
# where a parameter key is an int, a "<name>" string or ("ref", expr).
Expr = tuple


class Item:
    """Something parsed from a block, with its [start, end) span in the raw text."""

    __slots__ = ("start", "end")

    def __init__(self, start: int, end: int):
        self.start = start
        self.end = end

    def _fields(self) -> tuple:
        return tuple(
            getattr(self, name) for cls in type(self).__mro__ for name in getattr(cls, "__slots__", ())
        )

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and self._fields() == other._fields()

    def __hash__(self) -> int:
        return hash((type(self), self._fields()))

    def __repr__(self) -> str:
        names = [n for cls in reversed(type(self).__mro__) for n in getattr(cls, "__slots__", ())]
        return f"{type(self).__name__}({', '.join(f'{n}={getattr(self, n)!r}' for n in names)})"


@final  # the readers and writers tell items apart by `type(item) is ...`
class Word(Item):
    """A letter with a number: `G1`, `Z -110`, `F100.`; `,C1.` has letter ',C'.

    `number` is the number exactly as written (without letter and spaces),
    so that a rewritten value can keep the program's number style.
    """

    __slots__ = ("letter", "value", "number")

    def __init__(self, letter: str, value: float, number: str, start: int, end: int):
        super().__init__(start, end)
        self.letter = letter
        self.value = value
        self.number = number


@final  # the readers and writers tell items apart by `type(item) is ...`
class ExprWord(Item):
    """A letter whose value is an expression: `X[#1+2]`, `X#140/2`."""

    __slots__ = ("letter", "expr")

    def __init__(self, letter: str, expr: Expr, start: int, end: int):
        super().__init__(start, end)
        self.letter = letter
        self.expr = expr


@final  # the readers and writers tell items apart by `type(item) is ...`
class Comment(Item):
    """`(text)` or `; text`; `text` excludes the delimiters."""

    __slots__ = ("text", "style")

    def __init__(self, text: str, style: str, start: int, end: int):
        super().__init__(start, end)
        self.text = text
        self.style = style


@final  # the readers and writers tell items apart by `type(item) is ...`
class Statement(Item):
    """A construct the motion interpreter does not execute directly.

    kind: 'block_delete', 'assignment', 'oword', 'program_name', 'tape',
    'checksum', 'if', 'while', 'end', 'goto', 'stray_tape' (a `%` line in a
    program that does not start with one), 'unreadable' (a line the grammar
    cannot read: `node` holds the error, raised where the line runs).  `node`
    holds its parsed parts (a tuple whose shape depends on kind).
    """

    __slots__ = ("kind", "node")

    def __init__(self, kind: str, node: tuple, start: int, end: int):
        super().__init__(start, end)
        self.kind = kind
        self.node = node


UNREADABLE = "unreadable"  # the kind of a `Statement` standing for a line the grammar cannot read
STRAY_TAPE = "stray_tape"  # the kind of a `%` line in a program that did not start with one

AnyItem = Word | ExprWord | Comment | Statement


@dataclass(slots=True, eq=True)
class Block:
    """One line: `raw` (without line ending), `eol` ('\\n', '\\r\\n' or '') and items.

    `verbatim` blocks (after the closing tape mark) are kept as text only.
    `signature`, when known, is the letters of its words in order, each G word with
    its number as written (`G1XYF`), for a block of only one-letter words and
    comments (what the parser's fast path reads): the writer reads its facts from it
    instead of walking the items.  Whoever changes the items builds a Block without it.
    `layout`, when known, is `raw` with every digit '1' (`DIGITS_AS_ONE`), as the parser's
    fast path read it: the writer's key for what a layout teaches and how it is edited.
    """

    raw: str
    eol: str
    items: tuple[AnyItem, ...]
    line: int = 0
    verbatim: bool = False
    signature: str | None = field(default=None, compare=False, repr=False)
    layout: bytes | None = field(default=None, compare=False, repr=False)

    @property
    def text(self) -> str:
        return self.raw + self.eol

    def words(self) -> list[Word]:
        return [item for item in self.items if type(item) is Word]

    @property
    def plain(self) -> bool:
        """True when every item is a plain word or a comment (no expressions, no control)."""
        return all(type(item) is Word or type(item) is Comment for item in self.items)

    def source(self, item: Item) -> str:
        return self.raw[item.start : item.end]

    def place(self, col: int | None) -> tuple[int, int | None]:
        """The file's line and column of a column counted in `raw`: a block continued over
        several lines (Klartext's `~`) holds their line endings."""
        head = self.raw[: col - 1] if col is not None else ""
        if "\n" not in head:
            return self.line, col
        return self.line + head.count("\n"), len(head) - head.rfind("\n")
