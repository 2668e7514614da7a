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

Whether a construct sets such an offset is known only once a run of it does, so the interpreter
marks where a construct entered from straight code starts (`entered`), where straight code comes
back (`STRAIGHT`), and where interpretation ends in it (`left_at`: at such a setting, at anything
else out of scope, after which the construct may set one, or at a call ncpp cannot follow);
`stepped_back` holds the events from a head to the straight code after it (bounded), and gives the
held construct its step (a `Pass` whose `Setting` sets no value: `Setting.values` empty) where
interpretation ends in it.  Where a setting has no step (its construct's head is already written,
an action stands before the head, the construct was entered from another one), it warns."""

from __future__ import annotations

from collections.abc import Callable, Generator, Iterable, Iterator

from ncpp.errors import Location
from ncpp.motion.segments import Event, Pass
from ncpp.program.actions import actions_of

# Blocks without motion between the last move and a construct's head looked through for an action
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
    "last move and it, and a step after that would move where the original stands still"
)


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


def stepped_back(items: Iterable, warn: Callable[[str, Location], None]) -> Iterator[Event | tuple]:
    """The items without the marks, a construct's step back before its head where a setting in it
    ends interpretation (see the module docstring)."""
    items = iter(items)
    unheld = ""  # why the construct under way is not held ("": none is, or it is)
    since: list[Pass] = []  # the blocks that do not move since the last move (`_acts`)
    for item in items:
        kind = type(item)
        if kind is Pass:
            if len(since) <= MAX_SINCE:
                since.append(item)
            yield item
        elif kind is not Mark:
            since.clear()
            yield item
        elif item.step is not None:
            unheld = yield from _held(items, item.step, since, warn)
        elif item.where is not None:
            if item.setting:
                warn(NO_STEP.format(why=unheld or "it does not start in straight code"), item.where)
        else:
            unheld = ""


def _held(
    items: Iterator, step: Pass, since: list[Pass], warn: Callable[[str, Location], None]
) -> Generator[Event | tuple, None, str]:
    """A construct's events from its head (the mark that starts it went by): held until straight code
    comes back, given `step` first where a setting in it ends interpretation, but for an action
    between the last move and the head (`_acts`).  Returns why a setting in it is not stepped back
    to ("": it is, or it ended).  `since` goes on as `stepped_back`'s."""
    acted = _acts(since)
    held: list = []
    for item in items:
        kind = type(item)
        if kind is not Mark:
            if kind is Pass and len(since) <= MAX_SINCE:
                since.append(item)
            elif kind is not Pass:
                since.clear()
            held.append(item)
            if len(held) > MAX_HELD:
                yield from held
                return f"its head was written before, {MAX_HELD:,} events ahead"
            continue
        if item.where is not None:
            if acted:
                yield from held
                if item.setting:
                    warn(NO_STEP.format(why=ACTED), item.where)
                return ""
            yield step
        yield from held
        return ""  # (a construct does not start inside another: `Interpreter._enters`)
    yield from held
    return ""


def _acts(since: list[Pass]) -> bool:
    """Whether an action stands among the blocks since the last move (an M function, a tool, spindle
    speed or offset number, a dwell, a tool length: `actions_of`): a step after it would
    move where the original stands still, which the verifier, comparing the motion between two
    actions, refuses.  Past MAX_SINCE blocks, taken to."""
    if len(since) > MAX_SINCE:
        return True
    return any(any(actions_of(event.block)) for event in since if not event.skipped)
