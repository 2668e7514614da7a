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

from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line
from ncpp.program.blocks import Block, ExprWord, Word
from ncpp.program.numbers import NumberStyle, format_number
from ncpp.program.writer import edit_words, word_separator

AXES = "XYZ"
CENTRE_LETTERS = {17: "IJ", 18: "IK", 19: "JK"}  # as written; order of I J K words
MOTION_CODES = {0.0: 0, 1.0: 1, 2.0: 2, 3.0: 3}
DEFAULT_STYLE = NumberStyle(decimals=4)
GEOMETRY_LETTERS = "XYZIJKR"  # words a pass rewrites in a changed block


class IsoWriter:
    """Stateful writer; feed it the whole event stream once, in order."""

    comment_open, comment_close = "(", ")"

    def __init__(self, mm_decimals: int = 4, inch_decimals: int = 5):
        self.mm_decimals = mm_decimals
        self.inch_decimals = inch_decimals
        self.styles: dict[str, NumberStyle] = {}
        self.program_motion: int | None = None  # motion mode as the input program has it
        self.output_motion: int | None = None  # motion mode as the output has it
        self.last_written: dict[str, str] = {}  # last absolute coordinate text per axis in the output
        # Axes the program has positioned; before that the control's position is not
        # the interpreter's assumed zero, so a word must not be added for them.
        self.known_axes: set[str] = set()

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
                self.styles[item.letter] = NumberStyle.of(item.number)
                if item.letter in AXES:
                    self.known_axes.add(item.letter)

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
        return any(type(i) is Word and i.letter == "G" and (i.value in MOTION_CODES or 73 <= i.value <= 89) for i in block.items)

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

    def _remember_end(self, segment: Line | Arc) -> None:
        for axis, value in zip(AXES, segment.end):
            self.last_written[axis] = self._format(axis, value, segment)

    # -- changed blocks ---------------------------------------------------------
    def _format(self, letter: str, value: float, segment: Line | Arc) -> str:
        return format_number(value, self._style(letter, segment))

    def _style(self, letter: str, segment: Line | Arc) -> NumberStyle:
        style = self.styles.get(letter) or self.styles.get("X") or DEFAULT_STYLE
        return style.at_least(self.inch_decimals if segment.context.inch else self.mm_decimals)

    def _targets(self, block: Block, segment: Line | Arc) -> dict[str, float]:
        """Axis words to write: what the block had, and whatever moved in the output."""
        present = {w.letter for w in block.words()}
        values: dict[str, float] = {}
        for n, axis in enumerate(AXES):
            if segment.context.absolute:
                text = self._format(axis, segment.end[n], segment)
                if axis in present or (axis in self.known_axes and text != self.last_written.get(axis)):
                    values[axis] = segment.end[n]
            else:
                delta = segment.end[n] - segment.start[n]
                if axis in present or float(self._format(axis, delta, segment)) != 0.0:
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
        # centre words of the old arc, and Fanuc corner words: the corner is now explicit
        drop = [letter for letter in ("I", "J", "K", "R", "P", ",R", ",C") if letter not in values]
        if not self._arc_block(block):  # P is a dwell time (G4) or blending tolerance (G64) there
            drop = [letter for letter in drop if letter != "P"]
        raw = edit_words(block, values, styles, drop=drop, motion=code if code != self.output_motion or self._has_motion_word(block) else None)
        if self._has_motion_word(block) or code != self.output_motion:
            self.output_motion = code
        if self._has_motion_word(block):
            self.program_motion = self._block_motion(block)
        self._remember_end(segment)
        return raw

    def _new_block(self, block: Block, segment: Line | Arc) -> str:
        values = self._words(block, segment)
        code = self._motion_code(segment)
        sep = word_separator(block)
        lower = bool(block.words()) and all(block.raw[w.start].islower() for w in block.words() if block.raw[w.start].isalpha())
        parts = []
        if code != self.output_motion:
            parts.append(f"G{code}")
            self.output_motion = code
        parts += [letter + self._format(letter, value, segment) for letter, value in values.items()]
        self._remember_end(segment)
        text = sep.join(parts) if sep else "".join(parts)
        return text.lower() if lower else text


def _literal_geometry(block: Block) -> Block:
    """The block with expression-valued geometry words (`Z[-#<depth>]`) as plain
    words: a pass changed what they evaluate to, so new numbers replace them."""
    if not any(type(i) is ExprWord and i.letter in GEOMETRY_LETTERS for i in block.items):
        return block
    items = [Word(i.letter, 0.0, "0", i.start, i.end) if type(i) is ExprWord and i.letter in GEOMETRY_LETTERS else i for i in block.items]
    return replace(block, items=items)
