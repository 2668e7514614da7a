"""Loops that never end, refused where they first come back to a state they were in before.

A program's run is deterministic: nothing comes in from outside while it runs (ncpp leaves a
program that reads the machine's own state, a probe or an operator's input out of its scope).
So if the flow arrives at the same backward jump (a loop's end, a GOTO back) with exactly the
state it had at an earlier arrival -- every parameter, the position, the modes, the flow's own
loops, calls and branches -- the stretch between the two arrivals runs again and again, for
ever.  That is the test here, and it refuses no loop that ends: a run that ends never repeats
a state.  A loop whose state keeps changing (a counter that counts for ever) is left to the
bound on lines run again (`flow.MAX_RERUN`).

The arrivals are checked as Brent's cycle finding does: the state is taken whole at the 1st,
2nd, 4th, 8th ... arrival and each arrival after it is compared with it, so a loop that repeats
after p arrivals is found within about twice p arrivals once it repeats.  Comparing whole states
at every arrival would cost more than the loop's own lines, so the parameters are journalled
(`Journal`: the ones written since the state was taken, with their values then) and the whole
state is built and compared only where the jump, the parameters and the cheap part of the state
(`quick`: the position) are all as they were.

Before that, at the end of its first pass, a while loop whose condition is a constant true and
whose body has no way out (`flow.Flow._way_out`: no break, return, jump, program end or alarm, and
no call of a body that has one or cannot be seen) is refused at once, whatever its state does.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Hashable
from pathlib import PurePath
from typing import Any

import numpy as np

from ncpp.errors import Location, NcppError
from ncpp.program.blocks import Block, Item

ABSENT = object()  # a parameter that has no value (a name not defined, a number never written)


def exact(value: object) -> object:
    """`value` as something that compares equal to another's only where the two are the same
    state: floats to the bit (0.0 is not -0.0, NaN is no NaN), containers item by item,
    dataclasses field by field, arrays byte by byte, the program's text as it reads; any other
    object equal to nothing."""
    if isinstance(value, float):
        return (0.0, math.copysign(1.0, value)) if value == 0.0 else value
    if value is None or isinstance(value, (int, str)):  # (bool an int)
        return value
    if isinstance(value, (list, tuple)):
        return tuple(exact(item) for item in value)
    if isinstance(value, dict):
        return {key: exact(item) for key, item in value.items()}
    if isinstance(value, (set, frozenset)):
        return frozenset(value)  # (of numbers and names)
    if isinstance(value, (Block, Item)):  # (a program's parsed text: never changed, compared as it reads)
        return value
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        return type(value), tuple(exact(getattr(value, f.name)) for f in dataclasses.fields(value))
    if isinstance(value, PurePath):
        return str(value)
    if isinstance(value, np.ndarray):
        return value.dtype.str, value.shape, value.tobytes()
    return object()  # (an object whose state is not told: equal to nothing, no loop refused over it)


class Journal:
    """The values parameters had when the journal (re)started (`before`), of those written since:
    the parameters' keeper sets a key's, where it is not there yet, before each write;
    `changed(current)` says whether any differs now (`current(key)` gives a parameter's value as
    kept here, `ABSENT` for none)."""

    def __init__(self) -> None:
        self.before: dict[Hashable, object] = {}

    def restart(self) -> None:
        self.before.clear()

    def changed(self, current: Callable[[Hashable], object]) -> bool:
        for key, was in self.before.items():  # (a loop, not any(): this runs at every arrival)
            if current(key) != was:
                return True
        return False


class Revisits:
    """The arrivals of one program run at its backward jumps (the module docstring).

    `journal` notes the parameters' writes, `current` reads one as the journal keeps it (None:
    `quick` and `state` hold the parameters); `state()` gives the rest of the state (`exact`
    values), `quick()` a cheap part of it compared first (a copy: equal where the states are);
    `state()` may return None where the state cannot be told whole (a corner waiting for its next
    move), and no loop is refused there."""

    def __init__(
        self,
        journal: Journal | None,
        current: Callable[[Hashable], object] | None,
        quick: Callable[[], object],
        state: Callable[[], object],
    ):
        self.journal, self.current, self.quick, self.state = journal, current, quick, state
        self.arrivals = 0
        self.taken_at = 0  # the arrival whose state is kept (0: none yet)
        self.power = 1  # arrivals compared with it before the state is taken again
        self.site: Hashable = None
        self.kept_quick: object = None
        self.kept: object = None
        # The outermost jump since the state was taken: its rank and what the flow tells it by
        self.outer: tuple[tuple, Any] = ((), None)

    def arrived(self, site: Hashable, rank: tuple, place: Any) -> tuple[int, Any] | None:
        """The flow went back to a loop's head at `site` (which jump, in which call); `rank` orders
        the jumps outermost first ((the call depth, the head's index): a loop's head stands before
        those of the loops inside it), `place` is what the flow tells this jump by.  Where the
        state is one it had before: the jumps back since then and the `place` of the outermost
        (the loop that does not end: the others run inside it), else None."""
        self.arrivals += 1
        if rank < self.outer[0]:
            self.outer = (rank, place)
        if self.taken_at and self._same(site):
            return self.arrivals - self.taken_at, self.outer[1]
        if self.arrivals - self.taken_at >= self.power:
            self.taken_at, self.site, self.power = self.arrivals, site, 2 * self.power
            self.outer = (rank, place)
            if self.journal is not None:
                self.journal.restart()
            self.kept_quick, self.kept = self.quick(), self.state()
        return None

    def _same(self, site: Hashable) -> bool:
        if site != self.site or self.quick() != self.kept_quick:
            return False
        if self.journal is not None and self.journal.changed(self.current):  # type: ignore[arg-type]
            return False
        state = self.state()
        return state is not None and self.kept is not None and state == self.kept


# The expression nodes whose value depends on their operands alone (`expressions.py`'s tuples, and
# the Sinumerik parser's, which adds strings and boolean operators), and the functions of them that do
_PURE_NODES = frozenset(("num", "str", "neg", "pos", "not", "bnot", "bin", "atan2", "call"))
_PURE_FUNCTIONS = frozenset(("SIN", "COS", "TAN", "ASIN", "ACOS", "ATAN", "ATAN2", "SQRT", "ABS", "POT", "LN",
                             "EXP", "FIX", "FUP", "ROUND", "TRUNC", "MINVAL", "MAXVAL"))  # fmt: skip


def never_changes(expr: tuple) -> bool:
    """Whether an expression reads nothing that may change (no parameter, variable or system
    value): its value never changes."""
    kind = expr[0]
    if kind not in _PURE_NODES or kind == "call" and str(expr[1]).upper() not in _PURE_FUNCTIONS:
        return False
    return all(never_changes(part) for part in expr[1:] if type(part) is tuple)


def without_way_out(head: int, where: Location) -> NcppError:
    """The refusal of a loop (at line `head`) that can never end: no condition that changes, no way out."""
    return NcppError(
        f"a loop that does not end: the loop at line {head} has no condition that can end it (a constant, or "
        "none) and nothing in it leaves it (no break, return, jump, program end, alarm, or call that may) (the "
        "control would run it for ever; ncpp follows a program to its end)",
        where,
    )


def endless(jumps: int, head: int, where: Location) -> NcppError:
    """The refusal of a loop that came back to its head (line `head`) with the state it had `jumps`
    jumps back (to it or to the heads of loops inside it) before."""
    before = "at the jump back before" if jumps == 1 else f"{jumps:,} jumps back before"
    return NcppError(
        f"a loop that does not end: it comes back to line {head} with every parameter, the position and "
        f"the modes as they were {before} (the control would run it for ever; ncpp follows a program to "
        "its end)",
        where,
    )
