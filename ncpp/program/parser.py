"""Parse NC text into lossless blocks, one line at a time (streaming).

The grammar (`grammar/<dialect>.lark`) is the single definition of the
syntax.  Most lines of real programs are plain words and comments
(`X2.612 Z-0.1497`); for those the parser takes a fast path: a scanner
compiled from the grammar's own WORD / COMMA_WORD / PAREN_COMMENT /
SEMI_COMMENT terminals, which yields the same items the LALR parser would
(a test checks that on the whole corpus).  Everything else goes through the
Lark LALR parser.
"""

from __future__ import annotations

import functools
import re
from pathlib import Path
from typing import BinaryIO, Iterable, Iterator

import lark
from lark import Token, Transformer, v_args

from ncpp.errors import Location, NcppError
from ncpp.program.blocks import AnyItem, Block, Comment, ExprWord, Statement, Word

_GAP = "[ \\t\\r\\f\\v\\x1a]*"


def grammar_path(name: str) -> Path:
    """Grammar files ship inside the wheel as ncpp/grammar; in a checkout they sit at the top."""
    package = Path(__file__).resolve().parent.parent
    for folder in (package / "grammar", package.parent / "grammar"):
        candidate = folder / f"{name}.lark"
        if candidate.exists():
            return candidate
    raise FileNotFoundError(f"grammar {name}.lark not found beside the ncpp package")


@functools.lru_cache(maxsize=None)
def lalr_parser(name: str) -> lark.Lark:
    return lark.Lark(
        grammar_path(name).read_text(encoding="utf-8"),
        parser="lalr",
        propagate_positions=True,
        maybe_placeholders=False,
        cache=False,
    )


def _number_value(number: str) -> float:
    return float(number.replace(" ", "").replace("\t", ""))


def _word(text: str, start: int, end: int) -> Word:
    """`Z -110` -> Word('Z', -110.0, '-110'); `,c1.` -> Word(',C', 1.0, '1.')."""
    if text[0] == ",":
        body = text[1:].lstrip(" \t")
        letter, number = "," + body[0].upper(), body[1:]
    else:
        letter, number = text[0].upper(), text[1:]
    number = number.replace(" ", "").replace("\t", "")
    return Word(letter, float(number), number, start, end)


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
    del _statement

    @v_args(meta=True)
    def oword_number(self, meta, children):
        """`O1000` is a plain word (Fanuc program number); `O<name>` alone is a statement."""
        (tok,) = children
        if "<" in tok:
            return Statement("oword", (str(tok),), meta.start_pos, meta.end_pos)
        return _word(str(tok), meta.start_pos, meta.end_pos)

    @v_args(meta=True)
    def assignment(self, meta, children):
        target, value = children
        return Statement("assignment", (target, value), meta.start_pos, meta.end_pos)

    # -- expressions -----------------------------------------------------------
    def number(self, children):
        return ("num", float(children[0]))

    def param(self, children):
        (key,) = children
        if isinstance(key, Token):
            return ("param", int(key) if key.type == "INT" else str(key).lower())
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


class LineParser:
    """Parses one line of a dialect into a Block."""

    FAST_TERMINALS = ("WORD", "COMMA_WORD", "PAREN_COMMENT", "SEMI_COMMENT")

    def __init__(self, grammar: str = "iso"):
        self.grammar = grammar
        self._lark = lalr_parser(grammar)
        self._builder = _ItemBuilder()
        patterns = {t.name: t.pattern.to_regexp() for t in self._lark.terminals}
        alternatives = "|".join(f"(?P<{name}>{patterns[name]})" for name in self.FAST_TERMINALS)
        self._fast = re.compile(f"{_GAP}(?:{alternatives})")
        self._blank = re.compile(f"{_GAP}$")

    def parse(self, raw: str, eol: str = "", line: int = 0, file: str = "<stdin>") -> Block:
        items = self._scan_plain(raw)
        if items is None:
            items = self._parse_lalr(raw, line, file)
        return Block(raw, eol, items, line)

    def _scan_plain(self, raw: str) -> tuple[AnyItem, ...] | None:
        """Items of a line made only of plain words and comments, else None."""
        items: list[AnyItem] = []
        pos = 0
        match = self._fast.match
        while True:
            m = match(raw, pos)
            if m is None:
                break
            kind = m.lastgroup
            start, end = m.start(kind), m.end(kind)
            if kind == "WORD" or kind == "COMMA_WORD":
                items.append(_word(m.group(kind), start, end))
            elif kind == "PAREN_COMMENT":
                items.append(Comment(raw[start + 1 : end - 1], "(", start, end))
            else:
                items.append(Comment(raw[start + 1 : end], ";", start, end))
            pos = end
        if pos == len(raw) or self._blank.match(raw, pos):
            return tuple(items)
        return None

    def _parse_lalr(self, raw: str, line: int, file: str) -> tuple[AnyItem, ...]:
        try:
            tree = self._lark.parse(raw)
        except lark.exceptions.UnexpectedInput as err:
            col = getattr(err, "column", None)
            raise NcppError(_describe(err, raw), Location(file, line, col)) from None
        items = self._builder.transform(tree)
        return tuple(item for item in _flatten(items))


def _flatten(items: Iterable) -> Iterator[AnyItem]:
    for item in items:
        if isinstance(item, tuple):
            yield from _flatten(item)
        else:
            yield item


def _describe(err: lark.exceptions.UnexpectedInput, raw: str) -> str:
    col = getattr(err, "column", 1) or 1
    rest = raw[col - 1 :].strip()
    if isinstance(err, lark.exceptions.UnexpectedEOF) or not rest:
        return "unexpected end of block"
    if isinstance(err, lark.exceptions.UnexpectedToken) and err.token.type == "$END":
        return "unexpected end of block"
    snippet = rest[:20]
    if rest[0] == "(":
        return f"unclosed comment: {snippet!r}"
    if isinstance(err, lark.exceptions.UnexpectedToken):
        return f"unexpected {snippet!r}"
    return f"cannot read {snippet!r}"


def iter_lines(stream: BinaryIO) -> Iterator[tuple[str, str]]:
    """(content, eol) for each line of a binary stream, decoded losslessly."""
    for raw in stream:
        text = raw.decode("latin-1")
        if text.endswith("\r\n"):
            yield text[:-2], "\r\n"
        elif text.endswith("\n"):
            yield text[:-1], "\n"
        else:
            yield text, ""


def parse_stream(stream: BinaryIO, file: str = "<stdin>", grammar: str = "iso") -> Iterator[Block]:
    """Blocks of a program, lazily.  After the closing `%` lines are kept verbatim
    (a control stops reading there)."""
    parser = LineParser(grammar)
    tape_marks = 0
    for number, (content, eol) in enumerate(iter_lines(stream), start=1):
        if tape_marks >= 2:
            yield Block(content, eol, (), number, verbatim=True)
            continue
        block = parser.parse(content, eol, number, file)
        if block.items and type(block.items[0]) is Statement and block.items[0].kind == "tape":
            tape_marks += 1
        elif tape_marks == 0 and block.items:
            tape_marks = -10**9  # material before any `%`: the program has no tape marks
        yield block


def parse_text(text: str, file: str = "<string>", grammar: str = "iso") -> list[Block]:
    import io

    return list(parse_stream(io.BytesIO(text.encode("latin-1")), file, grammar))
