"""Parse NC text into lossless blocks, one line at a time (streaming).

The grammar (`grammar/<dialect>.lark`) is the single definition of the
syntax.  Most lines of real programs are plain words and comments
(`X2.612 Z-0.1497`); for those the parser takes a fast path: a scanner
compiled from the grammar's own WORD / COMMA_WORD / PAREN_COMMENT /
SEMI_COMMENT terminals, which yields the same items the LALR parser would
(a test checks that on the whole corpus).  Everything else goes through the
Lark LALR parser, once per layout of a line (`Y[#<ys>*-56.12]`, `L X+1.5 R0
F800`): a line of a layout parsed before has its items cut from it where that
line's items were (`_Cut`: most Klartext blocks) or takes that line's tree with
its own token texts (`_Replay`).
"""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, replace
from itertools import chain, islice
from pathlib import Path
from typing import Any

import lark
from lark import Discard, Token, Transformer, v_args

from ncpp.cache import cached_build
from ncpp.errors import Location, NcppError
from ncpp.program.blocks import (
    DIGITS_AS_ONE,
    STRAY_TAPE,
    UNREADABLE,
    AnyItem,
    Block,
    Comment,
    ExprWord,
    Statement,
    Word,
)

_GAP_CHARS = (
    " \t\r\f\v\x1a"  # blanks between items (a regex class body: SUB as itself, no digit in the pattern)
)
_GAP = f"[{_GAP_CHARS}]*"


def grammar_path(name: str) -> Path:
    """Grammar files ship inside the wheel as ncpp/grammar; in a checkout they sit at the top."""
    package = Path(__file__).resolve().parent.parent
    for folder in (package / "grammar", package.parent / "grammar"):
        candidate = folder / f"{name}.lark"
        if candidate.exists():
            return candidate
    raise FileNotFoundError(f"grammar {name}.lark not found beside the ncpp package")


_LARK_OPTIONS = {"parser": "lalr", "propagate_positions": True, "maybe_placeholders": False}
# A grammar that adds to another's rules (`%extend`) and the grammar it adds to, read before it
GRAMMAR_BASE = {"fanuc": "iso"}


def grammar_text(name: str) -> str:
    """The text of grammar `name`, after that of the grammar it adds to (`GRAMMAR_BASE`)."""
    own = grammar_path(name).read_text(encoding="utf-8")
    base = GRAMMAR_BASE.get(name)
    return own if base is None else f"{grammar_text(base)}\n{own}"


@functools.cache
def lalr_parser(name: str) -> lark.Lark:
    """The dialect's Lark parser, loaded from the user's cache when it was built before
    (building the LALR tables takes several times as long as loading them: every `ncpp` run
    pays it, and the LinuxCNC filter runs whenever a program is opened)."""
    text = grammar_text(name)
    return cached_build(
        f"{name}-lark",
        f"{text}\n{_LARK_OPTIONS}\n{lark.__version__}",
        lambda: lark.Lark(text, **_LARK_OPTIONS),
        lark.Lark.load,
    )


def _word(text: str, start: int, end: int) -> Word:
    """`Z -110` -> Word('Z', -110.0, '-110'); `,c1.` -> Word(',C', 1.0, '1.')."""
    if text[0] == ",":
        body = text[1:].lstrip(" \t")
        letter, number = "," + body[0].upper(), body[1:]
    else:
        letter, number = text[0].upper(), text[1:]
    number = _digits(number)
    return Word(letter, float(number), number, start, end)


def _digits(text: str) -> str:
    """A number as rs274ngc reads it, without the blanks written between its digits (`1 0` is 10)."""
    return text.replace(" ", "").replace("\t", "")


_UPPER = {chr(c): chr(c).upper() for c in range(256)}  # str.upper of one Latin-1 character
_new_word = Word.__new__


class _ItemBuilder(Transformer):
    """Turns a Lark tree of one line into items with spans."""

    # -- items -----------------------------------------------------------------
    def word(self, children):
        (tok,) = children
        return _word(str(tok), tok.start_pos, tok.end_pos)

    comma_word = word

    def comment(self, children):
        (tok,) = children
        return Comment(str(tok)[1:-1], "(", tok.start_pos, tok.end_pos)

    def line_comment(self, children):
        (tok,) = children
        return Comment(str(tok)[1:], ";", tok.start_pos, tok.end_pos)

    @v_args(meta=True)
    def expr_word(self, meta, children):
        letter, expr = children
        return ExprWord(str(letter).upper(), expr, meta.start_pos, meta.end_pos)

    @v_args(meta=True)
    def comma_expr_word(self, meta, children):
        letter, expr = children
        return ExprWord("," + str(letter)[-1].upper(), expr, meta.start_pos, meta.end_pos)

    def _statement(kind: str):  # type: ignore[misc]
        @v_args(meta=True)
        def build(self, meta, children):
            node = tuple(str(c) if isinstance(c, Token) else c for c in children)
            return Statement(kind, node, meta.start_pos, meta.end_pos)

        return build

    block_delete = _statement("block_delete")
    checksum = _statement("checksum")
    tape = _statement("tape")
    program_name = _statement("program_name")
    oword = _statement("oword")
    fanuc_if = _statement("if")
    fanuc_while = _statement("while")
    fanuc_end = _statement("end")
    fanuc_goto = _statement("goto")
    external_output = _statement("external_output")
    del _statement

    @v_args(meta=True)
    def oword_number(self, meta, children):
        """`O1000` is a plain word (Fanuc program number); `O<name>` alone is a statement."""
        (tok,) = children
        if "<" in tok:
            return Statement("oword", (str(tok),), meta.start_pos, meta.end_pos)
        return _word(str(tok), meta.start_pos, meta.end_pos)

    def colon_program_number(self, children):
        """`:1000` is the program number O1000 (`grammar/fanuc.lark`)."""
        (tok,) = children
        return _word("O" + tok[1:], tok.start_pos, tok.end_pos)

    @v_args(meta=True)
    def assignment(self, meta, children):
        target, value = children
        return Statement("assignment", (target, value), meta.start_pos, meta.end_pos)

    # -- expressions -----------------------------------------------------------
    def number(self, children):
        return ("num", float(_digits(children[0])))

    def param(self, children):
        (key,) = children
        if isinstance(key, Token):
            return ("param", int(_digits(key)) if key.type == "INT" else str(key).lower())
        return ("param", ("ref", key))

    def group(self, children):
        return children[0]

    def neg(self, children):
        return ("neg", children[0])

    def pos(self, children):
        return children[0]

    def _binary(self, children):
        a, op, b = children
        return ("bin", str(op).upper(), a, b)

    logic = relation = sum = product = power = wsum = wproduct = fanuc_condition = _binary

    def call(self, children):
        name, arg = children
        return ("call", str(name).upper(), arg)

    def atan2(self, children):
        _, a, b = children
        return ("atan2", a, b)

    def exists(self, children):
        _, target = children
        return ("exists", target)

    def start(self, children):
        return tuple(children)


@dataclass(frozen=True)
class Dialect:
    """What the line parser needs to know about a dialect's syntax.

    `fast_terminals` name the grammar terminals the plain-line scanner uses
    (WORD / COMMA_WORD become words, PAREN_COMMENT a `(` comment, SEMI_COMMENT
    a `;` comment); none means every block goes through the LALR parser.
    `continuation` is the mark that, ending a line, continues its block on
    the next line (Heidenhain `~`).  `max_line`: the longest block the dialect's
    controls read (`max_line_source` says whose rule it is); a longer one is refused
    before it is scanned, which keeps the time and memory of a line bounded.
    `leader`: text before the program start `%` (within the first `LEADER_LINES` lines) is a
    tape leader the control skips, as Fanuc's do.
    `programs_after_end`: the text after the closing `%` may hold more programs, each O-number
    program one the control keeps in memory for M98 and G65 to call (Fanuc operator's manual,
    "Program configuration"; Haas Mill Operator's Manual, "Subprograms"): it is parsed too, its
    blocks still `verbatim` (`_after_end`).
    `read_where_run`: a line the grammar cannot read is an error where it runs, not where it stands (rs274ngc reads only the
    lines it runs: an uncalled subroutine, an untaken branch, the text after M2
    may hold anything): it becomes a block of one `unreadable` statement.
    `bare_tape_marks`: only a line of `%` alone (blanks aside) is a tape mark; a `%` with more on
    its line (`% vfd enable`, `%(note)`) is a bad character where it runs, as rs274ngc reads it.
    `tape_marks`: the controls take `%` lines for the program's start and end; without them (grbl)
    every `%` line is a stray one and no text after a `%` goes unread.
    """

    name: str
    grammar: str
    builder: type[Transformer]
    fast_terminals: tuple[str, ...] = ()
    continuation: str | None = None
    read_where_run: bool = False
    max_line: int = 256
    max_line_source: str = "rs274ngc (LinuxCNC) holds a line in LINELEN, 256 characters"
    leader: bool = False  # lines before a first `%` line are a tape leader, not read (`_leader`)
    programs_after_end: bool = False  # the lines after the closing `%` are parsed (`_after_end`)
    eob_semicolon: bool = False  # `;` is the end of block as the control shows it (`_words_after_eob`)
    bare_tape_marks: bool = False  # a `%` with more on its line is no tape mark (rs274ngc)
    tape_marks: bool = True  # `%` lines mark the program's start and end (not grbl's)


def dialect_syntax(dialect: str | Dialect) -> Dialect:
    if isinstance(dialect, Dialect):
        return dialect
    from ncpp.program.dialects import get_dialect  # the registry imports this module

    return get_dialect(dialect)


# A UTF-8 byte order mark (a Windows editor's), as the latin-1 text a program is read as
_BOM = "\xef\xbb\xbf"
BOM_MESSAGE = "the file starts with a UTF-8 byte order mark (bytes EF BB BF), which NC controls do not expect (rs274 refuses it): save the program without it"

# A number of more digits than a float holds reads as infinity (`X999...9`): refused, as
# rs274 refuses the line ("Command too long"); shorter lines cannot hold one.
_FINITE_LINE = 300


def _refuse_infinite(block: Block, file: str) -> None:
    for item in block.items:
        if type(item) is Word and not math.isfinite(item.value):
            raise NcppError(
                f"number out of range: {item.letter}{item.number[:20]}... ({len(item.number)} characters)",
                Location(file, block.line, item.start + 1),
            )


def _refuse_cr_line_ends(raw: str, line: int, file: str) -> None:
    """Text after a CR: lines ended by CR alone (classic Mac OS), which the grammar would
    read as blanks, running every line of the program into one."""
    bare = _TEXT_AFTER_CR.search(raw)  # (a continued block holds the CR LF of its lines)
    if bare is not None:
        raise NcppError(
            "the program's lines end in a carriage return (CR) alone: convert them to LF or CR LF",
            Location(file, line, bare.start() + 1),
        )


# A word's start (a letter, then a number, a parameter or a bracket) after a `;`, past blanks and
# parenthesised comments
_WORD_AFTER_EOB = re.compile(r"(?:[ \t]|\([^)]*\))*([A-Za-z][ \t]*[-+]?[ \t]*[0-9.#\[])")


def _words_after_eob(block: Block, dialect: Dialect, file: str) -> Block:
    """The block, unless words follow a `;` on its line.  Fanuc's manuals write the end of block
    as `;` (operator's manuals: "the end of block code is indicated by ; (semicolon)", the actual
    code being LF in ISO code, CR in EIA), the control's screen shows it so, Haas's editor too, and
    hand-written programs carry it (`G43; H01 (USE TOOL OFFSET #1)`).  Where a control reads a `;`
    in a file as the end of a block, the words after it are a block of their own; where as a
    comment (LinuxCNC's rule, the ISO grammar's), they are skipped.  No manual says which, so
    such a line is refused where it runs, not read either way; a `;` with only blanks or a `(...)`
    comment after it ends the block in both readings."""
    for item in block.items:
        if type(item) is not Comment or item.style != ";":
            continue
        word = _WORD_AFTER_EOB.match(item.text)
        if word is None:
            continue
        col = item.start + 2 + word.start(1)
        error = NcppError(
            f"words follow `;` on the line (`{item.text[word.start(1) :].split()[0]}`): a "
            f"{dialect.name.capitalize()} control shows its end of block as `;` and may read them as a "
            "block of their own, where ncpp would read `;` as a comment and skip them; put them on a "
            "line of their own, or in parentheses if they are a comment",
            Location(file, *block.place(col)),
        )
        if not dialect.read_where_run:
            raise error
        return Block(block.raw, block.eol, (Statement(UNREADABLE, (error,), 0, len(block.raw)),), block.line)
    return block


def _refuse_long(raw: str, dialect: Dialect, line: int, file: str) -> None:
    limit = dialect.max_line
    raise NcppError(
        f"block too long: {len(raw)} characters, where a {dialect.name} block may have {limit} "
        f"({dialect.max_line_source})",
        Location(file, line, limit + 1),
    )


# Brackets nested deeper than this are refused in every dialect: rs274ngc reads 120 in a line of
# its 256 characters, and a bound keeps the parser's and the evaluator's recursion short.
MAX_NESTING = 128
_BRACKETS = {"[": 1, "(": 1, "]": -1, ")": -1}


def _refuse_deep(block: Block, file: str) -> None:
    """Refuse brackets nested deeper than MAX_NESTING in a block's expressions (not its comments)."""
    for item in block.items:
        if type(item) is Word or type(item) is Comment:
            continue
        depth = 0
        for offset, char in enumerate(block.raw[item.start : item.end]):
            depth += _BRACKETS.get(char, 0)
            if depth > MAX_NESTING:
                where = Location(file, block.line, item.start + offset + 1)
                raise NcppError(f"brackets nested deeper than {MAX_NESTING}", where)


_TEXT_AFTER_CR = re.compile(r"\r[ \t\f\v\x1a\r]*[^ \t\f\v\x1a\r\n]")


class LineParser:
    """Parses one line (or one continued block) of a dialect into a Block."""

    FAST_TERMINALS = ("WORD", "COMMA_WORD", "PAREN_COMMENT", "SEMI_COMMENT")

    def __init__(self, grammar: str | Dialect = "iso"):
        self.dialect = dialect_syntax(grammar)
        self.grammar = self.dialect.grammar
        self._lark = lalr_parser(self.grammar)
        self._reads_atan = GRAMMAR_BASE.get(self.grammar, self.grammar) == "iso"  # (ATAN[y]/[x]: `ATAN_FORM`)
        self._builder = self.dialect.builder()
        self._items = (
            _PlainItems(self._lark, self.dialect.fast_terminals) if self.dialect.fast_terminals else None
        )
        self._blank = re.compile(f"{_GAP}$")
        # plain lines by their layout (`DIGITS_AS_ONE`): what `_scan_plain` reads of them, see `_shape`
        self._shapes: dict[bytes, object] = {}
        self._by_layout = self._items is not None and self._items.digit_blind
        self._trees = _TreeLayouts.of(self._lark)

    def parse(self, raw: str, eol: str = "", line: int = 0, file: str = "<stdin>") -> Block:
        if len(raw) > self.dialect.max_line:
            _refuse_long(raw, self.dialect, line, file)
        plain = self._scan_plain(raw)
        if plain is None:
            block = Block(raw, eol, self._read_lalr(raw, line, file), line)
        else:
            items, signature, layout = plain
            block = Block(raw, eol, items, line, False, signature, layout)
        if len(raw) > _FINITE_LINE:  # only such a line can hold a number of more than 308 digits
            _refuse_infinite(block, file)
        if "\r" in raw:  # (a CR before the LF is the line's end, not in `raw`)
            _refuse_cr_line_ends(raw, line, file)
        if plain is None and raw.count("[") + raw.count("(") > MAX_NESTING:  # (else it cannot nest deeper)
            _refuse_deep(block, file)
        if self.dialect.eob_semicolon and ";" in raw:
            block = _words_after_eob(block, self.dialect, file)
        return block

    def _scan_plain(self, raw: str) -> tuple | None:
        """(items, `Block.signature`, `Block.layout`) of a line made only of plain words and
        comments, else None; the signature is None when a word has two letters (`,R`), the
        layout where the scanner read the line."""
        if not self._by_layout:
            return _without_layout(self._scan_items(raw))
        # Most lines of a program share a few layouts (` X1.1111 Z-1.1111`): their words are
        # cut where the first line of the layout had them, without the scanner.
        try:
            layout = raw.encode("latin-1").translate(DIGITS_AS_ONE)
        except UnicodeEncodeError:  # text not read from bytes (`parse("X1 (€)")`): no layout
            return _without_layout(self._scan_items(raw))
        shape = self._shapes.get(layout)
        if shape is None:
            shape = self._learn_shape(raw, layout)
        if type(shape) is not tuple:  # not plain, or a plain line cutting cannot read
            return None if shape is _NOT_PLAIN else _without_layout(self._scan_items(raw))
        cut, signature, g_numbers = shape
        if g_numbers:  # the signature has the G words' numbers as written (one, mostly: `G1XY`)
            pieces = signature
            (a, b), *more = g_numbers
            signature = pieces[0] + raw[a:b] + pieces[1]
            for n, (a, b) in enumerate(more, start=2):
                signature += raw[a:b] + pieces[n]
        return cut.items(raw), signature, layout

    def _learn_shape(self, raw: str, layout: bytes) -> object:
        """The shape of the line's layout, scanned from the line and remembered."""
        scanned = self._scan_items(raw)
        shape = _NOT_PLAIN if scanned is None else _shape(raw, *scanned)
        if len(self._shapes) >= _MAX_SHAPES:  # comments can make every layout new: keep memory flat
            self._shapes.clear()
        self._shapes[layout] = shape
        return shape

    def _scan_items(self, raw: str) -> tuple[tuple[AnyItem, ...], str | None] | None:
        """`_scan_plain` by the scanner."""
        scanner = self._items
        if scanner is None or raw.rfind("(") > raw.rfind(")"):
            # (an unclosed comment, for the LALR parser to report: scanning would try each of its
            # `(` to the end of the line, time quadratic in its length; each `(` the scanner tries
            # now ends at the next `)`, which the comment takes)
            return None
        items: list[AnyItem] = []
        append = items.append
        signature = ""  # built here, where the words are: the writer reads its facts from it
        two_letters = False
        comma, paren, semi = scanner.comma, scanner.paren, scanner.semi
        pos = 0  # the items are consecutive (checked below): their spans follow from their lengths
        for found in scanner.findall(raw):
            start = pos + len(found[0])
            letter = found[1]
            if letter:  # a WORD, one per word of the program: built inline
                number = found[2]
                pos = start + 1 + len(number)
                letter = _UPPER[letter]
                if " " in number or "\t" in number:  # `X - 5`, `X1 5`
                    number = _digits(number)
                word = _new_word(Word)
                word.letter, word.value, word.number, word.start, word.end = (
                    letter,
                    float(number),
                    number,
                    start,
                    pos,
                )
                append(word)
                signature += letter if letter != "G" else "G" + number
                continue
            if found[comma]:
                text = found[comma]
                pos = start + len(text)
                append(_word(text, start, pos))
                two_letters = True
            elif found[paren]:
                text = found[paren]
                pos = start + len(text)
                append(Comment(text[1:-1], "(", start, pos))
            elif found[semi]:
                text = found[semi]
                pos = start + len(text)
                append(Comment(text[1:], ";", start, pos))
            else:  # a character no item starts with: the LALR parser says what is wrong
                return None
        # nothing was skipped (any non-blank is an item or the stray character above): only blanks may follow
        if pos == len(raw) or self._blank.match(raw, pos):
            return tuple(items), (None if two_letters else signature)
        return None

    def _read_lalr(self, raw: str, line: int, file: str) -> tuple[AnyItem, ...]:
        """`_parse_lalr`; where the dialect reads lines where they run, a line it cannot
        read is one `unreadable` statement holding the error (`Dialect.read_where_run`)."""
        try:
            return self._parse_lalr(raw, line, file)
        except NcppError as err:
            if (
                not self.dialect.read_where_run or err.message == BOM_MESSAGE
            ):  # (a byte order mark: the file's, not a line's)
                raise
            return (Statement(UNREADABLE, (err,), 0, len(raw)),)

    def _parse_lalr(self, raw: str, line: int, file: str) -> tuple[AnyItem, ...]:
        trees = self._trees
        layout = None
        if trees is not None:
            layout = trees.layout(raw)
            known = None if layout is None else trees.known.get(layout)
            if known is not None:
                return known.items(raw)
        try:
            tree = self._lark.parse(raw)
            items = tuple(_flatten(self._builder.transform(tree)))
        except lark.exceptions.UnexpectedInput as err:
            col = getattr(err, "column", None)
            # a continued block spans lines: Lark counts them from 1
            line += max(getattr(err, "line", 1) or 1, 1) - 1
            if raw.startswith(_BOM):
                raise NcppError(BOM_MESSAGE, Location(file, line, 1)) from None
            atan = _lone_atan(raw, _error_pos(err)) if self._reads_atan else None
            if atan is not None:
                raise NcppError(ATAN_FORM, Location(file, line, atan + 1)) from None
            if self.grammar == "fanuc" and _BARE_COLON.match(raw):
                raise NcppError(BARE_COLON, Location(file, line, raw.index(":") + 1)) from None
            raise NcppError(_describe(err, raw), Location(file, line, col)) from None
        except RecursionError:  # the builder walks the tree recursively: brackets hundreds deep
            raise NcppError("expression nested too deeply", Location(file, line, 1)) from None
        if trees is not None and layout is not None:  # (after a whole parse: the test costs nothing)
            trees.learn(layout, _Cut.of(raw, items, trees.layout) or _Replay(tree, self._builder))
        return items


class _TreeLayouts:
    """What the builder makes of LALR-parsed lines, by layout: a line whose layout was
    parsed before is cut where that line's items were (`_Cut`) or built from that line's
    tree with its own token texts (`_Replay`), without the parser (about six times the
    cost of the builder's transform).

    The layout is the line with its digits as `1`.  Lines of one layout lex into
    the same terminals at the same spans when no terminal tells one digit from
    another (`\\d`, `0-9`): the same tokens, so the same tree, but for the tokens'
    texts.  A grammar whose terminals do name digits (Heidenhain's `DR2`, `R0`)
    names them right after a letter: there the layout keeps the digit."""

    MAX = 1024  # layouts remembered (each holds one line's tree and its steps): memory stays flat

    def __init__(self, layout: Callable[[str], str]):
        self.layout = layout
        self.known: dict[str, _Cut | _Replay] = {}

    @classmethod
    def of(cls, parser: lark.Lark) -> _TreeLayouts | None:
        """The layouts of the grammar's lines (None: its terminals name digits elsewhere)."""
        named = [_digits_named(t.pattern.to_regexp()) for t in parser.terminals]
        if any(found is None for found in named):
            return None
        if not any(named):
            return cls(lambda raw: raw.translate(_ALL_DIGITS_AS_ONE))
        return cls(functools.partial(_DIGITS_NOT_AFTER_A_LETTER.sub, "1"))

    def learn(self, layout: str, known: _Cut | _Replay) -> None:
        if len(self.known) >= self.MAX:
            self.known.clear()
        self.known[layout] = known


class _Cut:
    """The items of the lines of one layout cut from the line, without scanner or builder:
    for a layout whose items are each the same on every line of it (no digit the layout
    turns to `1` in its span: `L`, `R0`, `FMAX`) or a plain word (`X-47.4002`, `N12`: its
    number as written and read by `float`), as most Klartext blocks and plain ISO lines are."""

    def __init__(self, steps: tuple):
        self.steps = steps  # per item: the item itself, or (letter, start, start of the number, end)

    @classmethod
    def of(cls, raw: str, items: tuple[AnyItem, ...], layout: Callable[[str], str]) -> _Cut | None:
        varying = _varying(raw, layout)
        steps: list = []
        for item in items:
            if not any(varying[item.start : item.end]):
                steps.append(item)  # the same text on every line of the layout: the same item
                continue
            if type(item) is not Word:
                return None
            number_at = item.end - len(item.number)
            if (
                any(varying[item.start : number_at])
                or raw[number_at : item.end] != item.number
                or not _reads_as(item.number, item.value)
            ):
                return None  # `X+10,5`, `X - 5`: the builder reads such numbers its own way
            steps.append((item.letter, item.start, number_at, item.end))
        return cls(tuple(steps))

    def items(self, raw: str) -> tuple[AnyItem, ...]:
        items: list[AnyItem] = []
        append = items.append
        for step in self.steps:
            if type(step) is tuple:
                letter, start, number_at, end = step
                number = raw[number_at:end]
                word = _new_word(Word)  # built inline: one per word of the program
                word.letter, word.value, word.number, word.start, word.end = (
                    letter,
                    float(number),
                    number,
                    start,
                    end,
                )
                append(word)
            else:
                append(step)
        return tuple(items)


_NEXT_DIGIT = str.maketrans("0123456789", "1234567890")


def _varying(raw: str, layout: Callable[[str], str]) -> list[bool]:
    """Per character of `raw`: whether lines of its layout may have another there: a digit
    the layout turns to `1` (it is `1` in the layout of the line with every digit changed
    too; a digit the layout keeps changes there)."""
    kept = layout(raw.translate(_NEXT_DIGIT))
    return [c.isdigit() and k == "1" == one for c, k, one in zip(raw, kept, layout(raw))]


def _reads_as(number: str, value: float) -> bool:
    """Whether `float` reads the number text as the builder did."""
    try:
        return float(number) == value and number.strip() == number
    except ValueError:
        return False


class _Replay:
    """A builder's transform of one tree, compiled for trees of its layout: in post-order,
    each token (with what Lark's Transformer calls on it) and each rule (with its
    callable and how many results it takes), without the Transformer's look-ups per node."""

    def __init__(self, tree: lark.Tree, builder: Transformer):
        self.tree, self.builder = tree, builder
        self.steps: list[tuple] = []
        self._compile(tree)

    def _compile(self, tree: lark.Tree) -> None:
        builder = self.builder
        for child in tree.children:
            if isinstance(child, Token):
                visit = getattr(builder, child.type, None) if builder.__visit_tokens__ else None
                self.steps.append((child, visit))
            else:
                self._compile(child)
        self.steps.append((len(tree.children), _rule_call(builder, tree)))

    def items(self, raw: str) -> tuple[AnyItem, ...]:
        return tuple(_flatten(self.run(raw)))

    def run(self, raw: str) -> Any:
        """What `builder.transform` gives for the line `raw` of this layout (Lark types it Any)."""
        results: list = []
        try:
            for first, call in self.steps:
                if type(first) is int:  # a rule of `first` children
                    children = results[len(results) - first :] if first else []
                    del results[len(results) - first :]
                    result = call([c for c in children if c is not Discard])
                else:  # a token: the template's, with this line's text
                    token = _borrowed(first, raw[first.start_pos : first.end_pos])
                    result = token if call is None else call(token)
                results.append(result)
        except Exception:  # raised as the Transformer raises it (a VisitError)
            return self.builder.transform(_retokened(self.tree, raw))
        return None if results[0] is Discard else results[0]


_new_str = str.__new__


def _borrowed(template: Token, text: str) -> Token:
    """`Token.new_borrow_pos(template.type, text, template)` without its keyword handling
    (a quarter of the cost: the replay makes one per token of every line it builds)."""
    token = _new_str(Token, text)
    token.type, token.value = template.type, text
    token.start_pos, token.end_pos = template.start_pos, template.end_pos
    token.line, token.column, token.end_line, token.end_column = (
        template.line,
        template.column,
        template.end_line,
        template.end_column,
    )
    return token


def _rule_call(builder: Transformer, tree: lark.Tree) -> Callable[[list], object]:
    """The call `Transformer._call_userfunc` makes for the rule of `tree` on its children."""
    data, meta = tree.data, tree.meta
    f = getattr(builder, data, None)
    if f is None:
        return lambda children: builder.__default__(data, children, meta)
    wrapper = getattr(f, "visit_wrapper", None)
    if wrapper is None:
        return f
    return lambda children: wrapper(f, data, children, meta)


_ALL_DIGITS_AS_ONE = str.maketrans("0123456789", "1111111111")
_DIGITS_NOT_AFTER_A_LETTER = re.compile(r"(?<![A-Za-z])[0-9]")
_REPEAT = re.compile(r"\{\d+(?:,\d*)?\}")  # a repeat count: its digits are no text's


def _digits_named(pattern: str) -> bool | None:
    """Whether a terminal's regular expression names digits (a digit, or a class with
    some digits but not all), each right after a letter (`DR2`, `R[0LR]`); None when it
    names one anywhere else (`[1-9]` after a blank, `R?2`)."""
    named, previous, i = False, "", 0
    while i < len(pattern):
        c = pattern[i]
        if c == "\\":
            atom, i = pattern[i : i + 2], i + 2
        elif c == "[":
            end = _class_end(pattern, i)
            atom, i = pattern[i:end], end
        elif repeat := _REPEAT.match(pattern, i):
            atom, i = repeat.group(), repeat.end()
        else:
            atom, i = c, i + 1
        if atom.isdigit() or (
            atom[0] == "[" and re.search(r"[0-9]", atom.replace("\\d", "").replace("0-9", ""))
        ):
            if not (len(previous) == 1 and previous.isascii() and previous.isalpha()):
                return None
            named = True
        previous = atom
    return named


def _class_end(pattern: str, start: int) -> int:
    """Where the character class opened at `start` ends (after its `]`)."""
    i = start + 2 if pattern.startswith("[^", start) else start + 1
    i += pattern[i] == "]"  # a `]` first is itself
    while pattern[i] != "]":
        i += 2 if pattern[i] == "\\" else 1
    return i + 1


def _retokened(tree: lark.Tree, raw: str) -> lark.Tree:
    """`tree` (of a line of raw's layout) with every token's text read from `raw`."""
    children = [
        _borrowed(child, raw[child.start_pos : child.end_pos])
        if type(child) is Token
        else _retokened(child, raw)
        for child in tree.children
    ]
    return lark.Tree(tree.data, children, tree.meta)


# Lines of one layout (`DIGITS_AS_ONE`): the fast terminals tell no digit from another
# (`_PlainItems.digit_blind`), so they scan into the same items at the same spans.
_MAX_SHAPES = 10_000  # layouts remembered
_NOT_PLAIN = "not plain"  # the shape of a layout the scanner does not read (the LALR parser does)
_SCAN = "scan"  # the shape of a plain layout whose items cutting cannot build: scanned each time


def _shape(raw: str, items: tuple[AnyItem, ...], signature: str | None) -> object:
    """How to build the items of a line of this layout: (a `_Words` of its words, signature,
    g_numbers) for a line of one-letter words whose numbers are written without blanks, else
    `_SCAN`.  When the line has G words, the signature is the pieces around their numbers,
    which the line's text fills (`g_numbers`: their spans)."""
    words = [item for item in items if type(item) is Word]
    if signature is None or len(words) != len(items):
        return _SCAN  # a comma word (`,R`), a comment
    spans = tuple((w.letter, w.start, w.end - len(w.number), w.end) for w in words)
    if any(raw[number_at:end] != w.number for (_, _, number_at, end), w in zip(spans, words)):
        return _SCAN  # `X - 5`: the number is written with blanks
    g_numbers = tuple((number_at, end) for letter, _, number_at, end in spans if letter == "G")
    if not g_numbers:
        return _Words(spans), signature, ()
    pieces, piece = [], ""
    for w in words:
        if w.letter == "G":
            pieces.append(piece + "G")
            piece = ""
        else:
            piece += w.letter
    return _Words(spans), (*pieces, piece), g_numbers


class _Words(_Cut):
    """`_Cut` of a layout of plain words only (most lines): every step a word."""

    def items(self, raw: str) -> tuple[AnyItem, ...]:
        items: list[AnyItem] = []
        append = items.append
        for letter, start, number_at, end in self.steps:
            number = raw[number_at:end]
            word = _new_word(Word)  # built inline: one per word of the program
            word.letter = letter
            word.value = float(number)
            word.number = number
            word.start = start
            word.end = end
            append(word)
        return tuple(items)


class _PlainItems:
    """The plain-line scanner: `findall(raw)` gives one tuple per item, compiled from
    the grammar's fast terminals.  Its fields: [0] the blanks before the item,
    [1] [2] the letter and the number (as written) of a WORD, split after the
    character class WORD starts with, and at `comma` / `paren` / `semi` the text
    of a COMMA_WORD / PAREN_COMMENT / SEMI_COMMENT (a never-matching group
    stands for a terminal the dialect does not take); else a stray character.
    The stray character matters: findall would skip it, and the spans, which
    follow from the lengths of what it found, would be wrong."""

    OTHERS = ("COMMA_WORD", "PAREN_COMMENT", "SEMI_COMMENT")

    def __init__(self, lark_parser: lark.Lark, names: tuple[str, ...]):
        patterns = {t.name: t.pattern.to_regexp() for t in lark_parser.terminals}
        split = re.fullmatch(r"(\[[^\]]*\])(.*)", patterns["WORD"], re.S) if "WORD" in names else None
        if split is None:
            raise ValueError("the plain-line scanner needs a WORD that starts with a one-letter class")
        others = [f"(?P<{name}>{patterns[name] if name in names else '(?!)'})" for name in self.OTHERS]
        pattern = re.compile(f"({_GAP})(?:({split[1]})({split[2]})|{'|'.join(others)}|[^{_GAP_CHARS}])")
        self.findall = pattern.findall
        self.comma, self.paren, self.semi = (pattern.groupindex[name] - 1 for name in self.OTHERS)
        # a pattern naming no digit (`\\d`, `0-9` and ranges of letters only) treats all digits alike
        self.digit_blind = _digits_named(pattern.pattern) is False


def _flatten(items: Iterable) -> Iterator[AnyItem]:
    for item in items:
        if isinstance(item, tuple):
            yield from _flatten(item)
        else:
            yield item


# The arc tangent's one form in Fanuc macro B ("#i=ATAN[#j]/[#k]", Fanuc operator's manual, "Custom
# macro", arithmetic and logic operations), Haas's macros (ATAN[#j]/[#k]) and LinuxCNC's ("ATAN[Y]/[X]",
# G-code overview, "Functions"; rs274 stops at an ATAN without it: "Slash missing after first atan
# argument"); none of the manuals gives ATAN one argument
ATAN_FORM = (
    "ATAN without `/[x]` after its bracket: ncpp reads the arc tangent in the two-argument form ATAN[y]/[x] "
    "of Fanuc macro B, Haas and LinuxCNC, and no other (a one-argument ATAN is in none of their manuals)"
)
_ATAN = re.compile(r"(?i)atan[ \t]*\[")


def _lone_atan(raw: str, pos: int) -> int | None:
    """Where the ATAN starts whose bracket no `/` follows, at or before the parse error's `pos`."""
    for found in _ATAN.finditer(raw, 0, pos + 1):
        depth, end = 0, found.end() - 1
        for end in range(found.end() - 1, len(raw)):
            depth += {"[": 1, "]": -1}.get(raw[end], 0)
            if depth == 0:
                break
        if depth == 0 and not raw[end + 1 :].lstrip(" \t").startswith("/"):
            return found.start()
    return None


def _error_pos(err: lark.exceptions.UnexpectedInput) -> int:
    pos = getattr(err, "pos_in_stream", None)
    return pos if pos is not None else (getattr(err, "column", 1) or 1) - 1


# Fanuc's and Haas's program number address with no number after it (`:`, `: (PART)`, `fanuc.lark`)
_BARE_COLON = re.compile(r"^[ \t]*:(?![ \t]*\d)")
BARE_COLON = (
    "a program number address `:` without its number (in ISO code `:` stands for O, which the "
    "program's number follows: `:1000`)"
)

# A LinuxCNC o-word's name, where its keyword must follow (`o<frame_circ> call [1]`, `o100 sub`)
_OWORD_NAME = re.compile(r"[ \t]*(?:[Nn][ \t]*\d+[ \t]*)?[Oo][ \t]*(?:<[^>]*>|\d+)[ \t]*")


def _describe(err: lark.exceptions.UnexpectedInput, raw: str) -> str:
    pos = _error_pos(err)
    rest = raw[pos:].strip()
    if isinstance(err, lark.exceptions.UnexpectedEOF) or not rest:
        return "unexpected end of block"
    if isinstance(err, lark.exceptions.UnexpectedToken) and err.token.type == "$END":
        return "unexpected end of block"
    snippet = rest[:20]
    oword = _OWORD_NAME.match(raw)
    if oword is not None and oword.end() == pos and not rest[0].isalpha():
        # (rs274ngc: "Unknown control command in o word"; `o<name> [1]` lacks the `call`)
        return f"an o-word without its keyword (call, sub, if, while...) before {snippet!r}"
    if rest[0] == "(" and ")" in rest:  # (a closed comment where a value or a word had to come)
        return f"a comment where a value belongs: {snippet!r}"
    if rest[0] == "(":
        return f"unclosed comment: {snippet!r}"
    if isinstance(err, lark.exceptions.UnexpectedToken):
        return f"unexpected {snippet!r}"
    if rest[0] == ")" and "(" in raw[:pos]:  # (a comment ends at its first ')': a '(' in it opens none)
        return f"a ')' after the comment closed, comments do not nest: {snippet!r}"
    return f"cannot read {snippet!r}"


def iter_lines(stream: Iterable[bytes]) -> Iterator[tuple[str, str]]:
    """(content, eol) for each line of a binary stream, decoded losslessly."""
    for raw in stream:
        text = raw.decode("latin-1")
        if text.endswith("\r\n"):
            yield text[:-2], "\r\n"
        elif text.endswith("\n"):
            yield text[:-1], "\n"
        else:
            yield text, ""


def continued_lines(lines: Iterable[tuple[str, str]], mark: str) -> Iterator[tuple[int, str, str]]:
    """(first line number, content, eol) of each block, joining a line that ends
    with `mark` to the next one; the joined content keeps the inner line endings."""
    pending, first, eol = "", 0, ""
    for number, (content, eol) in enumerate(lines, start=1):
        if not pending:
            first = number
        if eol and content.rstrip(" \t").endswith(mark):
            pending += content + eol
            continue
        yield first, pending + content, eol
        pending = ""
    if pending:  # the last line ended with the mark
        yield first, pending[: len(pending) - len(eol)], eol


def _without_layout(scanned: tuple | None) -> tuple | None:
    """The scanner's (items, signature) with no layout (`LineParser._scan_plain`)."""
    return None if scanned is None else (*scanned, None)


def parse_stream(
    stream: Iterable[bytes], file: str = "<stdin>", grammar: str | Dialect = "iso"
) -> Iterator[Block]:
    """Blocks of a program, lazily.  After the closing `%` lines are kept verbatim
    (a control stops reading there; `Dialect.programs_after_end`: parsed as well).  `grammar`
    names the dialect (or is one)."""
    parser = LineParser(grammar)
    if parser.dialect.continuation:
        yield from _parse_continued(parser, iter_lines(stream), file)
        return
    tape_marks = 0
    after_end = parser.dialect.programs_after_end
    lines: Iterable[tuple[str, str]] = iter_lines(stream)
    skipped: list[tuple[str, str]] = []
    if parser.dialect.leader:
        skipped, lines = _leader(lines)
        for number, (content, eol) in enumerate(skipped, start=1):
            yield Block(content, eol, (), number, verbatim=True)
    for number, (content, eol) in enumerate(lines, start=len(skipped) + 1):
        if tape_marks >= 2:
            if after_end:
                yield _after_end(parser, content, eol, number, file)
            else:
                yield Block(content, eol, (), number, verbatim=True)
            continue
        block = parser.parse(content, eol, number, file)
        mark = _tape_text(block)
        if mark is not None and _no_tape_mark(mark, parser.dialect):
            block = _stray_tape_mark(block)
        elif mark is not None:
            tape_marks += 1
            if tape_marks < 0 and parser.dialect.read_where_run:  # rs274ngc: a bad character where it runs
                block = _stray_tape_mark(block)
        elif tape_marks == 0 and block.items:
            tape_marks = -(10**9)  # material before any `%`: the program has no tape marks
        yield block


LEADER_LINES = 64  # how far down a program's start `%` is looked for, below a tape leader
_TAPE_MARK = re.compile(r"[ \t]*%")


def _leader(lines: Iterable[tuple[str, str]]) -> tuple[list[tuple[str, str]], Iterator[tuple[str, str]]]:
    """(the tape leader, the lines from the program start on).  A Fanuc control reads a file
    from its first `%`: "data between the first % and the next LF is skipped" (Series 16i/18i
    operator's manual B-63524EN, memory card file format), and the leader before the program
    start is not read (the Data Server manual B-64014EN, NC program format).  Simulators'
    example files put their own directives there (`($Message("...") )`)."""
    lines = iter(lines)
    head = list(islice(lines, LEADER_LINES))
    start = next((k for k, (content, _) in enumerate(head) if _TAPE_MARK.match(content)), 0)
    return head[:start], chain(head[start:], lines)


def _after_end(parser: LineParser, content: str, eol: str, number: int, file: str) -> Block:
    """A line after the closing `%` of a file that may hold more programs: verbatim (text the
    program does not run), with its items for a call to find and run; a line the parser refuses
    (too long, CR line ends) is a line it cannot read, an error only where a call runs it."""
    try:
        items = parser.parse(content, eol, number, file).items
    except NcppError as err:
        items = (Statement(UNREADABLE, (err,), 0, len(content)),)
    return Block(content, eol, items, number, verbatim=True)  # (no signature: no fast path takes it)


def _tape_text(block: Block) -> str | None:
    """A `%` line's mark, `%` and what follows it on the line (None: the block is no `%` line)."""
    first = block.items[0] if block.items else None
    return first.node[0] if type(first) is Statement and first.kind == "tape" else None


def _no_tape_mark(mark: str, dialect: Dialect) -> bool:
    """A `%` line the dialect's controls take for no tape mark wherever it stands."""
    return not dialect.tape_marks or dialect.bare_tape_marks and mark.strip() != "%"


def _stray_tape_mark(block: Block) -> Block:
    """A `%` line that is no tape mark (in a program that did not start with one, or with more on
    its line where `Dialect.bare_tape_marks`): a `stray_tape` statement."""
    mark, *rest = block.items
    return replace(block, items=(Statement(STRAY_TAPE, mark.node, mark.start, mark.end), *rest))  # type: ignore[union-attr]


def _parse_continued(parser: LineParser, lines: Iterable[tuple[str, str]], file: str) -> Iterator[Block]:
    for number, content, eol in continued_lines(lines, parser.dialect.continuation or ""):
        yield parser.parse(content, eol, number, file)


def parse_text(text: str, file: str = "<string>", grammar: str | Dialect = "iso") -> list[Block]:
    import io

    return list(parse_stream(io.BytesIO(text.encode("latin-1")), file, grammar))
