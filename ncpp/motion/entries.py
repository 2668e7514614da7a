"""A step back to the programmed point before a loop or subroutine that sets an offset from where the
control stands.

A G92 or G10 L10/L11/L20 in text that runs more than once, or away from where it stands, ends
interpretation (`Interpreter._in_flow`): each run would set its offset from another point.  The
control reaches such a construct standing where the last compensated move put it, off the
programmed point by that move's correction, and the construct runs as programmed from there: the
offset the block sets would carry the correction, and so would every move after it.  Written right
before the construct's first line (its head: the `o100 while`, the call, the first line a backward
GOTO runs again), a step back to the programmed point puts the control where the program means, and
the construct then runs as the original does (a step inside it would run again with each pass).

Where an action stands between the last move and the head (an M function, a tool, spindle speed or
offset number, a dwell, a tool length change: `_acts`), a step after it would move where the
original stands still: the step comes right after the move instead, in that move's frame (its units,
offsets and tool length: a G43 or tool change among the blocks applies after it), so the control
stands at the programmed point through the actions and into the construct, as the original's does.

Whether a construct sets such an offset is known only once a run of it does, so the interpreter
marks where a construct entered from straight code starts (`entered`), where straight code comes
back (`STRAIGHT`), and where interpretation ends in it (`left_at`: at such a setting, at anything
else out of scope, after which the construct may set one, or at a call ncpp cannot follow);
`stepped_back` holds the blocks without motion since the last move (`_Since`, bounded) and the
events from a head to the straight code after it (bounded), and gives the held construct its step
(a `Pass` whose `Setting` sets no value: `Setting.values` empty) where interpretation ends in it.
Where a setting has no step (its construct's head is already written, the blocks since the last
move are not all held or hold a setting of their own, the construct comes in an arc or cycle mode
after an action, it was entered from another construct), it warns."""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterable, Iterator

from ncpp.errors import Location
from ncpp.motion.segments import Arc, Event, Line, Pass, Setting
from ncpp.program.actions import actions_of

# Blocks without motion between the last move and a construct's head held and looked through for an action
MAX_SINCE = 1_000
# Events held from a construct's head until straight code comes back: past them the head is written
# (memory stays bounded) and a setting in the construct gets a warning instead of its step
MAX_HELD = 10_000

NO_STEP = (
    "a G92 or G10 L10/L11/L20 in a loop or subroutine ends interpretation, and ncpp cannot write a step "
    "back to the programmed point before the construct that runs it ({why}): the control reaches it where the "
    "last compensated move left it, so the offset it sets, and every move after it, may carry that move's "
    "correction; put the tool at a programmed point with a move that names each axis the block sets before the "
    "loop or call, or compensate with --expand"
)
ACTED = (
    "an M function, a tool, spindle speed or offset number, a dwell or a tool length change stands between the "
    "last move and it (a step after that would move where the original stands still), and a step before that "
)
# Why no step back comes right after the last move, where an action stands since it (`_unmovable`)
UNSTRAIGHT = ACTED + "would come before other code than blocks run in their place (a loop's, a call's)"
SETTING = (
    ACTED + "would come before a G92 or G10 L10/L11/L20 that sets its offset from where the control stands"
)
MODE = ACTED + "would change the arc's or canned cycle's mode the construct comes in"
FAR = "more than {:,} blocks without motion stand between the last move and it"


class Mark:
    """A mark in the interpreter's events: where a construct entered from straight code starts
    (`entered`: its step back, before the next event), where straight code comes back (`STRAIGHT`),
    and where a setting in a construct ended interpretation (`left_at`: the place warned at)."""

    __slots__ = ("step", "where", "setting")

    def __init__(self, step: Pass | None = None, where: Location | None = None, setting: bool = False):
        self.step, self.where, self.setting = step, where, setting


STRAIGHT = Mark()


def entered(step: Pass) -> Mark:
    return Mark(step=step)


def left_at(where: Location, setting: bool = False) -> Mark:
    """Interpretation ended at `where` in the construct under way; `setting`: at a block that sets an
    offset from where the control stands (warned of where no step back has a place)."""
    return Mark(where=where, setting=setting)


class _Since:
    """The blocks that do not move since the last move (`_acts`: up to MAX_SINCE of them), held while
    a step back may yet come before them, right after the move (`moved`)."""

    __slots__ = ("moved", "passes", "held")

    def __init__(self) -> None:
        self.moved: Line | Arc | None = None  # the last move, while every block since it is held
        self.passes: list[Pass] = []
        self.held: list[Pass] = []

    def move(self, item: object) -> list[Pass]:
        """A move, or another event (a called run's): the blocks held before it, to pass on first."""
        held, self.held, self.passes = self.held, [], []
        kind = type(item)
        self.moved = item if kind is Line or kind is Arc else None  # type: ignore[assignment]
        return held

    def add(self, item: Pass) -> list[Pass]:
        """A block that does not move, in straight code: the blocks to pass on now (none while held)."""
        passes = self.passes
        if len(passes) > MAX_SINCE:
            return [item]
        passes.append(item)
        if self.moved is None:
            return [item]
        self.held.append(item)
        return self.take() if len(passes) > MAX_SINCE else []  # (held no further: memory stays bounded)

    def count(self, item: Pass) -> None:
        """A block that does not move, inside a construct (passed on with it)."""
        if len(self.passes) <= MAX_SINCE:
            self.passes.append(item)

    def take(self) -> list[Pass]:
        """The blocks held, passed on from here: no step comes before them any more."""
        held, self.held, self.moved = self.held, [], None
        return held


def stepped_back(items: Iterable, warn: Callable[[str, Location], None]) -> Iterator[Event | tuple]:
    """The items without the marks, a construct's step back where a setting in it ends interpretation
    (see the module docstring)."""
    items = iter(items)
    unheld = ""  # why the construct under way is not held ("": none is, or it is)
    since = _Since()
    for item in items:
        kind = type(item)
        if kind is Pass:
            yield from since.add(item)
        elif kind is not Mark:
            yield from since.move(item)
            yield item
        elif item.step is not None:
            unheld = yield from _held(items, item.step, since, warn)
        elif item.where is not None:
            if item.setting:
                warn(NO_STEP.format(why=unheld or "it does not start in straight code"), item.where)
        else:
            unheld = ""
    yield from since.take()


def _held(
    items: Iterator, step: Pass, since: _Since, warn: Callable[[str, Location], None]
) -> Generator[Event | tuple, None, str]:
    """A construct's events from its head (the mark that starts it went by): held until straight code
    comes back, given its step back where a setting in it ends interpretation (`_unmovable`).  Returns
    why a setting in it is not stepped back to ("": it is, or it ended).  `since` goes on as
    `stepped_back`'s."""
    # where the step goes: None right before the head (no action since the last move), "" right after
    # that move, else why it has none
    why = _unmovable(step, since) if _acts(since.passes) else None
    last, before = since.moved, since.take()  # (the blocks since the last move: a step may come before them)
    held: list = []
    for item in items:
        kind = type(item)
        if kind is not Mark:
            if kind is Pass:
                since.count(item)
            else:
                since.passes.clear()
            held.append(item)
            if len(held) > MAX_HELD:
                yield from before
                yield from held
                return f"its head was written before, {MAX_HELD:,} events ahead"
            continue
        if item.where is None:
            yield from before
        elif why is None:
            yield from before
            yield step
        elif why:
            yield from before
            if item.setting:
                warn(NO_STEP.format(why=why), item.where)
        else:
            yield from _after_move(step, last, before)  # type: ignore[arg-type]  # (`_unmovable`: there is one)
        yield from held
        return ""  # (a construct does not start inside another: `Interpreter._enters`)
    yield from before
    yield from held
    return ""


def _after_move(step: Pass, last: Line | Arc, before: list[Pass]) -> list[Pass]:
    """The blocks since the last move, the construct's step back right before the first that runs
    (as the rest, an action: `_acts`), in the move's frame; it is written as a new block before that
    block's text (the writer writes a step ahead of its block's, `IsoWriter._write_group`)."""
    first = next(n for n, event in enumerate(before) if not event.skipped)
    at = Setting((), last.context, last.end, leaves=True)
    return [*before[:first], Pass(before[first].block, motion=step.motion, setting=at), *before[first:]]


def _unmovable(step: Pass, since: _Since) -> str:
    """Where an action stands among the blocks since the last move, why the construct's step back
    cannot come right after that move ("": it can).  There it is the control's move in the move's
    frame (units, offsets, tool length: before a G43 or tool change among the blocks), and the
    control stands at the programmed point through the blocks and into the construct, as the
    original's does."""
    if len(since.passes) > MAX_SINCE:
        return FAR.format(MAX_SINCE)
    if since.moved is None or not since.held:
        return UNSTRAIGHT
    if any(event.setting is not None for event in since.held):
        return SETTING
    if step.motion != 0.0 and step.motion != 1.0:  # (a step would set G0 or G1 for the construct)
        return MODE
    return ""


def _acts(since: list[Pass]) -> bool:
    """Whether an action stands among the blocks since the last move (an M function, a tool, spindle
    speed or offset number, a dwell, a tool length: `actions_of`): a step after it would
    move where the original stands still, which the verifier, comparing the motion between two
    actions, refuses.  Past MAX_SINCE blocks, taken to."""
    if len(since) > MAX_SINCE:
        return True
    return any(any(actions_of(event.block)) for event in since if not event.skipped)
