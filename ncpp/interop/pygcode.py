"""Adapter between ncpp blocks and pygcode `Line` objects.

For users who already hold their G-code as pygcode objects::

    from ncpp.interop.pygcode import to_pygcode, from_pygcode

    line = to_pygcode(block)          # pygcode.Line, or None
    block = from_pygcode(line)        # ncpp Block, parsed by ncpp's own parser

`to_pygcode(block)` builds the Line from the block's words directly (not by
re-parsing text), so every word keeps its exact value: `X3.2100` becomes
pygcode's `Word('X', 3.21)`, `T01` keeps pygcode's string value `'01'`.  The
words are grouped into G codes with pygcode's own `words2gcodes`, without
pygcode's check that two codes of one modal group do not share a block.  It
returns None for what pygcode cannot represent: expressions and parameters
(`X[#1+2]`, `#1=5`), control statements (o-words, IF/WHILE/GOTO), block
delete, program names, letters outside A-Z (`,C` chamfers, `@` `^` polar
words, `$` spindle selectors), a fractional value for pygcode's integer
letters (`N10.5`, `L2.5`), and verbatim blocks after the closing `%`.
pygcode keeps one comment per line: several comments are joined with ". ",
and the comment is a `;` comment if the block had one.

`from_pygcode(line, style)` writes the line's words as text in ncpp's own
number style and parses that text with ncpp's parser, so the result is an
ordinary lossless Block.  pygcode's formatting (`X3.21` rounded to three
places, `G01`) is not used: each value is written with `format_number`
using the style given for its letter, with as many more decimals as the
value needs to be kept exactly (`style.at_least`).  `style` is a
`NumberStyle` for the dimension letters (X Y Z A B C U V W I J K R) or a
mapping letter -> `NumberStyle` (as `ncpp.program.writer.edit_words` takes);
other letters get the shortest exact form (`G1`, `S12000`, `F1500`).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Mapping
from decimal import Decimal

import pygcode
from pygcode.comment import CommentBrackets, CommentSemicolon
from pygcode.words import WORD_MAP

from ncpp.program.blocks import Block, Comment, Statement, Word
from ncpp.program.numbers import NumberStyle, format_number
from ncpp.program.parser import LineParser
from ncpp.program.writer import AXIS_LETTERS

__all__ = ["to_pygcode", "from_pygcode"]

COMMENT_JOINER = CommentBrackets.MULTICOMMENT_JOINER  # pygcode's own ". "


def to_pygcode(block: Block) -> pygcode.Line | None:
    """The block as a pygcode Line with the same word values, or None (see module doc)."""
    if block.verbatim:
        return None
    words, comments, macro, semicolon = [], [], None, False
    for item in block.items:
        if type(item) is Word:
            word = _pygcode_word(item)
            if word is None:
                return None
            words.append(word)
        elif type(item) is Comment:
            comments.append(item.text.lstrip() if item.style == ";" else item.text)  # as pygcode reads it
            semicolon = semicolon or item.style == ";"
        elif type(item) is Statement and item.kind == "tape" and macro is None:
            macro = block.source(item)
        else:
            return None
    line = pygcode.Line()
    line.block = pygcode.Block()
    line.block.words = words
    line.block.gcodes, line.block.modal_params = pygcode.words2gcodes(words)
    if comments:
        kind = CommentSemicolon if semicolon else CommentBrackets
        line.comment = kind(COMMENT_JOINER.join(comments))
    line.macro = macro
    return line


def _pygcode_word(word: Word) -> pygcode.Word | None:
    if word.letter not in WORD_MAP:
        return None
    kind = WORD_MAP[word.letter]["class"]
    if kind is str:  # T and O: pygcode keeps the digits as written
        return pygcode.Word(word.letter, word.number.lstrip("+"))
    if kind is int and not word.value.is_integer():
        return None
    return pygcode.Word(word.letter, kind(word.value))


PLAIN = NumberStyle()  # numbers written as pygcode gives them


def from_pygcode(
    line: pygcode.Line,
    style: NumberStyle | Mapping[str, NumberStyle] = PLAIN,
    eol: str = "\n",
) -> Block:
    """A Block parsed by ncpp from the line's words written in ncpp's number style."""
    styles = style if isinstance(style, Mapping) else {letter: style for letter in AXIS_LETTERS}
    words = line.block.words if line.block is not None else []
    pieces = [word.letter + _number_text(word.value, styles.get(word.letter)) for word in words]
    if line.comment is not None:
        pieces.append(str(line.comment))
    if line.macro:
        pieces.append(line.macro)
    return _parser().parse(" ".join(pieces), eol)


def _number_text(value: float | int | str, style: NumberStyle | None) -> str:
    """`value` in `style`, with enough decimals to keep it exactly."""
    if isinstance(value, str):
        return value
    if not math.isfinite(value):
        raise ValueError(f"cannot write {value!r} as an NC number")
    needed = max(0, -Decimal(repr(float(value))).normalize().as_tuple().exponent)  # type: ignore[operator]
    style = (style or NumberStyle(decimals=0)).at_least(needed)
    text = format_number(value, style)
    while float(text) != value:  # rounding at a power of two can need one more place
        style = style.at_least(style.decimals + 1)
        text = format_number(value, style)
    return text


@functools.lru_cache(maxsize=1)
def _parser() -> LineParser:
    return LineParser("iso")
