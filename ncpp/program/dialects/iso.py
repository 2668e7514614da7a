"""ISO / Fanuc / LinuxCNC writer: motion events back to NC text.

A block none of whose segments changed is written as it was read.  For a
changed block the first segment edits the block itself (its other words,
N number and comments stay); further segments of the same block become new
blocks carrying only what moves.  Numbers imitate the program: each letter
is written in the style of the last number the program wrote with it,
with at least the resolution needed for compensation.
"""

from __future__ import annotations

import math
import re
from collections.abc import Callable, Collection, Iterable, Iterator
from dataclasses import replace
from itertools import takewhile
from operator import itemgetter
from typing import Protocol

from ncpp.motion.cycles import CANNED
from ncpp.motion.once import OnceRuns
from ncpp.motion.segments import (
    CYCLE,
    DRILLED,
    EXTRA_AXES,
    PLANE_AXES,
    TAP_IN,
    TAP_OUT,
    Arc,
    Context,
    Event,
    Line,
    Pass,
    Setting,
    plane_letters,
)
from ncpp.passes.rotary import time_shares, turns
from ncpp.program.blocks import DIGITS_AS_ONE, Block, Comment, ExprWord, Statement, Word
from ncpp.program.numbers import NumberStyle, format_number
from ncpp.program.writer import EditPlan, _literal, _with_motion, set_words, spelling

AXES = "XYZ"
_XYZ = frozenset(AXES)
_NUMBERED_AXES = tuple(enumerate(AXES))  # ((0, "X"), ...): no enumerate object per line written
CENTRE_WORDS = {
    17: (("I", 0), ("J", 1)),
    18: (("I", 0), ("K", 2)),
    19: (("J", 1), ("K", 2)),
}  # (letter, axis), as written
_CENTRE_AXES = {plane: (a, b) for plane, ((_, a), (_, b)) in CENTRE_WORDS.items()}
MOTION_CODES = {0.0: 0, 1.0: 1, 2.0: 2, 3.0: 3}
DEFAULT_STYLE = NumberStyle(decimals=4)
GEOMETRY_LETTERS = "XYZIJKR"  # words a pass rewrites in a changed block
WRITTEN_LETTERS = "XYZIJK"  # the letters the writer writes numbers for
MOVING_LETTERS = "XYZABCUVWIJKR"  # words that make a block move (with the modal motion)
AXES_NOT_MOVED = frozenset(
    (10.0, 28.0, 30.0, 52.0, 92.0, 43.1)
)  # G codes whose axis words no modal motion moves to
# Letters whose number styles the writer uses: it writes XYZIJK (and CR, with X's style,
# for Sinumerik); the styles of other words (F, S, R, ...) are never asked for, so not learnt.
STYLED_LETTERS = frozenset(WRITTEN_LETTERS)
DROPPED = (
    "I",
    "J",
    "K",
    "R",
    "P",
    ",R",
    ",C",
    "@",
    "^",
)  # words of the old geometry a changed block loses (`@` `^`: polar)
_DROPPED = frozenset(DROPPED)
_BIT = {letter: 1 << n for n, letter in enumerate(WRITTEN_LETTERS)}  # a set of written letters is a bit mask
_ALL_AXES = _BIT["X"] | _BIT["Y"] | _BIT["Z"]
_CENTRE_BITS = {plane: _BIT[a] | _BIT[b] for plane, ((a, _), (b, _)) in CENTRE_WORDS.items()}
# Per bit mask: the letters written, in order, each with the index of its number in `_numbers`
# (X Y Z: 0 1 2; an arc's two centre words: 3 4).
_WRITTEN = tuple(
    tuple(
        (letter, n if n < 3 else 3 + sum(bool(bits & _BIT[c]) for c in WRITTEN_LETTERS[3:n]))
        for n, letter in enumerate(WRITTEN_LETTERS)
        if bits & _BIT[letter]
    )
    for bits in range(1 << len(WRITTEN_LETTERS))
)
_AXIS_BITS = _BIT["X"] | _BIT["Y"] | _BIT["Z"]
_ANY_CENTRE = _BIT["I"] | _BIT["J"] | _BIT["K"]
_UNKNOWN = object()  # a plan not compiled yet
_SIGNATURE_WORD = re.compile(r"(.)([-+.\d]*)")  # a letter, and a G word's number
_MAX_LAYOUTS = 10000  # layouts remembered (comments can make every layout new)
_MAX_UNITS = 64  # sets of number styles remembered with their compiled lines (a program uses a few)


_LONG_GROUP = 1024  # events of one block past which the writer asks whether it needs them all


# Fanuc macro B's control statements (`ncpp.motion.flow`): a loop's runs belong to its END line
_FANUC_CONTROL = frozenset(("goto", "if", "while", "end"))  # (statement kinds)


def _lines_ended(
    write_group: Callable[[list[Event]], Iterable[str]],
) -> Callable[[list[Event]], Iterable[str]]:
    """`write_group` whose lines each end a line but the last of a block that ends none (a file's
    last line without a newline): split in several lines, or followed by a guard's, they would run
    into one (`G1 X0.0004 Y0G2 ...`), a block the control reads otherwise or refuses."""
    eol = "\n"

    def ended(group: list[Event]) -> Iterable[str]:
        nonlocal eol
        end = group[0].block.eol
        if end:
            eol = end  # (a file's lines end alike: its last line's new neighbours end as the one before)
            return write_group(group)
        lines = list(write_group(group))
        return [line if line.endswith("\n") else line + eol for line in lines[:-1]] + lines[-1:]

    return ended


class Stamps(Protocol):
    """How far the writer has read (`pipeline._Reached`), which the verifier tags written lines by:
    `state` now, and `pin` to tag the lines handed out next with an earlier one (None: now again)."""

    state: tuple[int, int, int]

    def pin(self, state: tuple[int, int, int] | None) -> None: ...


Piece = tuple[list[str], "tuple[int, int, int] | None"]  # written lines and their tag (None: no stamps)


class _Text:
    """A line of a definition's text held (`_AtDefinition`): written so unless its run stands in
    its place."""

    __slots__ = ("key", "name", "piece")

    def __init__(self, key: int, name: str, piece: Piece):
        self.key, self.name, self.piece = key, name, piece


class _AtDefinition:
    """`write_group`, with the one run of a subroutine (`Interpreter.run`, `OnceRuns`) written where
    its definition stands, each line tagged (`stamps`) as where the writer had read when it wrote it:
    the verifier cuts the run into the same chunks as the input's.  The run's lines are written
    where the run comes (the writer's state follows the program as it runs) and placed:

    * a definition after the call: the lines of a block among `runs.blocks` are kept from its run
      and written in place of its text;
    * a definition before the call (`runs.ahead`): the lines from its text on are held until its
      run has been written, then written with the run's lines in place of its text, the lines held
      after them; one told to stay as programmed (`runs.programmed`) keeps its text.  What is held
      is bounded: `Interpreter.run` tells a definition as programmed where the events from the first
      one waiting pass `runs.held_most`."""

    def __init__(
        self, write_group: Callable[[list[Event]], Iterable[str]], runs: OnceRuns, stamps: Stamps | None
    ):
        self.write_group = write_group
        self.runs = runs
        self.ahead, self.blocks = runs.ahead, runs.blocks  # (filled in place as the reading goes on)
        self.stamps = stamps
        self.kept: dict[int, Piece] = {}  # a run's lines, by its block's id, until its definition's text
        self.held: list[Piece | _Text] | None = None  # the lines from a definition before its call on
        self.names: set[str] = set()  # the definitions the lines held wait for
        self.ran: dict[int, list[Piece]] = {}  # the run's lines of a line held, by the line's id
        self.written: set[str] = set()  # those of the names whose run's lines came

    def write(self, group: list[Event]) -> Iterable[str]:
        key = id(group[0].block)
        if self.held is None and key not in self.ahead:
            if key not in self.blocks:
                return self.write_group(group)
            return self._placed(self._after(key, group))
        return self._hold(group, key)

    def finish(self) -> Iterable[str]:
        """The lines still held where the program's lines end (a definition never told: its text)."""
        return () if self.held is None else self._placed(self._released())

    def _state(self) -> tuple[int, int, int] | None:
        return self.stamps.state if self.stamps is not None else None

    def _after(self, key: int, group: list[Event]) -> list[Piece]:
        """A block of a run whose definition comes after it: its lines kept, then at the definition's
        text, written there."""
        if key in self.kept:  # (the definition's text)
            return [self.kept.pop(key)]
        self.kept[key] = (list(self.write_group(group)), self._state())
        return []

    def _hold(self, group: list[Event], key: int) -> Iterable[str]:
        """A group while lines are held, or a line of a definition's text met before its call."""
        first = group[0]
        name = self.runs.ahead.get(key)
        text = name is not None and type(first) is Pass and first.skipped  # the definition's text
        run = name if not text and name in self.names and key in self.runs.blocks else None  # its run
        # (told since the last group: what is held goes first, and this group may start another hold)
        pieces = self._released() if self.held is not None and self._told(run) else []
        if text and name is not None and name not in self.runs.programmed:
            if self.held is None:
                self.held = []
            self.names.add(name)
            self.held.append(_Text(key, name, (list(self.write_group(group)), self._state())))
        elif run is not None:
            self.ran.setdefault(key, []).append((list(self.write_group(group)), self._state()))
            self.written.add(run)
        else:
            lines = (self._after(key, group) if key in self.runs.blocks else
                     [(list(self.write_group(group)), self._state())])  # fmt: skip
            (pieces if self.held is None else self.held).extend(lines)
        if self.held is not None and self._told(run):
            pieces += self._released()
        return self._placed(pieces) if pieces else ()

    def _told(self, run: str | None) -> bool:
        """Whether each definition the lines held wait for is told: to stay as programmed, or its
        run's lines written (but `run`'s, whose lines are coming)."""
        programmed = self.runs.programmed
        return all(n in programmed or (n in self.written and n != run) for n in self.names)

    def _released(self) -> list[Piece]:
        """The lines held, a run's in place of its definition's text, and no more held."""
        pieces: list[Piece] = []
        for item in self.held or ():
            if type(item) is _Text:
                ran = self.ran.pop(item.key, None) if item.name in self.written else None
                pieces += ran or [item.piece]
            else:
                pieces.append(item)  # type: ignore[arg-type]
        self.held, self.ran = None, {}
        self.names.clear()
        self.written.clear()
        return pieces

    def _placed(self, pieces: list[Piece]) -> Iterator[str]:
        stamps = self.stamps
        if stamps is None:
            for lines, _ in pieces:
                yield from lines
            return
        for lines, state in pieces:
            stamps.pin(state)
            yield from lines
        stamps.pin(None)


# a guard's checks written before a block, and after it, told the axes X Y Z its G92 / G10 L20 sets
# that the program has not positioned (`IsoWriter.write`, `ncpp/guard.py`)
ChecksBefore = Callable[[list[Event]], list[str]]
ChecksAfter = Callable[[list[Event], Collection[str]], list[str]]


def _none(events: list[Event]) -> list[str]:
    return []


def _none_after(events: list[Event], unplaced: Collection[str]) -> list[str]:
    return []


def _setting_of(group: list[Event]) -> Setting | None:
    """The `Setting` of a block's G92 / G10 L20 whose axes `_write_group` tells of: its first
    event's, past the steps back of a loop or call ahead of it (`Setting`s of no values)."""
    for event in group:
        if type(event) is not Pass or event.setting is None or event.skipped or event.cycle is not None:
            return None
        if event.setting.values:
            return event.setting
    return None


def _leads_in(event: Event) -> bool:
    """Whether the event is a step to a canned cycle's programmed start (`apply_error_map._lead_in`): after
    a control line's first event, the cycle its text runs first, the step written before that line (inside
    the text it would run again with each run)."""
    return type(event) is Line and event.fixed == CYCLE and event.changed


def written_at_once(event: Event) -> bool:
    """Whether the writer writes the block of its first `event` from that event alone, at once: a
    control line's (an o-word, M97, M98, M99) that runs, whose text depends only on its `Pass`; the
    moves it runs after it (a loop's next runs, a subroutine's) are left as programmed and not
    kept, so a loop of any length is written (and verified, `ncpp.verify`) as it runs."""
    if type(event) is not Pass or event.skipped or event.cycle is not None or event.setting is not None:
        return False  # (a setting's: a step back before a loop or call, `entries.py`, precedes its event)
    signature = event.block.signature  # (a plain block is a control line by its M97-M99 only)
    return (signature is None or "M" in signature) and _Facts(event.block).flow


class IsoWriter:
    """Stateful writer; feed it the whole event stream once, in order."""

    comment_open, comment_close = "(", ")"
    control_at_once = True  # control lines are written at their first event (`written_at_once`)
    written_at_once = staticmethod(written_at_once)

    def __init__(self, mm_decimals: int = 4, inch_decimals: int = 5):
        self.mm_decimals = mm_decimals
        self.inch_decimals = inch_decimals
        self.styles: dict[str, NumberStyle] = {}
        self.program_motion: int | None = None  # motion mode as the input program has it
        self.output_motion: int | None = None  # motion mode as the output has it
        # Axes the program has positioned; before that the control's position is not
        # the interpreter's assumed zero, so a word must not be added for them.
        self.known_axes: set[str] = set()
        # told, once each, of the axes X Y Z the program has not positioned where a compensated feed
        # move leaves out its correction along them (`_tell_unpositioned`: "Y" or "X and Y")
        self.unpositioned: Callable[[str, Block], None] | None = None
        self._told_unpositioned: set[str] = set()
        # told of a G92 / G10 L20 (its events) that sets its offset from axes X Y Z the program has not
        # positioned yet: from where the control stands, which ncpp takes to be its assumed start (["X", "Y"])
        self.unplaced_setting: Callable[[list[str], list[Event]], None] | None = None
        # told of a loop or call in which interpretation ends (it may set an offset from where the control
        # stands), after a compensated move, in a mode (G2/G3, a cycle) a step back would change
        self.unstepped: Callable[[Block], None] | None = None
        # the subroutines run once, written where their definition stands (`_AtDefinition`)
        self.once_runs: OnceRuns | None = None
        self.stamps: Stamps | None = None  # how far it has read, where a verifier tags its lines by it
        # Per layout of a plain block's text (`DIGITS_AS_ONE`): what its numbers teach, see `_read_layout`.
        self._layouts: dict[bytes, tuple] = {}
        self._layout: tuple[Block | None, bytes] = (None, b"")  # the last block whose layout was read, and it
        self._interned_lessons: dict[tuple, tuple] = {}  # equal (letter, style) tuples are one
        self._last_lesson: tuple | None = (
            None  # the (letter, style) learnt last (learning them again changes nothing)
        )
        # Derived from `styles`, emptied when a style changes: (letter, inch) -> style to write,
        # inch -> `_Written` (the styles of WRITTEN_LETTERS and the decimal places of X, Y, Z).
        self._resolved: dict = {}
        self._interned_units: dict[
            tuple, _Written
        ] = {}  # styles -> their `_Written`, so its plans outlive a style change
        self._facts_block: Block | None = None  # the last block asked about, and its facts
        self._facts_value: _Facts = None  # type: ignore[assignment]  # (read only with `_facts_block`)
        self._signature_facts: dict[str, _Facts] = {}  # the facts of plain blocks, by their `signature`
        self._spelled: tuple[Block | None, tuple[str, bool]] = (
            None,
            (" ", False),
        )  # a block and its `spelling`
        # The end of the last segment written (where the output is, once rounded to the decimal
        # places of X, Y and Z it was written with): rounded only when compared, and most
        # axes a block does not write are exactly where they were.
        self._last_end: tuple[float, float, float] | None = None
        self._last_places: tuple[int, int, int] = (0, 0, 0)
        self._last_context: Context | None = None  # the frame (units, offsets) `_last_end` is in
        self._frame_seen: Context | None = None  # the frame of the last block's moves (`_settle_plane`)
        self._plane_unsettled = False  # a rotation turned or moved the frame since a move gave X and Y
        self._unsettled_letters = frozenset("XY")  # the axes of the plane(s) it turned (`_settle_plane`)

    def comment(self, text: str) -> str:
        return f"{self.comment_open}{text}{self.comment_close}"

    def _ran(self, event: Event) -> None:
        """An event of the runs of a control line written at once (`written_at_once`), not kept."""

    # -- the stream -----------------------------------------------------------
    def write(
        self,
        events: Iterable[Event],
        after: ChecksAfter | None = None,
        before: ChecksBefore | None = None,
    ) -> Iterator[str]:
        """The written lines, block by block; `before(events)` and `after(events, unplaced)` give
        lines to precede and to follow a block's (the guards' checks, `ncpp/guard.py`)."""
        group: list[Event] = []
        block = None
        written: Callable[[list[Event]], Iterable[str]] = self._write_group
        if after is not None or before is not None:
            ahead, behind = before or _none, after or _none_after
            written = lambda group: self._checked(group, ahead, behind)  # noqa: E731
        write_group = _lines_ended(written)
        placing = None
        if self.once_runs is not None:
            placing = _AtDefinition(write_group, self.once_runs, self.stamps)
            write_group = placing.write
        control = False  # the group is a control line's, whose writing reads only its first event
        leading = False  # a control line's first event, held for the lead-in steps that may follow it
        ran = self._ran if type(self)._ran is not IsoWriter._ran else None  # (ISO's does nothing)
        for event in events:
            if event.block is block:
                if leading and _leads_in(event):
                    group.append(event)
                    continue
                if leading:
                    yield from write_group(group)
                    group, control, leading = [], True, False
                if not control:
                    group.append(event)
                    # (a loop's end or a call owns every move it runs, millions for a long loop: not kept)
                    control = len(group) == _LONG_GROUP and self._facts(block).flow
                elif ran is not None:
                    ran(event)
                continue
            if group:
                yield from write_group(group)
            block, group, control, leading = event.block, [event], False, False
            if self.control_at_once and self.written_at_once(event):
                leading = True
        if group:
            yield from write_group(group)
        if placing is not None:
            yield from placing.finish()

    def _tell_unpositioned(self, block: Block, motion: list[Line | Arc]) -> None:
        """Before a compensated block that feeds is written: tell `unpositioned` of the axes X Y Z
        the program has not positioned yet (each once), whose correction its moves leave out until
        it does (a rapid's, to a clearance before the first cut, matters to no part)."""
        if self.unpositioned is None or len(self._told_unpositioned) == 3 or _XYZ <= self.known_axes:
            return
        if all(type(m) is Line and m.rapid for m in motion):
            return
        new = sorted(_XYZ - self.known_axes - self._told_unpositioned)
        if new:
            self._told_unpositioned.update(new)
            self.unpositioned(" and ".join(new), block)

    def _checked(self, group: list[Event], before: ChecksBefore, after: ChecksAfter) -> list[str]:
        """A block's lines between the guards' checks, `after` told the axes its G92 / G10 L20 sets
        that the program has not positioned, read before its words position them."""
        setting = _setting_of(group)
        unplaced = self._unplaced(setting) if setting is not None else ()
        return [*before(group), *self._write_group(group), *after(group, unplaced)]

    def _unplaced(self, setting: Setting) -> list[str]:
        """The axes X Y Z a G92 / G10 L20 sets that the program has not positioned yet."""
        return sorted({AXES[i] for i, _ in setting.values} - self.known_axes)

    def _tell_unplaced(self, group: list[Event], setting: Setting) -> None:
        """Before a G92 / G10 L20 is written (its words then position its axes): tell
        `unplaced_setting` of the axes X Y Z it sets that the program has not positioned yet."""
        if self.unplaced_setting is None:
            return
        unplaced = self._unplaced(setting)
        if unplaced:
            self.unplaced_setting(unplaced, group)

    def _write_group(self, group: list[Event]) -> Iterable[str]:
        """The lines of one block's events (a list: cheaper than a generator per block)."""
        first = group[0]
        block = first.block
        if type(first) is Pass and first.skipped:  # text the program does not run: it teaches nothing
            return [block.text]
        if type(first) is Pass and first.cycle is not None:
            return self._expanded(block, group)
        if type(first) is Pass and first.setting is not None:
            if not first.setting.values:  # a loop's or call's step back (`ncpp.motion.entries`), in its mode
                step = self._step_back(block, first.setting, MOTION_CODES.get(first.motion))  # type: ignore[arg-type]
                return [*step, *(self._write_group(group[1:]) if group[1:] else ())]
            self._tell_unplaced(group, first.setting)
        facts = self._read_block(block, any(type(e) is Line or type(e) is Arc for e in group))
        if facts.flow:
            # (`write`: the steps to the programmed start of a canned cycle the line's text runs first)
            steps = [as_written(e) for e in takewhile(_leads_in, group[1:])]  # type: ignore[arg-type]
            return [
                *(self._new_blocks(block, steps, block.eol) if steps else ()),
                *self._write_control(block, first),
            ]
        if type(first) is Pass and first.setting is not None and first.setting.shift is not None:
            if first.setting.leaves and self.program_motion in (0, 1):
                return self._stepped_back(block, first.setting)
            return [self._setting_text(block, first.setting) + block.eol]
        motion = [as_written(e) for e in group if type(e) is Line or type(e) is Arc]
        self._settle_plane(block, motion)
        # steps to a canned cycle's start (`apply_error_map._lead_in`): new blocks before it
        lead = sum(1 for _ in takewhile(_leads_in, motion))
        lines = self._new_blocks(block, motion[:lead], block.eol) if lead else []
        motion = motion[lead:] if lead else motion
        hole = motion[0].hole if motion and type(motion[0]) is Line else None
        drilled = hole is not None and hole.command is not None  # a compensated cycle: its words change
        for segment in motion:
            if segment.changed:
                break
        else:  # nothing changed, or a compensated cycle's words only
            self._learn_program_motion(block, motion)
            if self._needs_mode_restore(block):
                lines.append(self._restore_mode_line(block))
            if drilled:
                lines += self._hole_texts(block, motion)  # type: ignore[arg-type]
            else:
                lines.append(block.text)
            self._after_verbatim(block, motion)
            return lines
        self._tell_unpositioned(block, motion)
        # a drilling cycle the block calls after its move, a rigid tap's return: the control's, from its text
        called = len(motion)
        while called > 1 and (motion[called - 1].fixed == DRILLED or _returns(motion[called - 1])):
            called -= 1
        cycle, motion = called < len(motion), motion[:called]
        if not facts.plain:
            block = _literal_geometry(block)
        eol = block.eol
        if len(motion) > 1 and (motion[0].context.inverse_time or motion[0].extra):
            lines += self._write_pieces(block, motion, eol)
        else:
            lines.append(self._edit_block(block, motion[0]) + eol)
            if len(motion) > 1:
                lines += self._new_blocks(block, motion[1:], eol)
        if cycle:  # the cycle leaves the tool elsewhere: the next block writes every axis it knows
            self._last_end = None
        return lines

    def _write_pieces(self, block: Block, pieces: list, eol: str) -> list[str]:
        """A move written in pieces that each need words of their own: the axes beyond X Y Z
        (A B C, U V W) where they turn their share of the move, and in G93 the F that gives
        each its share of the move's time (`rotary.time_shares`)."""
        more = self._piece_words(block, pieces)
        block = _literal_geometry(block, "".join(more[0]))
        return [self._edit_block(block, pieces[0], more[0]) + eol] + self._new_blocks(
            block, pieces[1:], eol, more[1:]
        )

    def _piece_words(self, block: Block, pieces: list) -> list[dict[str, str]]:
        """Per piece: letter -> number text of its words beyond X Y Z I J K (`_write_pieces`)."""
        given = {item.letter: item for item in block.items if type(item) is Word or type(item) is ExprWord}

        def style(letter: str) -> NumberStyle:
            word = given.get(letter)
            return (NumberStyle.of(word.number) if type(word) is Word else DEFAULT_STYLE).at_least(4)

        feeds = (
            [pieces[0].feed / share for share in time_shares(pieces)]
            if pieces[0].context.inverse_time
            else None
        )
        out = []
        for k, piece in enumerate(pieces):
            words = {}
            for i, value in enumerate(piece.extra):
                letter = EXTRA_AXES[i]
                if (k == 0 and letter in given and value != pieces[-1].extra[i]) or (
                    k > 0 and turns(piece) and value != piece.extra_start[i]
                ):
                    words[letter] = format_number(self._piece_number(piece, i, style(letter)), style(letter))
            if feeds is not None and not (type(piece) is Line and piece.rapid):
                words["F"] = format_number(feeds[k], style("F"))
            out.append(words)
        return out

    @staticmethod
    def _piece_number(piece: Line | Arc, i: int, style: NumberStyle) -> float:
        """The number a piece's word beyond X Y Z writes: where the axis turns to, or in G91 (which
        reads every axis word as an increment) the difference of that and the piece's start as
        written, so that the increments add up to the move's (`_numbers`)."""
        value = piece.extra[i]
        if piece.context.absolute or not piece.extra_start:
            return value
        return round(value, style.decimals) - round(piece.extra_start[i], style.decimals)

    # -- what a block says --------------------------------------------------------
    def _facts(self, block: Block) -> _Facts:
        """The facts of `block`, read once while it is being written."""
        if block is not self._facts_block:
            self._facts_block, self._facts_value = block, _Facts(block)
        return self._facts_value

    def _read_block(self, block: Block, moves: bool = True) -> _Facts:
        """The facts of a block about to be written; its number styles are learnt, and the axes its
        words name are known (`known_axes`) where it `moves` (a block whose words set an offset, a
        frame or a pole moves none)."""
        signature = block.signature
        facts: _Facts | None
        if signature is None:
            facts = _Facts(block)
            if moves:  # (an axis word written as an expression, `Y[0]` or `Y#5`, positions as a number does)
                self.known_axes.update(facts.expression_axes)
        else:  # a handful of signatures make most blocks (`XZ`, `G1XY`): read each once
            facts = self._signature_facts.get(signature)
            if facts is None:
                facts = self._signature_facts[signature] = _Facts.of_signature(signature)
        self._facts_block, self._facts_value = block, facts
        if moves and facts.axis_letters:
            self.known_axes.update(facts.axis_letters)
        if facts.styled:
            if signature is None:
                self._learn_word_styles(block, facts)
            else:
                self._learn_layout_styles(block, facts)
        return facts

    def _learn_word_styles(self, block: Block, facts: _Facts) -> None:
        """Learn the number styles of the block's styled words, reading each number."""
        words = _words(block, facts)
        for n, letter in facts.styled:
            self._learn_style(letter, NumberStyle.of(words[n].number))
        self._last_lesson = None

    def _learn_layout_styles(self, block: Block, facts: _Facts) -> None:
        """Learn the number styles of a plain block's styled words: the styles are those of
        its layout's numbers, read once per layout, unless a number is zero-padded."""
        raw = block.raw
        layout = self._layout_of(block)
        lesson = self._layouts.get(layout)
        if lesson is None:
            lesson = self._read_layout(block, facts, layout)
        styles, firsts, spelled = lesson
        if spelled is not None:
            self._spelled = (block, spelled)
        if firsts is not None and "0" in firsts(raw):  # `X010.5`: the layout does not say the padding
            self._learn_word_styles(block, facts)
        elif styles is not self._last_lesson:
            known = self.styles
            for letter, style in styles:
                if known.get(letter) is not style:
                    self._learn_style(letter, style)
            self._last_lesson = styles

    def _layout_of(self, block: Block) -> bytes:
        """The block's raw text with every digit '1' (`Block.layout` where the parser read it;
        else made once per block: styles and edits ask)."""
        layout = block.layout
        if layout is None:
            known, layout = self._layout
            if known is not block:
                layout = block.raw.encode("latin-1").translate(DIGITS_AS_ONE)
                self._layout = (block, layout)
        return layout

    def _read_layout(self, block: Block, facts: _Facts, layout: bytes) -> tuple:
        """(the (letter, style) of each styled word of the layout, a getter of the first digits of
        its numbers with more than one digit before the point or None if there are none, its
        `spelling` or None if its separator has digits, in a comment)."""
        if len(self._layouts) >= _MAX_LAYOUTS:
            self._layouts.clear()
        text, words = layout.decode("latin-1"), _words(block, facts)
        styles, firsts = [], []
        for n, letter in facts.styled:
            word = words[n]
            number = text[word.end - len(word.number) : word.end]
            styles.append((letter, NumberStyle.of(number)))
            digits = number.lstrip("+-").lstrip(" \t")
            if len(digits.partition("," if "," in digits else ".")[0]) > 1:
                firsts.append(word.end - len(digits))
        spelled = spelling(block)
        lesson = self._layouts[layout] = (
            self._interned_lessons.setdefault(tuple(styles), tuple(styles)),
            itemgetter(*firsts) if firsts else None,
            None if any(map(str.isdigit, spelled[0])) else spelled,
        )
        return lesson

    def _learn_style(self, letter: str, style: NumberStyle) -> None:
        known = self.styles.get(letter)
        if known is not style and known != style:  # styles read from numbers are interned: mostly `is`
            self.styles[letter] = style
            # what is resolved from styles is written with at least mm_decimals / inch_decimals places:
            # `X1.125` then `X0.` (trailing zeros dropped, cameo.nc: 29k changes in 35k lines) write alike
            if known is None or not (
                known.resolves_like(style, self.mm_decimals)
                and known.resolves_like(style, self.inch_decimals)
            ):
                self._resolved.clear()

    def _block_motion(self, block: Block) -> int | None:
        return self._facts(block).motion

    def _has_motion_word(self, block: Block) -> bool:
        return self._facts(block).motion_word

    def _arc_block(self, block: Block) -> bool:
        """The block programs an arc (its P, if any, is the arc's turn count)."""
        return (self._block_motion(block) if self._has_motion_word(block) else self.program_motion) in (2, 3)

    def _spelling(self, block: Block) -> tuple[str, bool]:
        """How the block spells its words: (separator, lower case)."""
        spelled_block, spelled = self._spelled
        if spelled_block is not block:
            spelled = spelling(block)
            self._spelled = (block, spelled)
        return spelled

    # -- verbatim blocks ------------------------------------------------------
    def _learn_program_motion(self, block: Block, motion: list[Line | Arc]) -> None:
        """After a control line the program's mode is unknown here (and the output's known once
        a block was edited): a verbatim block moving without a motion word runs in it."""
        if self.program_motion is None and self.output_motion is not None and motion and not motion[0].fixed:
            if self._facts(block).moves and not self._has_motion_word(block):
                self.program_motion = self._motion_code(motion[0])

    def _needs_mode_restore(self, block: Block) -> bool:
        """A verbatim block relying on a modal motion the output changed (an arc written as lines)."""
        return (
            self._facts(block).moves
            and not self._has_motion_word(block)
            and self.program_motion is not None
            and self.output_motion != self.program_motion
        )

    def _restore_mode_line(self, block: Block) -> str:
        self.output_motion = self.program_motion
        return f"G{self.program_motion}{block.eol}"

    def _settle_plane(self, block: Block, motion: list[Line | Arc]) -> None:
        """After a rotation of the coordinate system turned or moved the frame (Fanuc's G68 and G69,
        Klartext's Cycle 10, Sinumerik's frames), the control places the axes of the plane it turns (X and
        Y; Z and X for a G68 in G18, Y and Z in G19) once a move gives both absolutely, and the interpreter
        follows no move of one of them alone before (`settle_rotation`): the first block edited there
        writes every axis it knows, so that a correction written on a move along the other axis, or a word
        left out where its axis stands, does not give one of them alone."""
        for segment in motion:
            seen, context = self._frame_seen, segment.context
            if seen is not None and seen is not context and _turns_plane(seen, context):
                self._plane_unsettled = True
                turned = (frame for frame in (seen, context) if frame.rotation is not None)
                self._unsettled_letters = frozenset(
                    "".join(plane_letters(frame.rotation_plane) for frame in turned)
                )
            self._frame_seen = context
        if not (self._plane_unsettled and motion):
            return
        if any(segment.changed for segment in motion):
            if motion[0].context.absolute:
                self._last_end, self._plane_unsettled = None, False
        elif self._unsettled_letters <= {
            i.letter for i in block.items if type(i) is Word or type(i) is ExprWord
        }:
            self._plane_unsettled = False  # (the program's own block gives both, as the control needs)

    def _after_verbatim(self, block: Block, motion: list[Line | Arc]) -> None:
        if self._has_motion_word(block):
            self.program_motion = self.output_motion = self._block_motion(block)
        for segment in motion:
            self._remember_end(segment)
        if motion and motion[-1].fixed:
            # a canned cycle, a loop or a subroutine: where it leaves the tool is the control's (G98
            # retracts to the compensated level it started from), so the next block writes every axis it knows
            self._last_end = None

    def _expanded(self, block: Block, group: list[Event]) -> list[str]:
        """A canned cycle's block written as its moves (--expand-cycles): its other words first
        (`_cycle_rest`), then a G0/G1 block per move, a G4 where it dwells.  The program's motion
        mode after it is the cycle's, which no block written after relies on (a block moving in it
        is one of these too)."""
        self._read_block(block)
        eol, (separator, lower) = block.eol, self._spelling(block)
        rest = _cycle_rest(block, separator)
        lines = [rest + eol] if rest else []
        run: list[Line | Arc] = []
        for event in group[1:]:
            if type(event) is Pass and event.dwell is not None:
                lines += self._new_blocks(block, run, eol)
                dwell = f"G4{separator}{event.dwell_word}"
                lines.append((dwell.lower() if lower else dwell) + eol)
                run = []
            elif type(event) is Line or type(event) is Arc:
                run.append(event)
        lines += self._new_blocks(block, run, eol)
        self.program_motion = None
        return lines

    def _hole_texts(self, block: Block, moves: list[Line]) -> list[str]:
        """A compensated canned cycle's block with its corrected X Y Z R, each written: every hole
        has a correction of its own, so none may be left to the previous block's sticky value.  Polar
        words (`@` `^`) give way to the X Y they put the hole at.  A block of repeats (L) is written
        a block per hole: the first without its L, the others X Y Z R alone, which continue the
        cycle (rs274ngc's convert_cycle: the same motion again keeps the series)."""
        firsts = [m for k, m in enumerate(moves) if k == 0 or m.hole is not moves[k - 1].hole]
        spelled = self._spelling(block)
        words = [self._hole_words(move) for move in firsts]
        hole = firsts[0].hole
        assert hole is not None
        # (the repeats' word: L, or Fanuc's K, where K is no G87's top)
        drop = "@^" + ("L" + ("K" if hole.top is None or hole.fanuc_back else "") if hole.repeats > 1 else "")
        lines = [set_words(_literal_geometry(block, GEOMETRY_LETTERS + drop), words[0], drop=drop,
                           spelled=spelled) + block.eol]  # fmt: skip
        separator, lower = spelled
        for texts in words[1:]:
            text = separator.join(f"{letter}{number}" for letter, number in texts.items())
            lines.append((text.lower() if lower else text) + block.eol)
        return lines

    def _hole_words(self, move: Line) -> dict[str, str]:
        """The words a hole is written with (letter -> number text): its position in the plane,
        its bottom along the normal (G17: X Y Z) and R, its corrected command; in G91 as rs274ngc
        reads a cycle there: the plane's axes from where the control stands, R from the level the
        series started at, the bottom from R."""
        hole = move.hole
        assert hole is not None and hole.command is not None  # (apply_error_map's)
        first, second, normal = PLANE_AXES[hole.plane]
        aa, bb, bottom, r = hole.command
        top = hole.top_command
        if hole.fanuc_back and top is not None:
            return self._fanuc_back_words(move, (aa, bb, r, top))
        if not move.context.absolute:
            top = None if top is None else top - bottom
            aa, bb = aa - move.start[first], bb - move.start[second]
            bottom, r = bottom - r, r - hole.series_level
        letters, values = [AXES[first], AXES[second], AXES[normal], "R"], [aa, bb, bottom, r]
        if top is not None:  # G87: its offset as programmed (an increment from the hole), its top corrected
            letters += ["IJK"[first], "IJK"[second], "IJK"[normal]]
            values += [hole.offset[0], hole.offset[1], top]
        return {
            letter: format_number(value, self._style(letter, move)) for letter, value in zip(letters, values)
        }

    def _fanuc_back_words(self, move: Line, command: tuple[float, float, float, float]) -> dict[str, str]:
        """`_hole_words` of Fanuc's G87 (G17 only): X Y the hole, R the level below the part its cut starts
        from, Z the top it ends at, all corrected; in G91 X Y from where the control stands, R from the
        level the series started at, Z from R (Fanuc Series 15i-MA operator's manual, "Back boring cycle
        (G87)").  Its shift I J, modal in the cycle, stays as the program writes it (or leaves it)."""
        hole = move.hole
        assert hole is not None
        aa, bb, r, top = command
        if not move.context.absolute:
            aa, bb, r, top = aa - move.start[0], bb - move.start[1], r - hole.series_level, top - r
        values = {"X": aa, "Y": bb, "Z": top, "R": r}
        return {letter: format_number(value, self._style(letter, move)) for letter, value in values.items()}

    # -- o-word control lines ---------------------------------------------------
    def _write_control(self, block: Block, first: Event) -> list[str]:
        """A control line (`o100 call`, `o100 endwhile`, `M98 P100`) with the moves it runs
        (the subroutine's, the loop's next iterations, left as programmed): its text.  The
        control must be in the program's motion mode there (the lines it runs may rely on
        it; the interpreter tells it on the line's `Pass`); after it the mode is the
        program's, unknown here, and nowhere else: the next edited block writes its motion
        word, and every axis it knows."""
        program = MOTION_CODES.get(first.motion) if type(first) is Pass else None  # type: ignore[arg-type]
        restore = program is not None and self.output_motion is not None and self.output_motion != program
        lines = [f"G{program}{block.eol}", block.text] if restore else [block.text]
        self.program_motion = self.output_motion = None
        self._last_end = None
        return lines

    # -- G92, G10 L10/L11/L20 -------------------------------------------------------------
    def _stepped_back(self, block: Block, setting: Setting) -> list[str]:
        """A block that sets an offset from where the control stands and ends interpretation: a step
        back to the programmed point first, in the program's G0 or G1 mode, so that the block and
        the blocks after it, which ncpp does not follow, read the point the program means."""
        return [*self._step_back(block, setting, self.program_motion), block.text]

    def _step_back(self, block: Block, setting: Setting, mode: int | None) -> list[str]:
        """The step back from where the control stands to the programmed point before `block`
        (`Setting.shift`: none where nothing compensated stands before it), in the program's `mode`;
        in a mode other than G0 or G1, which a step would change for the blocks after it,
        `unstepped` is told instead."""
        at, shift = setting.position, setting.shift
        if shift is None:
            return []
        if mode not in (0, 1):
            if self.unstepped is not None:
                self.unstepped(block)
            return []
        here = (at[0] + shift[0], at[1] + shift[1], at[2] + shift[2])
        step = Line(here, at, mode == 0, 0.0, block, setting.context)
        lines = self._new_blocks(block, [as_written(step)], block.eol)
        self._last_end = None  # (the block sets another frame)
        return lines

    def _setting_text(self, block: Block, setting: Setting) -> str:
        """A G92 / G10 L10/L11/L20 block with its axis values moved by where the control stands off the
        programmed point (`Setting.shift`): the offset the control computes from them is the
        program's.  After it the output's position is in another frame: the next move writes
        every axis it knows."""
        self._last_end = None
        assert setting.shift is not None  # (the pass told it, or the block was not handed here)
        shift = _program_shift(setting)
        moved = [(axis, value + shift[axis]) for axis, value in setting.values if shift[axis] != 0.0]
        if not moved:
            return block.raw
        styles = self._units(setting.context.inch).styles
        return set_words(
            _literal_geometry(block),
            {AXES[axis]: format_number(value, styles[AXES[axis]]) for axis, value in moved},
        )

    # -- numbers as written -----------------------------------------------------
    def _moved(self, axis: str, value: float, segment: Line | Arc) -> bool:
        """Whether writing `value` for the axis changes what the output last said."""
        (last, places), n = self._last_seen_from(segment.context), AXES.index(axis)
        return last is None or written_apart(value, self._style(axis, segment).decimals, last[n], places[n])

    def _last_seen_from(self, context: Context) -> tuple[tuple | None, tuple]:
        """(where the output is, the decimal places to compare it with) in `context`'s frame:
        after a change of units or offsets, the numbers last written, as the control holds them
        (`seen_from`)."""
        last, frame = self._last_end, self._last_context
        if last is None or frame is context or frame is None or not reframed(frame, context):
            return last, self._last_places
        return seen_from(last, self._last_places, frame, context, self._units(context.inch).places)

    def _remember_end(self, segment: Line | Arc, units: _Written | None = None) -> None:
        """The segment's end is where the output is now, written with `units`' places
        (the segment's units, looked up unless the caller has them)."""
        if units is None:
            inch = segment.context.inch  # once per line written: `_units`' cached look-up inlined
            units = self._resolved.get(inch) or self._units(inch)
        self._last_end, self._last_places, self._last_context = segment.end, units.places, segment.context

    def _format(self, letter: str, value: float, segment: Line | Arc) -> str:
        return format_number(value, self._style(letter, segment))

    def _style(self, letter: str, segment: Line | Arc | _Units) -> NumberStyle:
        key = (letter, segment.context.inch)
        style = self._resolved.get(key)
        if style is None:
            style = self.styles.get(letter) or self.styles.get("X") or DEFAULT_STYLE
            style = self._resolved[key] = style.at_least(self.inch_decimals if key[1] else self.mm_decimals)
        return style

    def _units(self, inch: bool) -> _Written:
        """How the output writes numbers in these units, resolved once per change of styles."""
        found = self._resolved.get(inch)
        if found is None:
            units = _INCH if inch else _MM
            styles = {letter: self._style(letter, units) for letter in WRITTEN_LETTERS}
            key = tuple(styles.values())
            found = self._interned_units.get(key)
            if found is None:
                if len(self._interned_units) >= _MAX_UNITS:  # each holds compiled lines: keep memory flat
                    self._interned_units.clear()
                found = self._interned_units[key] = _Written(styles)
            self._resolved[inch] = found
        return found

    # -- changed blocks ---------------------------------------------------------
    def _motion_code(self, segment: Line | Arc) -> int:
        if type(segment) is Arc:
            return 3 if segment.turn > 0 else 2
        return 0 if segment.rapid else 1

    def _written_bits(self, facts: _Facts, segment: Line | Arc, units: _Written) -> int:
        """`_bits_written` where the output is now."""
        frame = self._last_context
        context = segment.context
        if frame is context or frame is None or self._last_end is None or not reframed(frame, context):
            return _bits_written(
                facts, segment, units.places, self.known_axes, self._last_end, self._last_places
            )
        last, places = self._last_seen_from(segment.context)
        return _bits_written(facts, segment, units.places, self.known_axes, last, places, named=False)

    @staticmethod
    def _numbers(segment: Line | Arc, places: tuple[int, int, int]) -> tuple[float, ...]:
        """The numbers the segment writes, indexed as in `_WRITTEN`; `places`: the decimals of X, Y, Z.
        An increment (G91) is the difference of its end and start as written with those places, so
        that the control, adding them up, stands where the absolute positions would put it: rounded
        one by one, a run of increments drifts by their roundings' sum."""
        context, end = segment.context, segment.end
        if not context.absolute:
            start = segment.start
            x, y, z = places
            end = (
                round(end[0], x) - round(start[0], x),
                round(end[1], y) - round(start[1], y),
                round(end[2], z) - round(start[2], z),
            )
        if type(segment) is not Arc:
            return end
        centre, (a, b) = segment.center, _CENTRE_AXES[context.plane]
        if context.arc_absolute:
            return (*end, centre[a], centre[b])
        start = segment.start
        return (*end, centre[a] - start[a], centre[b] - start[b])

    def _texts(self, block: Block, segment: Line | Arc) -> dict[str, str]:
        """The words to write for the segment, letter -> number as the output writes it."""
        units = self._units(segment.context.inch)
        numbers = self._numbers(segment, units.places)
        styles = units.styles
        return {
            letter: format_number(numbers[n], styles[letter])
            for letter, n in _WRITTEN[self._written_bits(self._facts(block), segment, units)]
        }

    def _machine_texts(self, facts: _Facts, segment: Line | Arc) -> dict[str, str]:
        """`_texts` of a G53 line, whose numbers are machine coordinates (in program units):
        what it writes is decided in program coordinates, like every other block's."""
        units = self._units(segment.context.inch)
        end, offset = segment.context.turned(segment.end), segment.context.offset
        machine = (end[0] + offset[0], end[1] + offset[1], end[2] + offset[2])
        return {
            letter: format_number(machine[n], units.styles[letter])
            for letter, n in _WRITTEN[self._written_bits(facts, segment, units)]
        }

    def _edit_block(self, block: Block, segment: Line | Arc, more: dict[str, str] | None = None) -> str:
        if type(segment) is Line and segment.tap == TAP_IN:
            return self._edit_tap(block, segment)
        facts = self._facts_value if block is self._facts_block else self._facts(block)  # `_facts`, inlined
        code = (
            (3 if segment.turn > 0 else 2) if type(segment) is Arc else 0 if segment.rapid else 1
        )  # `_motion_code`
        output_motion = self.output_motion
        # the block's motion word is set when it says another motion, or when the output's mode is another
        motion = code if facts.first_motion != code and (code != output_motion or facts.motion_word) else None
        inch = segment.context.inch
        units = self._resolved.get(inch) or self._units(inch)
        # a G53 line's numbers are machine coordinates: no plan compiled for program coordinates
        raw = None if facts.machine or more else self._planned_edit(block, facts, segment, motion, units)
        if raw is None:
            raw = self._general_edit(block, facts, segment, motion, more)
        if facts.motion_word:
            self.output_motion, self.program_motion = code, facts.motion
        elif code != output_motion:
            self.output_motion = code
        self._last_end, self._last_places, self._last_context = (
            segment.end,
            units.places,
            segment.context,
        )  # `_remember_end`
        return raw

    def _edit_tap(self, block: Block, tap: Line) -> str:
        """A rigid tap's block (G33.1) with its corrected end: its G33.1, K (the pitch) and I stay.  The
        output's motion mode is the tap's, which a block written after it does not rely on."""
        texts = self._texts(block, tap)
        spelled = None if self._facts(block).letters.issuperset(texts) else self._spelling(block)
        self.output_motion = self.program_motion = None
        return set_words(block, texts, [], spelled)

    def _planned_edit(
        self, block: Block, facts: _Facts, segment: Line | Arc, motion: int | None, units: _Written
    ) -> str | None:
        """The edit by a plan compiled for the block's signature (None: a block no plan covers)."""
        signature = block.signature
        if (
            signature is None or not units.plain or "P" in facts.letters
        ):  # P: a turn count or not, see `_general_edit`
            return None
        bits = self._written_bits(facts, segment, units)
        # words the block lacks are appended spelled as the block was read
        spelled = (
            self._spelling(block)
            if bits & ~facts.bits or (motion is not None and facts.motion_at is None)
            else None
        )
        raw = block.raw
        # the block's layout, and a plan: blocks of one layout without comments whose numbers the
        # plan writes or drops all (but G words', in the signature) are its template with their numbers
        key = (self._layout_of(block), signature, bits, motion, spelled)
        edit = units.edits.get(key)
        if edit is None:
            plan = self._edit_plan(facts, signature, bits, motion, spelled, units)
            if plan is None:
                return None
            if len(units.edits) >= _MAX_LAYOUTS:
                units.edits.clear()
            comments = len(block.items) != facts.words
            edit = units.edits[key] = (
                plan if plan.keeps_numbers or comments else plan.template_for(raw, block.items)  # type: ignore[arg-type]
            )
        # (`_numbers`, inlined for an absolute line)
        numbers = (
            segment.end
            if type(segment) is Line and segment.context.absolute
            else self._numbers(segment, units.places)
        )
        if type(edit) is str:
            return edit.format(*numbers)
        return edit.apply(raw, _words(block, facts), numbers)  # type: ignore[union-attr]  # (a plan)

    @staticmethod
    def _edit_plan(
        facts: _Facts,
        signature: str,
        bits: int,
        motion: int | None,
        spelled: tuple[str, bool] | None,
        units: _Written,
    ) -> EditPlan | None:
        """The plan of an edit of a block with this signature, compiled once."""
        key = (signature, bits, motion, spelled)
        plan = units.edit_plans.get(key, _UNKNOWN)
        if plan is _UNKNOWN:
            dropped = [
                letter
                for letter in DROPPED + tuple(AXES)
                if letter in facts.letters and not bits & _BIT.get(letter, 0)
            ]
            plan = units.edit_plans[key] = EditPlan.compile(
                facts.word_letters,
                units.fields(bits),
                5 if bits & _ANY_CENTRE else 3,
                dropped,
                motion,
                facts.motion_at,
                spelled or (" ", False),
            )
        return plan  # type: ignore[return-value]

    def _general_edit(
        self,
        block: Block,
        facts: _Facts,
        segment: Line | Arc,
        motion: int | None,
        more: dict[str, str] | None = None,
    ) -> str:
        texts = self._machine_texts(facts, segment) if facts.machine else self._texts(block, segment)
        if more:  # (a piece's own words: `_write_pieces`)
            texts.update(more)
        # centre words of the old arc, and Fanuc corner words: the corner is now explicit;
        # P is an arc's turn count, but a dwell time (G4) or blending tolerance (G64) elsewhere
        drop = [letter for letter in DROPPED + tuple(AXES) if letter in facts.letters and letter not in texts]
        if "P" in drop and not self._arc_block(block):
            drop.remove("P")
        # words the block lacks are appended spelled as the block was read (before a G word is inserted)
        spelled = None if facts.letters.issuperset(texts) else self._spelling(block)
        return set_words(block if motion is None else _with_motion(block, motion), texts, drop, spelled)

    def _new_blocks(
        self, block: Block, segments: list[Line | Arc], eol: str, more: list[dict[str, str]] | None = None
    ) -> list[str]:
        """The lines of the segments a block makes after its first (arc pieces, reversal
        steps, subdivisions): new blocks, spelled as the block is.  Once per line written:
        what is the same for all of them is read once, the output's state is kept in locals
        (`_written_bits` with it), and `_motion_code`, `_numbers` (for an absolute line) and
        `_remember_end` are inlined."""
        facts = self._facts(block)
        spelled = self._spelling(block)
        known = self.known_axes
        output_motion, last, last_places = self.output_motion, self._last_end, self._last_places
        lines: list[str] = []
        context, frame = None, self._last_context  # (`frame`: the one `last` is in)
        for segment in segments:
            if segment.context is not context:  # (the segments of a block share their context, mostly)
                context = segment.context
                if (
                    last is not None
                    and frame is not None
                    and frame is not context
                    and reframed(frame, context)
                ):
                    last, last_places = seen_from(
                        last, last_places, frame, context, self._units(context.inch).places
                    )
                frame = context
                inch, absolute = context.inch, context.absolute
                units = self._resolved.get(inch) or self._units(inch)
                places = units.places
                templates = units.new_lines.setdefault((spelled, eol), {}) if units.plain else None
            code = (3 if segment.turn > 0 else 2) if type(segment) is Arc else 0 if segment.rapid else 1
            bits = _bits_written(facts, segment, places, known, last, last_places)
            motion = code if code != output_motion else None
            values = segment.end if code < 2 and absolute else self._numbers(segment, places)
            words = more[len(lines)] if more else None  # (a piece's own words: `_write_pieces`)
            if words:
                texts = {
                    letter: format_number(values[n], units.styles[letter]) for letter, n in _WRITTEN[bits]
                }
                lines.append(_new_block_text({**texts, **words}, motion, spelled) + eol)
            elif templates is not None:
                key = new_block_key(bits, motion)
                template = templates.get(key)
                if template is None:
                    template = templates[key] = (
                        _new_block_text(units.fields(bits), motion, (_literal(spelled[0]), spelled[1])) + eol
                    )
                lines.append(template.format(*values))
            else:
                styles = units.styles
                texts = {letter: format_number(values[n], styles[letter]) for letter, n in _WRITTEN[bits]}
                lines.append(_new_block_text(texts, motion, spelled) + eol)
            if motion is not None:
                output_motion = code
            last, last_places = segment.end, places
        self.output_motion, self._last_end, self._last_places, self._last_context = (
            output_motion,
            last,
            last_places,
            context,
        )
        return lines


def new_block_key(bits: int, motion: int | None) -> int:
    """A new block's template key among those of one spelling (`_Written.new_lines`): its
    written letters (`_BIT`), and above them its motion word's code + 1 (0: none)."""
    return bits if motion is None else bits | (motion + 1) << len(WRITTEN_LETTERS)


def _bits_written(facts: _Facts, segment: Line | Arc, places: tuple, known: set[str], last: tuple | None, last_places: tuple,
                  named: bool = True) -> int:  # fmt: skip
    """The letters the segment writes (a mask of `_BIT`): the axes its block has and whatever
    moved in the output (which is at `last`, written with `last_places`; `known`: the axes it
    has written), then an arc's centre; `places`: the decimals the segment is written with.
    Not `named`: of the axes its block has, only those that move (after a change of units or
    offsets, where the output's position is off the grid of the new numbers, a rounded number
    for an axis that stands would move it), unless none would be left: the block is a move the
    control makes (of no length), as the program's was."""
    bits, absent, end = facts.axis_bits, facts.absent_axes, segment.end
    if not named and last is not None and segment.context.absolute:
        named_bits = bits
        for n, axis in _NUMBERED_AXES:
            if bits & _BIT[axis] and not written_apart(end[n], places[n], last[n], last_places[n]):
                bits &= ~_BIT[axis]
        if named_bits & _ALL_AXES and not bits & _ALL_AXES:
            bits = named_bits
    if absent and segment.context.absolute:
        same_places = places == last_places
        for n, axis, bit in absent:
            # (`written_apart`'s first test first: most such axes are where the output left them)
            if axis in known and (
                last is None
                or not (same_places and end[n] == last[n])
                and written_apart(end[n], places[n], last[n], last_places[n])
            ):
                bits |= bit
    elif absent:
        start = segment.start
        for n, _axis, bit in absent:
            if round(end[n], places[n]) != round(start[n], places[n]):  # (the increment `_numbers` writes)
                bits |= bit
    if type(segment) is Arc:
        bits |= _CENTRE_BITS[segment.context.plane]
    return bits


def _new_block_text(words: dict[str, str], motion: int | None, spelled: tuple[str, bool]) -> str:
    """A new block of `words` (letter -> number text, or a format field), after `G<motion>` when it is set."""
    sep, lower = spelled
    text = sep.join(
        [letter + number for letter, number in words.items()]
        if motion is None
        else [f"G{motion}", *(letter + number for letter, number in words.items())]
    )
    return text.lower() if lower else text


class _Facts:
    """What the writer asks about a block."""

    __slots__ = ("letters", "motion_word", "motion", "first_motion", "moves", "plain", "words", "styled",
                 "word_letters", "motion_at", "bits", "axis_bits", "absent_axes", "machine", "flow", "settles",
                 "expression_axes", "local_call", "axis_letters")  # fmt: skip

    def __init__(self, block: Block | None = None):
        """The facts of `block`, read in one walk over its items (none: a block without words)."""
        self.letters: set[str] = set()  # letters of its plain words
        self.motion_word = False  # it has a motion G word (G0-G3, a canned cycle)
        self.motion: int | None = None  # the motion mode it sets (None: a canned cycle or none)
        self.first_motion: int | None = None  # the code of its first G0-G3 word (the one `_with_motion` sets)
        self.moves = False  # it has words that move with the modal motion
        self.plain = True  # only words and comments
        self.words = 0  # how many plain words it has
        self.styled: tuple[
            tuple[int, str], ...
        ] = ()  # (n, letter) of its n-th word when the writer learns its style
        self.word_letters: list[str] = []  # the letters of its plain words, in order
        self.motion_at: tuple[int, str] | None = (
            None  # (n, number as written) of its first G0-G3 word, the n-th word
        )
        self.machine = False  # it moves in machine coordinates (G53)
        self.flow = False  # a control line: an o-word (not `O<name>` alone, a program's name), M98, M99,
        # Haas's M97 P, a Fanuc GOTO, IF ... GOTO, WHILE or END
        self.local_call = False  # an M97, Haas's local call where the block has a P (`_sum_up`)
        self.settles = False  # its axis words are a G10 / G28 / G30 / G52 / G92 / G43.1's, not a move's
        self.expression_axes = ""  # the X Y Z words it writes as expressions (`Y[0]`, `Y#5`)
        for item in block.items if block is not None else ():
            kind = type(item)
            if kind is Word:
                word: Word = item  # type: ignore[assignment]  # (`kind` is its type: one type() per item)
                self._read_word(word.letter, word.value, word.number)
            elif kind is not Comment:
                self.plain = False
                if kind is ExprWord and item.letter in AXES:  # type: ignore[union-attr]  # (as above)
                    self.expression_axes += item.letter  # type: ignore[union-attr]
                if kind is Statement and (
                    (item.kind == "oword" and len(item.node) >= 2) or item.kind in _FANUC_CONTROL  # type: ignore[union-attr]
                ):
                    self.flow = True
        self._sum_up()

    @classmethod
    def of_signature(cls, signature: str) -> _Facts:
        """The facts of a plain block with this `Block.signature`."""
        facts = cls()
        for letter, number in _SIGNATURE_WORD.findall(signature):
            facts._read_word(letter, float(number) if number else 0.0, number)
        facts._sum_up()
        return facts

    def _sum_up(self) -> None:
        if self.local_call and "P" in self.letters:
            self.flow = True
        if self.settles:
            self.moves = False
        self.bits = sum(
            bit for letter, bit in _BIT.items() if letter in self.letters
        )  # the written letters it has
        self.axis_bits = self.bits & _AXIS_BITS
        self.axis_letters = self.letters & _XYZ  # the axes its plain words name
        self.absent_axes = tuple(
            (n, axis, _BIT[axis]) for n, axis in _NUMBERED_AXES if axis not in self.letters
        )

    def _read_word(self, letter: str, value: float, number: str) -> None:
        if letter == "M" and (value == 98.0 or value == 99.0):
            self.flow = True
        elif letter == "M" and value == 97.0:
            self.local_call = True
        self.letters.add(letter)
        self.word_letters.append(letter)
        if letter in STYLED_LETTERS:
            self.styled += ((self.words, letter),)
        self.words += 1
        if letter == "G":
            code = MOTION_CODES.get(value)
            if code is not None:
                self.motion_word, self.motion = True, code
                if self.first_motion is None:
                    self.first_motion, self.motion_at = code, (self.words - 1, number)
            elif 73 <= value <= 89 or value == 33.1:  # a canned cycle's, a rigid tap's
                self.motion_word, self.motion = True, None
            elif value == 53.0:
                self.machine = True
            elif value in AXES_NOT_MOVED:
                self.moves = self.settles = (
                    True  # (`_sum_up`: its axis words do not move with the modal motion)
                )
        elif letter in MOVING_LETTERS:
            self.moves = True


def _returns(move: Line | Arc) -> bool:
    """A rigid tap's return: the control's own move, no block writes it."""
    return type(move) is Line and move.tap == TAP_OUT


def _words(block: Block, facts: _Facts) -> tuple[Word, ...]:
    """The plain words of the block, in order."""
    items = block.items
    return items if len(items) == facts.words else tuple(item for item in items if type(item) is Word)  # type: ignore[return-value]


def _turns_plane(before: Context, after: Context) -> bool:
    """Whether a rotation of the coordinate system, before or after, turned or moved the plane it turns."""
    if before.rotation is None and after.rotation is None:
        return False
    if before.rotation != after.rotation or before.rotation_plane != after.rotation_plane:
        return True
    a, b, _ = PLANE_AXES[after.rotation_plane]
    return before.offset[a] != after.offset[a] or before.offset[b] != after.offset[b]


def reframed(before: Context, after: Context) -> bool:
    """Whether the program's numbers mean other machine positions after than before (units, offsets,
    the rotation of the coordinate system)."""
    return (
        before.inch != after.inch
        or before.offset != after.offset
        or before.rotation != after.rotation
        or before.rotation_plane != after.rotation_plane
        or before.mirror != after.mirror
    )


def as_written(segment: Line | Arc) -> Line | Arc:
    """The segment in the program's own frame: under a rotation of the coordinate system (LinuxCNC's
    G10 L2 R) or a mirror image (Fanuc's G51.1) the segments' points are turned as the control turns the
    program's (`Context.turned`), and the words written are those that the control, turning them, moves
    to the (corrected) points; an arc mirrored in one axis of its plane is written the other way round,
    as the control reverses it."""
    context = segment.context
    if not context.framed:
        return segment
    back = context.turned
    if type(segment) is Arc:
        return replace(
            segment,
            start=back(segment.start, -1.0),
            end=back(segment.end, -1.0),
            center=back(segment.center, -1.0),
            turn=-segment.turn if context.reverses else segment.turn,
        )
    return replace(segment, start=back(segment.start, -1.0), end=back(segment.end, -1.0))


def seen_from(last: tuple, places: tuple, before: Context, after: Context, after_places: tuple) -> tuple[tuple, tuple]:  # fmt: skip
    """The point the output wrote as `last` (with `places` decimals) in the frame `before`, as
    the control holds it in the frame `after`, with the decimal places to compare it with there."""
    written = (round(last[0], places[0]), round(last[1], places[1]), round(last[2], places[2]))
    machine = before.to_machine(before.turned(written))
    return after.turned(after.to_program(machine), -1.0), after_places


def written_apart(value: float, places: int, last: float, last_places: int) -> bool:
    """Whether `value` written with `places` decimals says another number than `last` written
    with `last_places` (compared as numbers first: most axes a block does not write are
    exactly where the output left them)."""
    if value == last and places == last_places:
        return False
    if places == last_places and places < len(_STEPS):
        # on the grid of the written decimals: away from a tie (a product's error is ~1e-16
        # of it), the nearest grid points are those `round` picks, at a fraction of its cost
        a, b = value * _STEPS[places], last * _STEPS[places]
        if -_EXACT < a < _EXACT and -_EXACT < b < _EXACT:
            na, nb = math.floor(a + 0.5), math.floor(b + 0.5)
            if abs(a - na) < _CLEAR and abs(b - nb) < _CLEAR:
                return na != nb
    return round(value, places) != round(last, last_places)


_STEPS = tuple(10.0**k for k in range(10))  # grid points per unit, by decimal places
_EXACT = 2.0**40  # scaled values this small: their product's error is < 2**-12 of a grid step
_CLEAR = 0.5 - 2.0**-10  # how far from a grid point a scaled value may be: clear of the ties


class _Written:
    """How the output writes numbers in one system of units: the style of each letter
    it writes, and the decimal places of X, Y and Z."""

    __slots__ = ("styles", "places", "plain", "edit_plans", "edits", "new_lines")

    def __init__(self, styles: dict[str, NumberStyle]):
        self.styles = styles
        self.places: tuple[int, int, int] = tuple(styles[axis].decimals for axis in AXES)  # type: ignore[assignment]
        self.plain = all(
            style.plain for style in styles.values()
        )  # every number one `format` spec: plans apply
        # Compiled lines: (signature, written bits, motion, spelling) -> `EditPlan` (None: none applies),
        # (layout, signature, ...) -> that plan, or the format template it makes of such blocks,
        # and per spelling (a dialect's: (spelling, line end) here) {`new_block_key`: the format
        # template of a new block}.
        self.edit_plans: dict[tuple, EditPlan | None] = {}
        self.edits: dict[tuple, EditPlan | str] = {}
        self.new_lines: dict[tuple, dict[int, str]] = {}

    def fields(self, bits: int) -> dict[str, str]:
        """The written letters of the mask, each with its number as a field of `IsoWriter._numbers`."""
        return {letter: f"{{{n}:{self.styles[letter].spec}}}" for letter, n in _WRITTEN[bits]}


class _Units:
    """Stands in for a segment where only its units matter (style look-ups)."""

    def __init__(self, inch: bool):
        self.context = Context(inch=inch)


_MM, _INCH = _Units(False), _Units(True)


# A canned cycle's own words, which its moves written as G0/G1 blocks replace (`IsoWriter._expanded`)
_CYCLE_LETTERS = frozenset("XYZABCUVWRQLPIJK@^")


def _cycle_rest(block: Block, separator: str) -> str:
    """The block's text without its canned-cycle words (the cycle's G code, the hole's words):
    its other words and comments, as written ("" when none is left but a block number)."""
    raw, kept = block.raw, []
    for item in block.items:
        if type(item) is Word and item.letter.upper() == "G" and item.value in CANNED:
            continue
        if (type(item) is Word or type(item) is ExprWord) and item.letter.upper() in _CYCLE_LETTERS:
            continue
        kept.append(raw[item.start : item.end])
    if all(text[:1] in "Nn" for text in kept):
        return ""
    return separator.join(kept)


def _literal_geometry(block: Block, letters: str = GEOMETRY_LETTERS) -> Block:
    """The block with expression-valued geometry words (`Z[-#<depth>]`), or those of other
    `letters`, as plain words: a pass changed what they evaluate to, so new numbers replace them."""
    if not any(type(i) is ExprWord and i.letter in letters for i in block.items):
        return block
    items = tuple(
        Word(i.letter, 0.0, "0", i.start, i.end) if type(i) is ExprWord and i.letter in letters else i
        for i in block.items
    )
    return replace(block, items=items, signature=None)  # the signature is that of the old items


def _program_shift(setting: Setting) -> tuple[float, float, float]:
    """A setting's shift (`Setting.shift`, in the frame of the segments) as the program's words take
    it: turned back under a rotation of the coordinate system (`Context.turned`)."""
    shift = setting.shift
    assert shift is not None
    if not setting.context.framed:
        return shift
    at = setting.position
    back = setting.context.turned((at[0] + shift[0], at[1] + shift[1], at[2] + shift[2]), -1.0)
    here = setting.context.turned(at, -1.0)
    return (back[0] - here[0], back[1] - here[1], back[2] - here[2])
