"""Write blocks back to NC text.

An unchanged block is its raw text.  `edit_words` rewrites the values of some
words of a block in place, keeping every other character, and appends words
the block did not have after its last word, separated the way the block
separates its words.
"""

from __future__ import annotations

import copy
from collections.abc import Collection, Iterable, Mapping, Sequence
from typing import BinaryIO

from ncpp.program.blocks import AnyItem, Block, Comment, ExprWord, Word
from ncpp.program.numbers import NumberStyle, format_number

AXIS_LETTERS = frozenset("XYZABCUVWIJKR")


def write_blocks(blocks: Iterable[Block], out: BinaryIO) -> int:
    """Write blocks as bytes (Latin-1, the inverse of the parser's decoding)."""
    count = 0
    for block in blocks:
        out.write(block.text.encode("latin-1"))
        count += 1
    return count


def spelling(block: Block) -> tuple[str, bool]:
    """How the block spells its words: (separator, lower case).

    The separator is what stands between its first two adjacent words, a word given by an
    expression (`H#33`) one of them ('' when packed, ' ' when it has none); lower case when a
    word has a letter and none of their letters is a capital (`^60`, LinuxCNC's polar words,
    has none: capitals).
    """
    raw = block.raw
    separator = None
    previous_end = -1
    letters = capital = False
    for item in block.items:
        kind = type(item)
        if kind is not Word and kind is not ExprWord:
            previous_end = -1  # (no separator measured across a comment or a statement)
            continue
        if separator is None and previous_end >= 0:
            separator = raw[previous_end : item.start]
        previous_end = item.end
        first = raw[item.start]
        if first.isalpha():
            letters, capital = True, capital or not first.islower()
    return (" " if separator is None else separator), letters and not capital


def edit_words(
    block: Block,
    values: Mapping[str, float],
    style_for: Mapping[str, NumberStyle],
    drop: Iterable[str] = (),
    motion: int | None = None,
) -> str:
    """The raw text of `block` with the words of `values` set (replaced or
    appended) and the words of `drop` removed.

    The letter's case as written is kept for replaced words; spacing between
    items is kept; comments stay where they were.  `motion` (0-3) sets the
    block's motion G word, replacing G0-G3 or inserting one before the first
    axis word.
    """
    texts = {letter: format_number(value, style_for[letter]) for letter, value in values.items()}
    return edit_texts(block, texts, drop, motion)


def edit_texts(
    block: Block, texts: Mapping[str, str], drop: Iterable[str] = (), motion: int | None = None
) -> str:
    """`edit_words` with the numbers already written (`texts`: letter -> number text)."""
    spelled = spelling(block)  # before a G word is inserted between the words
    if motion is not None:
        block = _with_motion(block, motion)
    return set_words(block, texts, frozenset(drop), spelled)


def set_words(
    block: Block,
    texts: Mapping[str, str],
    drop: Collection[str] = (),
    spelled: tuple[str, bool] | None = None,
) -> str:
    """`edit_words` with the numbers already written (`texts`: letter -> number text)
    and no motion word to set.  `spelled` is the block's `spelling` when the caller
    knows it already (it only matters for appended words)."""
    raw = block.raw
    pieces: list[str] = []
    cursor = 0
    pending = dict(texts)
    at = (
        None  # where appended words go (an index into `pieces`): after the last axis word, else the last word
    )
    seen_axis = False
    for item in block.items:
        if type(item) is Word:
            letter = item.letter
            text = pending.pop(letter, None)
            if text is not None:  # gap, letter as written, number
                pieces += (raw[cursor : item.start + 1], text)
            elif letter in drop:  # remove the word and the separator before it (after it, when it leads)
                gap = raw[cursor : item.start]
                if _leads(pieces, gap):
                    pieces.append(gap)
                    cursor = _past_blanks(raw, item.end)
                else:
                    pieces.append(gap.rstrip(" \t"))
                    cursor = item.end
                at, seen_axis = len(pieces), True
                continue
            else:
                pieces.append(raw[cursor : item.end])
                cursor = item.end
                if letter in AXIS_LETTERS:
                    at, seen_axis = len(pieces), True
                elif not seen_axis:
                    at = len(pieces)
                continue
            cursor = item.end
            at, seen_axis = len(pieces), True
        elif type(item) is not Comment:  # comments stay in the gap before the next item
            pieces.append(raw[cursor : item.end])
            cursor = item.end
            if not seen_axis:
                at = len(pieces)
    if pending:
        sep, lower = spelled or spelling(block)
        extra = "".join(
            sep + (letter.lower() if lower else letter) + text for letter, text in pending.items()
        )
        if at is None:
            if not "".join(pieces).strip():
                extra = extra.lstrip()
        elif _bare("".join(pieces[:at])):  # after dropped words that led the block: in their place
            extra = extra.lstrip() + (sep if "".join(pieces[at:]).strip() or raw[cursor:].strip() else "")
        pieces.insert(len(pieces) if at is None else at, extra)
    pieces.append(raw[cursor:])
    return "".join(pieces)


# How an `EditPlan` cuts the raw text at a word (the text between two cuts is kept):
_REPLACE = 0  # before its number (its letter kept), again after it
_DROP = 1  # before it, the separator before it stripped, again after it
_DROP_LEADING = 4  # as _DROP, but when only blanks are kept before it: the separator after it stripped
_BEFORE = 2  # before it (something is inserted there)
_AFTER = 3  # after it (something is appended there)


class EditPlan:
    """`edit_texts` compiled for one shape of block: the words it cuts the raw text at,
    and what goes between the pieces it keeps.

    The shape is the letters of the block's words (no other items but comments) and,
    when the motion code is set, its first G0-G3 word.  `fields` maps each letter to
    write to its number as a format field (`{0:z.4f}`) of the numbers `apply` is given.
    """

    __slots__ = ("cuts", "parts", "template", "keeps_numbers")

    def __init__(
        self, cuts: tuple[tuple[int, int], ...], parts: tuple[str | int, ...], count: int, keeps_numbers: bool
    ):
        self.cuts = cuts  # (word index, how to cut): see _REPLACE ...
        self.parts = parts  # template text, and the index of each kept piece where it goes
        self.template = "".join(part if isinstance(part, str) else f"{{{count + part}}}" for part in parts)
        self.keeps_numbers = (
            keeps_numbers  # it keeps words other than G words (`F100`), whose number can be any
        )

    @classmethod
    def compile(
        cls,
        letters: Sequence[str],
        fields: Mapping[str, str],
        count: int,
        drop: Collection[str] = (),
        motion: int | None = None,
        motion_word: tuple[int, str] | None = None,
        spelled: tuple[str, bool] = (" ", False),
    ) -> EditPlan | None:
        """The plan of `edit_texts(block, texts, drop, motion)` for blocks whose words have
        these `letters`, `motion_word` (its index and number as written) being the first
        G0-G3 word; `count` numbers fill `fields`.  None for the shapes it does not cover
        (no words; a G word to insert where there is no axis word, or before a dropped one)."""
        sep, lower = spelled
        before: dict[int, str] = {}  # word index -> text inserted before it
        replace: dict[int, str] = {}  # word index -> its new number (a field or a G code)
        if motion is not None:
            if motion_word is not None:
                n, number = motion_word
                replace[n] = format_number(motion, NumberStyle.of(number))
            else:
                first = next((n for n, letter in enumerate(letters) if letter in AXIS_LETTERS), None)
                if first is None or letters[first] in drop:
                    return None
                before[first] = ("g" if lower else "G") + str(motion) + _literal(sep)
        pending = dict(fields)
        dropped: set[int] = set()
        at = None  # the word after which appended words go (as `set_words` places them)
        seen_axis = False
        for n, letter in enumerate(letters):
            field = pending.pop(letter, None) if n not in replace else None
            if field is not None or letter in drop:
                if field is not None:
                    replace[n] = field
                else:
                    dropped.add(n)
                at, seen_axis = n, True
            elif letter in AXIS_LETTERS:
                at, seen_axis = n, True
            elif not seen_axis:
                at = n
        leading = 0  # the words before the first one kept or replaced: dropped, they may lead the block
        while leading < len(letters) and leading in dropped:
            leading += 1
        if at is None or (
            pending and at < leading
        ):  # words appended where the dropped words led: `set_words`
            return None
        appended = "".join(
            _literal(sep) + (letter.lower() if lower else letter) + field for letter, field in pending.items()
        )
        cuts: list[tuple[int, int]] = []
        parts: list[str | int] = []

        def cut(n: int, how: int) -> None:
            parts.append(len(cuts))
            cuts.append((n, how))

        for n in range(len(letters)):
            if n in before:
                cut(n, _BEFORE)
                parts.append(before[n])
            if n in replace:
                cut(n, _REPLACE)
                parts.append(replace[n])
            elif n in dropped:
                cut(n, _DROP_LEADING if n < leading else _DROP)
            if n == at and appended:
                if n not in replace and n not in dropped:
                    cut(n, _AFTER)
                parts.append(appended)
        parts.append(len(cuts))
        kept = {n for n, letter in enumerate(letters) if letter != "G"} - replace.keys() - dropped
        return cls(tuple(cuts), tuple(parts), count, bool(kept))

    def apply(self, raw: str, words: Sequence[Word], numbers: Sequence[float]) -> str:
        """The edited text of a block of this shape (`words`: its words, in order)."""
        return self.template.format(*numbers, *self._kept(raw, words))

    def template_for(self, raw: str, words: Sequence[Word]) -> str:
        """`apply`'s template with the pieces of `raw` it keeps as its text: the template of every
        block with the same layout (other digits) and G words, when it keeps no other numbers
        (`keeps_numbers`, comments)."""
        kept = self._kept(raw, words)
        return "".join(part if isinstance(part, str) else _literal(kept[part]) for part in self.parts)

    def _kept(self, raw: str, words: Sequence[Word]) -> list[str]:
        """The pieces of `raw` it keeps."""
        pieces: list[str] = []
        keep = pieces.append
        cursor = 0
        for n, how in self.cuts:
            word = words[n]
            if how == _REPLACE:
                keep(raw[cursor : word.start + 1])
                cursor = word.end
            elif how == _DROP:
                keep(raw[cursor : word.start].rstrip(" \t"))
                cursor = word.end
            elif how == _DROP_LEADING:
                gap = raw[cursor : word.start]
                if _leads(pieces, gap):
                    keep(gap)
                    cursor = _past_blanks(raw, word.end)
                else:
                    keep(gap.rstrip(" \t"))
                    cursor = word.end
            elif how == _BEFORE:
                keep(raw[cursor : word.start])
                cursor = word.start
            else:
                keep(raw[cursor : word.end])
                cursor = word.end
        keep(raw[cursor:])
        return pieces


def _leads(kept: Sequence[str], gap: str) -> bool:
    """A word after the `kept` pieces and `gap` leads its block: no separator before it
    but blanks that stay (an indent, the blank of a `/ ` block delete)."""
    return not gap.strip() and _bare("".join(kept))


def _bare(text: str) -> bool:
    """Nothing but blanks, or ending in one: a word after it needs no separator."""
    return not text.strip() or text[-1] in " \t"


def _past_blanks(raw: str, at: int) -> int:
    """The index after the spaces and tabs of `raw` from `at`."""
    return len(raw) - len(raw[at:].lstrip(" \t"))


def _literal(text: str) -> str:
    """`text` as literal text of a format template."""
    return text.replace("{", "{{").replace("}", "}}")


def _with_motion(block: Block, code: int) -> Block:
    """The block with its G0-G3 word set to `code` (items re-spanned)."""
    raw = block.raw
    for item in block.items:
        if type(item) is Word and item.letter == "G" and item.value in (0.0, 1.0, 2.0, 3.0):
            if item.value == code:
                return block
            text = raw[item.start] + format_number(code, NumberStyle.of(item.number))
            new_raw = raw[: item.start] + text + raw[item.end :]
            return _respan(block, new_raw, item.end, len(text) - (item.end - item.start))
    first = next((i for i in block.items if type(i) is Word and i.letter in AXIS_LETTERS), None)
    at = first.start if first is not None else len(raw.rstrip())
    sep, lower = spelling(block)
    g = ("g" if lower else "G") + str(code)
    text = g + sep if first is not None else (sep if raw.strip() else "") + g
    return _respan(block, raw[:at] + text + raw[at:], at, len(text))


def _respan(block: Block, raw: str, after: int, shift: int) -> Block:
    """Shift the spans of items that start at or after `after` by `shift`."""
    if shift == 0:  # `G2` -> `G1`: the same spans
        return Block(raw, block.eol, block.items, block.line)
    return Block(
        raw, block.eol, tuple(_shifted(i, shift) if i.start >= after else i for i in block.items), block.line
    )


def _shifted(item: AnyItem, shift: int) -> AnyItem:
    """A copy of the item `shift` characters further on (constructors: far cheaper than copy.copy)."""
    start, end = item.start + shift, item.end + shift
    if type(item) is Word:
        return Word(item.letter, item.value, item.number, start, end)
    if type(item) is Comment:
        return Comment(item.text, item.style, start, end)
    moved = copy.copy(item)
    moved.start, moved.end = start, end
    return moved
