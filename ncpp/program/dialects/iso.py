"""ISO / Fanuc / LinuxCNC writer: motion events back to NC text.

A block none of whose segments changed is written as it was read.  For a
changed block the first segment edits the block itself (its other words,
N number and comments stay); further segments of the same block become new
blocks carrying only what moves.  Numbers imitate the program: each letter
is written in the style of the last number the program wrote with it,
with at least the resolution needed for compensation.
"""

from __future__ import annotations

from dataclasses import replace
from typing import Iterable, Iterator

from ncpp.motion.segments import PLANE_AXES, Arc, Context, Event, Line
from ncpp.program.blocks import Block, ExprWord, Word
from ncpp.program.numbers import NumberStyle, format_number
from ncpp.program.writer import _lower_case, edit_words, word_separator

AXES = "XYZ"
CENTRE_LETTERS = {17: "IJ", 18: "IK", 19: "JK"}  # as written; order of I J K words
MOTION_CODES = {0.0: 0, 1.0: 1, 2.0: 2, 3.0: 3}
DEFAULT_STYLE = NumberStyle(decimals=4)
GEOMETRY_LETTERS = "XYZIJKR"  # words a pass rewrites in a changed block
DROPPED = ("I", "J", "K", "R", "P", ",R", ",C")  # words of the old geometry a changed block loses


class IsoWriter:
    """Stateful writer; feed it the whole event stream once, in order."""

    comment_open, comment_close = "(", ")"

    def __init__(self, mm_decimals: int = 4, inch_decimals: int = 5):
        self.mm_decimals = mm_decimals
        self.inch_decimals = inch_decimals
        self.styles: dict[str, NumberStyle] = {}
        self.program_motion: int | None = None  # motion mode as the input program has it
        self.output_motion: int | None = None  # motion mode as the output has it
        self.last_written: dict[str, float] = {}  # last absolute coordinate per axis in the output, as rounded there
        self._shapes: dict[str, tuple] = {}  # per letter: the shape of the number its style was read from
        self._resolved: dict[tuple[str, bool], NumberStyle] = {}  # (letter, inch) -> style to write
        # Axes the program has positioned; before that the control's position is not
        # the interpreter's assumed zero, so a word must not be added for them.
        self.known_axes: set[str] = set()
        self._memo_block: Block | None = None
        self._memo: dict = {}

    def comment(self, text: str) -> str:
        return f"{self.comment_open}{text}{self.comment_close}"

    # -- the stream -----------------------------------------------------------
    def write(self, events: Iterable[Event]) -> Iterator[str]:
        group: list[Event] = []
        for event in events:
            if group and event.block is not group[0].block:
                yield from self._write_group(group)
                group = []
            group.append(event)
        if group:
            yield from self._write_group(group)

    def _write_group(self, group: list[Event]) -> Iterator[str]:
        block = group[0].block
        self._memo_block, self._memo = block, {}  # facts about this block, computed once
        self._learn_styles(block)
        motion = [e for e in group if type(e) is Line or type(e) is Arc]
        if not any(e.changed for e in motion):
            if self._needs_mode_restore(block):
                yield self._restore_mode_line(block)
            yield block.text
            self._after_verbatim(block, motion)
            return
        block = _literal_geometry(block)
        for n, segment in enumerate(motion):
            yield (self._edit_block(block, segment) if n == 0 else self._new_block(block, segment)) + block.eol

    # -- verbatim blocks ------------------------------------------------------
    def _learn_styles(self, block: Block) -> None:
        for item in block.items:
            if type(item) is Word and item.letter not in ("G", "M", "N", "O"):
                letter, number = item.letter, item.number
                shape = (len(number), number.find("."), number[:1])  # cheap: styles rarely change
                if self._shapes.get(letter) != shape:
                    self._shapes[letter] = shape
                    self.styles[letter] = NumberStyle.of(number)
                    self._resolved.clear()
                    if letter in AXES:
                        self.known_axes.add(letter)

    def _block_motion(self, block: Block) -> int | None:
        code = None
        for item in block.items:
            if type(item) is Word and item.letter == "G":
                if item.value in MOTION_CODES:
                    code = MOTION_CODES[item.value]
                elif 73 <= item.value <= 89:
                    code = None
        return code

    def _arc_block(self, block: Block) -> bool:
        """The block programs an arc (its P, if any, is the arc's turn count)."""
        return (self._block_motion(block) if self._has_motion_word(block) else self.program_motion) in (2, 3)

    def _has_motion_word(self, block: Block) -> bool:
        return self._fact(block, "has_motion", lambda: any(
            type(i) is Word and i.letter == "G" and (i.value in MOTION_CODES or 73 <= i.value <= 89) for i in block.items))

    def _fact(self, block: Block, name: str, compute):
        """A fact about the block being written, computed once per block."""
        if block is not self._memo_block:
            return compute()
        memo = self._memo
        if name not in memo:
            memo[name] = compute()
        return memo[name]

    def _present(self, block: Block) -> set[str]:
        return self._fact(block, "present", lambda: {w.letter for w in block.words()})

    def _needs_mode_restore(self, block: Block) -> bool:
        """A verbatim block relying on a modal motion the output changed (an arc written as lines)."""
        moves = any(type(i) is Word and i.letter in "XYZABCUVWIJKR" for i in block.items)
        return (
            moves
            and not self._has_motion_word(block)
            and self.program_motion is not None
            and self.output_motion != self.program_motion
        )

    def _restore_mode_line(self, block: Block) -> str:
        self.output_motion = self.program_motion
        return f"G{self.program_motion}{block.eol}"

    def _after_verbatim(self, block: Block, motion: list[Event]) -> None:
        if self._has_motion_word(block):
            self.program_motion = self.output_motion = self._block_motion(block)
        for segment in motion:
            self._remember_end(segment)

    def _moved(self, axis: str, value: float, segment: Line | Arc) -> bool:
        """Whether writing `value` for the axis changes what the output last said."""
        return round(value, self._style(axis, segment).decimals) != self.last_written.get(axis)

    def _remember_end(self, segment: Line | Arc) -> None:
        last, end = self.last_written, segment.end
        dx, dy, dz = self._axis_decimals(segment.context.inch)
        last["X"], last["Y"], last["Z"] = round(end[0], dx), round(end[1], dy), round(end[2], dz)

    def _axis_decimals(self, inch: bool) -> tuple[int, int, int]:
        key = ("XYZ", inch)
        found = self._resolved.get(key)
        if found is None:
            found = self._resolved[key] = tuple(self._style(a, _INCH if inch else _MM).decimals for a in AXES)
        return found

    # -- changed blocks ---------------------------------------------------------
    def _format(self, letter: str, value: float, segment: Line | Arc) -> str:
        return format_number(value, self._style(letter, segment))

    def _style(self, letter: str, segment: Line | Arc) -> NumberStyle:
        key = (letter, segment.context.inch)
        style = self._resolved.get(key)
        if style is None:
            style = self.styles.get(letter) or self.styles.get("X") or DEFAULT_STYLE
            style = self._resolved[key] = style.at_least(self.inch_decimals if key[1] else self.mm_decimals)
        return style

    def _targets(self, block: Block, segment: Line | Arc) -> dict[str, float]:
        """Axis words to write: what the block had, and whatever moved in the output."""
        present = self._present(block)
        values: dict[str, float] = {}
        decimals = self._axis_decimals(segment.context.inch)
        end = segment.end
        if segment.context.absolute:
            last, known = self.last_written, self.known_axes
            for n, axis in enumerate(AXES):
                if axis in present or (axis in known and round(end[n], decimals[n]) != last.get(axis)):
                    values[axis] = end[n]
        else:
            start = segment.start
            for n, axis in enumerate(AXES):
                delta = end[n] - start[n]
                if axis in present or round(delta, decimals[n]) != 0.0:
                    values[axis] = delta
        return values

    def _centre_words(self, segment: Arc) -> dict[str, float]:
        i, j, _ = PLANE_AXES[segment.context.plane]
        letters = {0: "I", 1: "J", 2: "K"}
        words = {}
        for axis in sorted((i, j)):
            origin = 0.0 if segment.context.arc_absolute else segment.start[axis]
            words[letters[axis]] = segment.center[axis] - origin
        return words

    def _motion_code(self, segment: Line | Arc) -> int:
        if type(segment) is Arc:
            return 3 if segment.turn > 0 else 2
        return 0 if segment.rapid else 1

    def _words(self, block: Block, segment: Line | Arc) -> dict[str, float]:
        values = self._targets(block, segment)
        if type(segment) is Arc:
            values.update(self._centre_words(segment))
        return values

    def _edit_block(self, block: Block, segment: Line | Arc) -> str:
        values = self._words(block, segment)
        styles = {letter: self._style(letter, segment) for letter in values}
        code = self._motion_code(segment)
        has_motion = self._has_motion_word(block)
        present = self._present(block)
        # centre words of the old arc, and Fanuc corner words: the corner is now explicit;
        # P is an arc's turn count, but a dwell time (G4) or blending tolerance (G64) elsewhere
        drop = [letter for letter in DROPPED if letter in present and letter not in values]
        if "P" in drop and not self._arc_block(block):
            drop.remove("P")
        raw = edit_words(block, values, styles, drop=drop, motion=code if code != self.output_motion or has_motion else None)
        if has_motion or code != self.output_motion:
            self.output_motion = code
        if has_motion:
            self.program_motion = self._block_motion(block)
        self._remember_end(segment)
        return raw

    def _new_block(self, block: Block, segment: Line | Arc) -> str:
        values = self._words(block, segment)
        code = self._motion_code(segment)
        sep = self._fact(block, "separator", lambda: word_separator(block))
        lower = self._fact(block, "lower", lambda: _lower_case(block))
        parts = []
        if code != self.output_motion:
            parts.append(f"G{code}")
            self.output_motion = code
        parts += [letter + self._format(letter, value, segment) for letter, value in values.items()]
        self._remember_end(segment)
        text = sep.join(parts) if sep else "".join(parts)
        return text.lower() if lower else text


class _Units:
    """Stands in for a segment where only its units matter (style look-ups)."""

    def __init__(self, inch: bool):
        self.context = Context(inch=inch)


_MM, _INCH = _Units(False), _Units(True)


def _literal_geometry(block: Block) -> Block:
    """The block with expression-valued geometry words (`Z[-#<depth>]`) as plain
    words: a pass changed what they evaluate to, so new numbers replace them."""
    if not any(type(i) is ExprWord and i.letter in GEOMETRY_LETTERS for i in block.items):
        return block
    items = [Word(i.letter, 0.0, "0", i.start, i.end) if type(i) is ExprWord and i.letter in GEOMETRY_LETTERS else i for i in block.items]
    return replace(block, items=items)
