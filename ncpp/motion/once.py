"""A loop's first pass in its place, held until the flow tells whether its text runs again.

The flows (`flow.py`, `sinumerik_flow.py`) yield the blocks of a loop's first pass where they
stand as ONCE: whether the loop goes back is told only later, by the next block the flow
yields.  A body whose text runs once can carry that run's corrections (it is written in place,
as a RUN block's); one that runs again cannot (FIXED).  The interpreters hold the pass's events
here until then: the flow back in straight code tells "once", a block of the pass run again
(an inner loop's second pass) marks the events from that block's first on, and leaving the
interpreter's scope tells "again".  The held pass is bounded (MAX_ONCE events: memory).

A subprogram's run that may be its only one (a flow's CALLED: ISO's `flow.py`, Klartext's
`heidenhain_flow.py`) is held the same way, with all the events after it, until the program ends
(`held_to_the_end`): only there is it known that no other call ran its text.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field

from ncpp.motion.segments import Event
from ncpp.program.blocks import Block

# Events of a loop's first pass held until the flow tells whether its text runs again: a longer
# pass is left as programmed (memory stays bounded)
MAX_ONCE = 10_000


@dataclass
class OnceRuns:
    """The subroutines whose one run a reading finds, to be written where their definition stands
    (`Interpreter.run`): their names and the ids of their blocks (which the writer places).  A
    reading of a written program looks only for those the input's reading found (`only`), whose
    runs it holds to `held_most` events (the written lines of a run are more than the input's).

    A definition the flow meets before its call (`Flow._wait_for_call`) waits (`waiting`): the
    writer holds the lines written from its text on (`ahead`: the ids of its lines) until its run
    is told, to write the run there, or it is told to stay as programmed (`programmed`: called
    again or never, or the events from the first definition waiting passed `held_most`)."""

    blocks: set[int] = field(default_factory=set)
    names: set[str] = field(default_factory=set)
    only: set[str] | None = None
    held_most: int = field(default_factory=lambda: MAX_ONCE)
    ahead: dict[int, str] = field(default_factory=dict)  # id of a line of a waiting definition -> its name
    waiting: set[str] = field(default_factory=set)
    programmed: set[str] = field(default_factory=set)

    def may_run_once(self, name: str) -> bool:
        return (self.only is None or name in self.only) and name not in self.programmed

    def meet(self, name: str, lines: list[Block]) -> None:
        """A definition met before any call of it, `sub` to `endsub`: it waits for its run."""
        self.ahead.update((id(line), name) for line in lines)
        self.waiting.add(name)

    def ran_once(self, name: str, block: Block) -> None:
        """`block` ran in the one run of `name`: written where the definition stands."""
        self.names.add(name)
        self.blocks.add(id(block))
        self.waiting.discard(name)

    def refuse(self, name: str) -> None:
        """`name` stays as programmed (its run, if any, is told so: a FIXED one's)."""
        if name not in self.names:
            self.programmed.add(name)
            self.waiting.discard(name)

    def refuse_waiting(self) -> set[str]:
        """All definitions waiting stay as programmed: those refused."""
        refused, self.waiting = self.waiting, set()
        self.programmed |= refused
        return refused


class FirstPass:
    """The events of a loop's first pass in its place, each marked where it is known to run
    again: a block run in place as part of a loop (FIXED), and, when a block of the pass runs
    again, the events from that block's first on (the runs again come after them).  `as_programmed`
    is the dialect's mark of an event whose text runs again (None: the event is not written)."""

    def __init__(self, as_programmed: Callable[[Event], Event | None]) -> None:
        self.as_programmed = as_programmed
        self.events: list[Event] = []
        self.again: list[bool] = []  # the event's text runs again
        self.first: dict[int, int] = {}  # the id of a block run once so far -> its first event's index
        self.again_from = 0  # the events from this index on all run again

    def add(self, event: Event, block: Block, again: bool) -> None:
        if not again:
            self.first.setdefault(id(block), len(self.events))
            self.again_from = len(self.events) + 1
        self.events.append(event)
        self.again.append(again)

    def rerun(self, block: Block) -> bool:
        """`block` runs again: its text, and that of the blocks after it, runs more than once.
        Whether all of the pass does."""
        start = self.first.pop(id(block), None)
        if start is not None and start < self.again_from:
            self.again[start : self.again_from] = [True] * (self.again_from - start)
            self.again_from = start
        return self.again_from == 0

    def full(self) -> bool:
        return len(self.events) > MAX_ONCE

    def told(self, again: bool) -> list[Event]:
        """The events, all left as programmed if the pass runs again, else those marked so."""
        marked = (
            self.as_programmed(ev) if again or twice else ev for ev, twice in zip(self.events, self.again)
        )
        return [ev for ev in marked if ev is not None]


Run = tuple[str, Block]  # a CALLED run's subprogram and the line that called it


def held_to_the_end(
    items: Iterable[Event | tuple[Run, Event]],
    runs: OnceRuns,
    state: Callable[[], tuple[bool, bool]],
    again: Callable[[], list[str]],
    as_programmed: Callable[[Event, Block], Event | None],
) -> Iterator[Event]:
    """An interpreter's events, a CALLED run's as (its `Run`, event), with each such run and the
    events after it held until the program ends (`state()`: (done, ended)): if no other call ran
    the subprogram (`again()`: the names the flow found run again, emptied as read), its text ran
    once and is written for that run where its definition stands (`OnceRuns.ran_once`); else, or
    where the program leaves the interpreter's scope or the events held pass `runs.held_most`, its
    moves are left as programmed (`as_programmed(event, call)`, `OnceRuns.refuse`).  A definition
    met before its call waits (`OnceRuns.waiting`: the writer holds its lines): it stays as
    programmed too where the events from the first one waiting pass `held_most` (the lines the
    writer holds are bounded)."""
    held: list[tuple[Event, Run | None]] = []
    pending: set[str] = set()  # the CALLED subprograms among the events held
    rerun: set[str] = set()
    programmed: set[str] = set()  # those told to stay as programmed (the rest of a run too)
    waited = 0  # events since a definition met before its call began to wait
    for item in items:
        done, ended = state()
        if runs.waiting:
            waited += 1
            if done:  # (never called; one whose run is held is told with it, below)
                for name in runs.waiting - pending:
                    runs.refuse(name)
            elif waited > runs.held_most:
                rerun |= runs.refuse_waiting()  # (a run under way is told so, the rest of it too)
        else:
            waited = 0
        run: Run | None
        event: Event
        run, event = item if type(item) is tuple else (None, item)  # type: ignore[assignment]
        if run is not None and run[0] in programmed:  # (the rest of a run told past the bound)
            kept = as_programmed(event, run[1])
            if kept is None:
                continue
            run, event = None, kept
        if run is not None:
            pending.add(run[0])
        elif not held:
            yield event  # (the common case: nothing held)
            continue
        held.append((event, run))
        found = again()
        rerun.update(found)
        found.clear()
        if done or len(held) > runs.held_most or pending <= rerun:
            told = rerun if ended else pending
            programmed |= told
            yield from _told_runs(held, told, runs, as_programmed)
            held, pending, rerun = [], set(), set()
    for name in runs.waiting - pending:  # (never called)
        runs.refuse(name)
    if held:
        yield from _told_runs(held, rerun if state()[1] else pending, runs, as_programmed)


def _told_runs(
    held: list[tuple[Event, Run | None]],
    again: set[str],
    runs: OnceRuns,
    as_programmed: Callable[[Event, Block], Event | None],
) -> Iterator[Event]:
    """The events held from a CALLED run on: the runs of the subprograms in `again` left as
    programmed, the others as they ran, their blocks to be written at the definition."""
    for event, run in held:
        if run is None:
            yield event
        elif run[0] in again:
            runs.refuse(run[0])
            kept = as_programmed(event, run[1])
            if kept is not None:
                yield kept
        else:
            runs.ran_once(run[0], event.block)
            yield event
