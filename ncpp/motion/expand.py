"""`--expand`: an ISO program's loops and subroutines written out as straight code.

The flow (`flow.py`) runs the bodies of loops and subroutines block by block, out of the text's
order; without --expand their moves are left as programmed (FLOW).  With it every block a body
runs is written where it runs, as a block of its own for that run: its expressions written as
the numbers they have there (`literal`), so the moves are plain moves that compensation
corrects like any other, and its other words (M codes, tools, dwells, spindle) act once per run,
in the order they run.  The control lines (`o100 call`, `while`, `endwhile`, `if`, `M97`, `M98`, `M99`,
`WHILE`, `END`, `GOTO` ...) and the text that does not run (untaken branches, loops that run no
time) are left out.  Subroutine definitions stay, as the control skips them: a line out of the
interpreter's scope in the main program, outside any loop or branch, passes the rest of the
program through as it is, as without --expand, and the calls there find their subroutines.  The
text after the program's end stays as it is too.

A body's parameter assignments are not written: its blocks read no parameter once written as
numbers.  The lines of the main program that are written as they are may read them, so before
the first of those after an expanded stretch the parameters whose values the stretch changed
are set to the values they have there (`settled`): the program's own parameters, as its main
level sees them.  LinuxCNC's `#<_value>` and `#<_value_returned>` are read-only: a main-program
line that reads one is written with numbers too.

A construct outside the interpreter's scope inside a loop, a branch or a subroutine (once
something was expanded) is refused: the rest could not pass through as it is, its loop or
branch has lost its opening line.  So is a program whose loops and subroutines make more than
MAX_EXPANDED blocks.
"""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np

from ncpp.errors import Location, NcppError
from ncpp.motion.expressions import ExpressionError, OutOfScope, Parameters, evaluate, normalise_name, vacant
from ncpp.motion.flow import RUN, SKIP, TEXT, Control, Flow, control_of
from ncpp.motion.segments import Event, Pass
from ncpp.program.blocks import AnyItem, Block, Comment, ExprWord, Statement, Word

# Blocks that loops and subroutines may be written out in at most: each is a line of the output
# (or a few, for an arc written in pieces); past it the program is refused, not written for hours
MAX_EXPANDED = 1_000_000
# Letters whose values are whole numbers where they are (codes, tools, numbers, counts): written
# without a decimal point; every other letter's number has one (a Fanuc `X10` is 10 µm, not mm)
WHOLE_LETTERS = frozenset("GMTNOHDLPS")
# Positions (axes, arc centres and radii): written to PLACES decimals, far finer than any control
# moves (1e-6 mm, or inch), not the 17 digits of a double that a control may refuse; the moves
# compensation changes are written in the program's own style (the writer's)
POSITION_LETTERS = frozenset("XYZABCUVWIJKR")
PLACES = 6
# Parameters a program may not set (LinuxCNC: read-only), what the last subroutine returned
RETURNED = frozenset(("_value", "_value_returned"))
FANUC_STOP = 3006  # Fanuc's stop-with-message variable: its assignment is an action, kept
# Fanuc's alarm and stop-with-message variables: setting one is an action (the control stops), never
# a value to give the written program
ACTIONS = frozenset((3000, FANUC_STOP))
# LinuxCNC's comments that show parameters' values where they run, and the parameters they name
_SHOWING = re.compile(r"\s*(debug|print|log)\s*,", re.IGNORECASE)
_PARAMETER = re.compile(r"#(\d+|<[^>]*>)")
Running = Callable[[Block], Event | tuple[Event, ...]]  # the interpreter's reading of one block


class Expansion:
    """What --expand does to one run of a program (the interpreter asks it at each block)."""

    def __init__(self, params: Parameters, file: str):
        self.params = params
        self.file = file
        self.started = False  # something was expanded or left out: the rest cannot pass through as text
        self.expanded = 0  # blocks written out of loops and subroutines
        self.settled = True  # the written program's parameters are the program's (at the main level)
        # The written program's parameters where they were last the program's: numbered, named, vacant
        self.written: tuple[dict, dict, frozenset] = ({}, {}, frozenset())
        self.unknown: dict[int | str, str] = {}  # the parameters of unknown value when `written` was taken
        self.defining: str | None = None  # the subroutine whose definition's lines go by (kept)
        self.branches = 0  # if chains of the main program whose `if` was left out and `endif` not yet
        self._owed: tuple[Pass, ...] = ()  # assignments due before a line that failed to run (`owed`)

    def text(self, kind: str, done: bool, block: Block) -> tuple[Pass, ...] | None:
        """A line the flow does not run here: None where it is left out (text that does not run,
        SKIP, but a subroutine's definition, and a control line, TEXT, before the program's end),
        else the assignments to write before it: after the program's end or where it passes
        through uninterpreted, the parameters its text may read (`_settle`)."""
        if done:
            return self._settle(block)
        control = control_of(block) if block.signature is None else None  # (no plain block is one)
        if kind is SKIP and self._defines(control):
            return ()
        if kind is TEXT and control is not None:
            self.branches += (control.keyword == "if") - (control.keyword == "endif")
        self._unsettle()
        return None

    def owed(self) -> tuple[Pass, ...]:
        """The assignments due before a main-program line the interpreter could not read, which
        passes through as it is (and the rest with it)."""
        owed, self._owed = self._owed, ()
        return owed

    def _defines(self, control: Control | None) -> bool:
        """Whether a line that does not run is one of a subroutine's definition (`sub` to `endsub`)."""
        keyword, name = (control.keyword, control.name) if control is not None else ("", None)
        if self.defining is None and keyword == "sub":
            self.defining = str(name)
        elif self.defining is not None and keyword == "endsub" and name == self.defining:
            self.defining = None
            return True
        return self.defining is not None

    def refuses_leaving(self, flow: Flow) -> bool:
        """Whether the rest of the program cannot pass through as it is from here: a loop, a branch
        or a call is under way whose opening line was left out."""
        main = flow.frames[0]
        return self.started and (len(flow.frames) > 1 or bool(main.labels) or self.branches > 0
                                 or flow.skipping is not None or main.pc in flow.looped)  # fmt: skip

    def event(
        self, run: Running, block: Block, kind: str, local: bool = False
    ) -> tuple[Event | tuple[Event, ...], Block]:
        """The events of a block the flow runs, run by `run` (the interpreter's), and the block they
        are written as: a main-program line as it is (after the assignments that settle the
        parameters it may read), a body's line as the numbers of this run (`literal`).  A line of a
        Haas local subprogram (`local`) is written without its sequence number: an M97 left in the
        program (where the rest passes through) is to find its subprogram's Nn, not a copy of it."""
        if kind is RUN and not _reads_returned(block):
            settling = self._settle(block)
            try:
                events = run(block)
            except Exception:
                self._owed = settling  # (its text passes through: after them, `owed`)
                raise
            return ((*settling, *_each(events)) if settling else events), block
        self._unsettle()
        if kind is not RUN:
            self._count(block)
        written = literal(block, self.params, unnumbered=local)
        events = run(block)  # (an expression `literal` cannot evaluate fails here, as without --expand)
        if written is None:
            raise NcppError(
                "--expand: the line cannot be written with numbers", Location(self.file, block.line, 1)
            )
        each = _each(events)
        if not written.items and all(type(ev) is Pass for ev in each):  # (assignments only: nothing to write)
            return (), written
        for ev in each:
            ev.block = written
        return events, written

    def _count(self, block: Block) -> None:
        """One more block written out of a loop or a subroutine: refused past MAX_EXPANDED."""
        self.expanded = counted(self.expanded, Location(self.file, block.line, 1))

    def _unsettle(self) -> None:
        """A stretch written out starts (or goes on): the parameters the written program has are
        the program's now, before any of its blocks runs, until the next main-program line."""
        if self.settled:
            self.written = self._snapshot()
            self.unknown = dict(self.params.unknown)
            self.settled = False
        self.started = True

    def _snapshot(self) -> tuple[dict, dict, frozenset]:
        """The parameters the main program has now (a macro G66 calls may be under way)."""
        numbered, named, vacant_now = self.params.main_level()
        return numbered, {k: v for k, v in named.items() if k not in RETURNED}, vacant_now

    def _settle(self, block: Block) -> tuple[Pass, ...]:
        """Assignments that give the written program the parameters the program has before `block`
        (none when nothing was expanded since they were the same)."""
        if self.settled:
            return ()
        self.settled = True
        numbered, named, vacant_now = self._snapshot()
        was, was_named, was_vacant = self.written
        lines = []
        for key in self.params.unknown.keys() - ACTIONS:
            self._known(key, block)
        for key in sorted((numbered.keys() | was.keys()) - ACTIONS):
            if key in vacant_now:
                if key not in was_vacant:
                    lines.append(f"#{key}=#0")
            elif key in was_vacant or was.get(key, 0.0) != numbered.get(key, 0.0):
                lines.append(f"#{key}={number('#', numbered.get(key, 0.0))}")
        for name, value in named.items():
            if was_named.get(name) != value:
                lines.append(f"#<{name}>={number('#', value)}")
        return tuple(Pass(_assignment(text, block)) for text in lines)

    def _known(self, key: int | str, block: Block) -> None:
        """Refuse a parameter the stretch written out set to a value ncpp cannot know
        (`Parameters.set_unknown`): its assignment is left out, and the written program cannot give it
        that value as a number (one set so before the stretch keeps its own assignment)."""
        whence = self.params.unknown[key]
        if self.unknown.get(key) != whence:
            raise refused(whence, Location(self.file, block.line, 1))


def counted(expanded: int, where: Location) -> int:
    """`expanded` blocks written out of loops and subroutines and one more (at `where`): refused
    past MAX_EXPANDED."""
    if expanded >= MAX_EXPANDED:
        raise NcppError(
            f"--expand: the loops and subroutines make more than {MAX_EXPANDED:,} blocks written out; "
            "leave --expand out (their moves then pass through uncompensated)",
            where,
        )
    return expanded + 1


def refused(reason: str, where: Location) -> NcppError:
    """The error for a construct out of scope where the rest of the program cannot pass through as
    it is: inside a loop, a branch or a subroutine written out (its opening line is left out)."""
    return NcppError(f"--expand: {reason} is outside the motion interpreter's scope, inside a loop, "
                     "a branch or a subroutine written out: the rest cannot pass through as it is", where)  # fmt: skip


def _each(events: Event | tuple[Event, ...]) -> tuple[Event, ...]:
    return events if type(events) is tuple else (events,)  # type: ignore[return-value]


def literal(block: Block, params: Parameters, unnumbered: bool = False) -> Block | None:
    """The block as it runs now: each expression word as its value's number (a vacant one left
    out), its parameter assignments left out (but Fanuc's stop with a message), its N word too where
    `unnumbered`, the rest as written.  None where an expression cannot be evaluated (the
    interpreter then says why)."""
    try:
        texts = [None if unnumbered and type(item) is Word and item.letter == "N" else _text(item, block.raw, params)
                 for item in block.items]  # fmt: skip
    except (ExpressionError, OutOfScope):
        return None
    written = rewritten(block, texts)
    return _unindented(written) if unnumbered and texts and texts[0] is None else written


def _unindented(block: Block) -> Block:
    """The block without the blanks its text now starts with (those after a leading word left out)."""
    raw = block.raw
    cut = len(raw) - len(raw.lstrip(" \t"))
    if cut == 0:
        return block
    items = tuple(_placed(item, raw[item.start : item.end], item.start - cut) for item in block.items)
    return Block(raw[cut:], block.eol, items, block.line)


def rewritten(block: Block, texts: list[str | None]) -> Block:
    """The block with each item's text replaced by `texts`' (None: left out), the text between
    them as it was; an expression word written as a number becomes a plain word."""
    raw = block.raw
    pieces: list[str] = []
    items: list[AnyItem] = []
    at = last = 0  # where the new text and the old one are
    for item, text in zip(block.items, texts):
        gap = raw[last : item.start]
        last = item.end
        if text is None:
            continue
        pieces += (gap, text)
        at += len(gap)
        items.append(_placed(item, text, at))
        at += len(text)
    pieces.append(raw[last:])
    written = "".join(pieces)
    return Block(written if items else written.rstrip(), block.eol, tuple(items), block.line)


def _text(item: AnyItem, raw: str, params: Parameters) -> str | None:
    """An item's text in the block of this run (None: left out)."""
    if isinstance(item, ExprWord):
        if vacant(item.expr, params):
            return None
        return item.letter + number(item.letter, evaluate(item.expr, params))
    if isinstance(item, Statement) and item.kind in ("assignment", "if") and not _stops(item):
        return None
    if isinstance(item, Comment) and _SHOWING.match(item.text):
        return _PARAMETER.sub(lambda found: _shown(found, params), raw[item.start : item.end])
    return raw[item.start : item.end]


def _shown(found: re.Match, params: Parameters) -> str:
    """A parameter a DEBUG, PRINT or LOG comment shows, as LinuxCNC shows it there (`%lf`)."""
    name = found.group(1)
    try:
        return f"{params.read(normalise_name(name) if name.startswith('<') else int(name)):.6f}"
    except (ExpressionError, OutOfScope):
        return found.group(0)


def number(letter: str, value: float) -> str:
    """`value` as the program is to read it: the shortest digits that read back as it (a position's
    to PLACES decimals), a decimal point on every letter's but whole codes' (`WHOLE_LETTERS`), no
    exponent."""
    upper = letter.upper()
    if upper in WHOLE_LETTERS and value == int(value):
        return str(int(value))
    places = PLACES if upper in POSITION_LETTERS else None
    return np.format_float_positional(
        value, precision=places, unique=True, trim="-" if letter == "#" else "."
    )


def _placed(item: AnyItem, text: str, at: int) -> AnyItem:
    """`item` as `text` at `at` in the new text (an expression word as a plain word)."""
    end = at + len(text)
    if isinstance(item, ExprWord):
        digits = text[len(item.letter) :]
        return Word(item.letter, float(digits), digits, at, end)
    if isinstance(item, Word):
        return Word(item.letter, item.value, item.number, at, end)
    if isinstance(item, Comment):
        return Comment(item.text, item.style, at, end)
    return Statement(item.kind, item.node, at, end)


def _stops(statement: Statement) -> bool:
    """Fanuc's `#3006 = n (MESSAGE)`: the control stops there (an action of each run)."""
    return statement.kind == "assignment" and statement.node[0][1] == FANUC_STOP


def _reads_returned(block: Block) -> bool:
    """Whether the block reads what a subroutine returned (`#<_value>`), which the written program
    cannot set: the block is written with numbers."""
    if block.signature is not None:  # (plain words: no parameter)
        return False
    return any(
        _names_returned(item.expr if isinstance(item, ExprWord) else item.node)
        for item in block.items
        if isinstance(item, (ExprWord, Statement))
    )


def _names_returned(node: object) -> bool:
    if type(node) is tuple:
        if len(node) == 2 and node[0] == "param" and type(node[1]) is str:
            return normalise_name(node[1]) in RETURNED
        return any(_names_returned(part) for part in node)
    return False


def _assignment(text: str, block: Block) -> Block:
    """A line `#k=v` that sets a parameter, written before `block` (its line's number and end)."""
    return Block(text, block.eol, (Statement("assignment", (), 0, len(text)),), block.line)
