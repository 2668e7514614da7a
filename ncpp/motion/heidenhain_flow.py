"""Klartext labels, subprograms, program-section repeats and jumps: the order a program's blocks run in.

TNC 640 Klartext manual, "Subprograms and program section repeats": `LBL n` (1-65535 or a
name in quotes) marks a place, `LBL 0` ends a subprogram.  `CALL LBL n` runs the blocks after
`LBL n` up to `LBL 0` and goes on after the call (subprograms stand after M2/M30, since the
program runs through them otherwise; they nest up to 19 deep and do not call themselves);
`CALL LBL n REP k` runs the section from `LBL n` to the call k more times.  "If-then
decisions with Q parameters": `FN 9: IF +Q1 EQU +Q2 GOTO LBL n` (FN 10 NE, FN 11 GT,
FN 12 LT) jumps to `LBL n` when the condition holds.

`KlartextFlow.steps` yields each block with what the interpreter is to do with it, as
`ncpp.motion.flow` does for o-words (RUN, FIXED, SKIP, TEXT) and its `owner`: a block that
runs out of the text's order (a subprogram's, a repeat's, a loop's second pass) belongs to
the line that runs it, whose text the output is at, so that every text is written once where
it stands.  A block that will run again (it lies between a label and a later call of or jump
back to it, read ahead up to `LOOKAHEAD` blocks once a label is read) is FIXED from its first
pass: its one text cannot be rewritten for each run; so is a subprogram's text the program runs
in its place after a call ran it.  A block whose only runs again would be those of jumps back
(FN 9-12) is ONCE in its first pass (as `ncpp.motion.flow`'s loops): whether a jump goes back
is told later, by the flow going on past it in straight code (`in_straight_code`: the pass ran
once) or running a block of the pass again.  A call or jump back over a move that ran in place
(RUN) leaves the scope, and so does a label more than `MAX_AHEAD` blocks ahead or no longer held
(blocks are held from the first label before the position, up to `MAX_BEHIND` back).

A subprogram's text that stands before its call runs where it stands when the program comes to it
("Subprograms": subprograms stand after M2/M30 since the control runs them otherwise), and again
where it is called: a call without REP runs the blocks from its label to the first LBL 0, so where
those hold no control line (`_straight_end`), the blocks that run again are those alone, and the
main program's blocks after that LBL 0 run once (`bodies`).  A jump the program takes over such a
text (`FN 9: IF +0 EQU +0 GOTO LBL 99`, the subprograms ahead of the main program) runs none of it
there: the text waits for its call (`_wait_for_call`, `OnceRuns.meet`, as ISO's definitions do).

A subprogram called from the main program's straight code whose text stands after the call (after
M30, where the manual puts subprograms), or before it behind a jump that went over it, may run
once: its run's blocks are CALLED (`_runs_once`, as `ncpp.motion.flow`'s), and if its text runs
again -- another call of its label (with or
without REP), its `LBL` block run (the program running into it, a jump to it) -- the flow names
it in `called_again`: whether it ran once is known only where the program ends (`ncpp.motion.once`).
"""

from __future__ import annotations

import re
from collections.abc import Callable, Iterable, Iterator

from ncpp.errors import Location, NcppError
from ncpp.motion.endless import Revisits, endless, without_way_out
from ncpp.motion.flow import CALLED, FIXED, MAX_RERUN, ONCE, RUN, SKIP, TEXT, Around, CountedPasses
from ncpp.motion.modal import OutOfScope
from ncpp.motion.once import OnceRuns
from ncpp.program.blocks import Block, Statement, Word

# Blocks after a REP call searched for the REP calls of the sections around it (`_around`)
MAX_AROUND = 10_000
LOOKAHEAD = 20_000  # blocks read ahead of the one that runs, to find the calls and jumps back
MAX_AHEAD = 200_000  # blocks read ahead to find a label a call or jump names
MAX_BEHIND = 200_000  # blocks held behind the one that runs, for calls and jumps back
MAX_BODY = 10_000  # blocks searched from a label for the LBL 0 of a straight subprogram (`_straight_end`)
MAX_NESTING = 19  # subprogram levels (TNC 640 Klartext manual, "Nesting")
JUMPS = {9: "EQU", 10: "NE", 11: "GT", 12: "LT"}  # FN 9-12 and the comparison each makes
_JUMP = re.compile(
    r"[ \t]*IF[ \t]*(.+?)[ \t]*(EQU|NE|GT|LT)[ \t]*(.+?)[ \t]*GOTO[ \t]*LBL[ \t]*"
    r"(\d+|\"[^\"]*\"|Q\d+)[ \t]*$",
    re.I,
)
_DROP = 4096  # blocks dropped at a time


def label_key(name: object) -> float | str:
    """A label as its definitions and calls name it: a number or a name."""
    return name if type(name) is str else float(name)  # type: ignore[arg-type]


def jump_parts(text: str) -> tuple[str, str, str, object] | None:
    """An FN 9-12 body's (left operand, comparison, right operand, label), None if not one."""
    found = _JUMP.fullmatch(text)
    if found is None:
        return None
    left, test, right, label = found.groups()
    target: object = (
        label[1:-1] if label[0] == '"' else ("param", label.lower()) if label[0] in "Qq" else int(label)
    )
    return left, test.upper(), right, target


def _reference(item: Statement) -> object:
    """The label a call or jump statement names (a literal, else a Q parameter tuple), or None."""
    if item.kind == "call_label":
        return item.node[0]
    if item.kind == "fn" and item.node[0] in JUMPS:
        parts = jump_parts(item.node[1] or "")
        return None if parts is None else parts[3]
    return None


class KlartextFlow:
    """The blocks of a Klartext program in the order they run (see the module docstring).

    The interpreter tells it, while it runs a block, where the program goes next
    (`goto`, `call`, `end_subprogram`) and which in-place blocks moved (`moved`);
    `done()` says the program has ended; `stop(reason, block)` ends it where the
    flow itself cannot go on."""

    def __init__(
        self,
        file: str,
        blocks: Iterable[Block],
        outside: Callable[[], list[Around]] = list,
        once: OnceRuns | None = None,
    ):
        self.outside = outside  # the REP sections around this program's run (its CALL PGM's: `around_call`)
        self.file = file
        self.stream = iter(blocks)
        self.held: list[Block] = []  # blocks read and still wanted, from index `base`
        self.base = 0
        self.exhausted = False
        self.labels: dict[float | str, int] = {}  # label -> the index of its LBL block
        self.again: list[tuple[int, int]] = []  # [label, call or jump back]: blocks that run again
        # a label's index -> its straight text's LBL 0 (`_straight_end`), for a label called from after
        # that text while none of it had run in its place: a call of it runs that text alone
        self.bodies: dict[int, int] = {}
        self.called_text: set[tuple[int, int]] = set()  # [label, LBL 0] of the subprograms a call ran
        self.jumps_back: set[int] = set()  # the indices of the FN 9-12 among the ends of `again`
        self.twice: set[float | str] = set()  # labels defined more than once (the control refuses them)
        self.named_by_q = False  # a label defined by a Q parameter: no call or jump can be followed
        self.frames: list[tuple[int, float | str]] = []  # subprogram calls: (index to return to, label)
        self.counters: dict[int, int] = {}  # a REP call's index -> the repeats still to run
        self.marks: dict[int, int] = {}  # a REP call's index -> `CountedPasses.ended`'s mark
        self.sections: dict[int, tuple[int, int]] = {}  # a REP call's index -> (its label's index, passes)
        self.label_at: dict[int, float | str] = {}  # the index of a LBL block read -> its label
        # a LBL's index -> `CountedPasses.steps` when it last ran (where a section's first pass starts)
        self.label_steps: dict[int, int] = {}
        self.current = -1  # the index of the block the interpreter runs
        self.next: int | None = None  # where the block running sends the program (None: the next)
        self.last_run_move = -1  # the index of the last block whose moves ran in place (RUN)
        self.once_move = -1  # and of a jump's loop's first pass (ONCE) not yet told: it may be rewritten too
        self.rerun = 0  # blocks run out of the text's order
        self.passes = CountedPasses(file)
        self.revisits: Revisits | None = None  # refuses a loop back at a state it had (`watch`)
        self.at = (0, 0)  # where `steps` stands: the block to run, the next to write in place
        self.straight = False  # the block running runs in its place, once (RUN)
        self.once = once  # the subprograms whose first run may be CALLED (`_runs_once`; None: none)
        self.called: str | None = None  # the subprogram of the CALLED run under way
        self.entered: set[float | str] = set()  # the labels called or whose LBL block ran
        self.once_called: dict[float | str, str] = {}  # a label whose run was CALLED -> its name
        self.called_again: list[str] = []  # the CALLED subprograms whose text ran again since read
        self.next_in_place = 0  # where a jump over text goes on in place (`_wait_for_call`)

    # -- reading ------------------------------------------------------------------------
    def _read(self) -> None:
        """One more block of the stream: its label, or the label its call or jump names."""
        block = next(self.stream, None)
        if block is None:
            self.exhausted = True
            return
        index = self.base + len(self.held)
        self.held.append(block)
        item = next((i for i in block.items if type(i) is Statement and i.kind != "block_delete"), None)
        if item is None:
            return
        if item.kind == "label":
            if type(item.node[0]) is tuple:
                self.named_by_q = True
            elif label_key(item.node[0]) in self.labels:
                self.twice.add(label_key(item.node[0]))
            else:
                self.labels[label_key(item.node[0])] = index
                self.label_at[index] = label_key(item.node[0])
            return
        name = _reference(item)
        if name is not None and type(name) is not tuple and self.labels.get(label_key(name), index) < index:
            label = self.labels[label_key(name)]
            end = self._body(label, index) if item.kind == "call_label" and item.node[1] == 0 else None
            self.again.append((label, index if end is None else end))
            if item.kind == "fn":
                self.jumps_back.add(index)

    def _body(self, label: int, call: int) -> int | None:
        """The LBL 0 of the straight text after `label` (`_straight_end`), which a call without REP
        read at `call` runs alone, where that LBL 0 stands before the call and no block of the text
        has moved in its place yet (the text's blocks from here on run again: FIXED); else None."""
        if label in self.bodies:
            return self.bodies[label]
        if label < self.base or max(self.last_run_move, self.once_move) >= label:
            return None
        end = self._straight_end(label, MAX_BODY)
        if end is None or end >= call:
            return None
        self.bodies[label] = end
        return end

    def _straight_end(self, label: int, most: int) -> int | None:
        """The index of the first LBL 0 after the LBL block at `label`, within `most` blocks, where
        the blocks between are a run with no control line (no label, call, jump, FN 14, program end,
        M2 or M30: each runs once, in order) and no radius compensation RL/RR; else None."""
        end = label + 1
        while (block := self.block(end)) is not None and end - label <= most:
            head = _head(block)
            if head is not None and head.kind == "label" and head.node[0] == 0:
                return end
            if _way_out(block) or (head is not None and head.kind in _NOT_ONCE) or _compensates(block):
                return None
            end += 1
        return None

    def block(self, index: int) -> Block | None:
        """The block at `index`, read ahead to it (None past the end)."""
        while self.base + len(self.held) <= index and not self.exhausted:
            self._read()
        if index < self.base or index >= self.base + len(self.held):
            return None
        return self.held[index - self.base]

    def _look_ahead(self, index: int) -> None:
        while not self.exhausted and self.base + len(self.held) < index + LOOKAHEAD:
            self._read()

    def _trim(self, low: int) -> None:
        """Drop the blocks no call or jump can go back to: those before `low` and before
        the first label at or after `base` (and all more than MAX_BEHIND back)."""
        if low - self.base < _DROP:
            return
        first_label = min((i for i in self.labels.values() if i >= self.base), default=low)
        keep = max(min(low, first_label), low - MAX_BEHIND)
        if keep - self.base >= _DROP:
            del self.held[: keep - self.base]
            self.base = keep
            self.again = [(a, b) for a, b in self.again if b >= keep]
            self.called_text = {(a, b) for a, b in self.called_text if b >= keep}
            self.jumps_back = {b for b in self.jumps_back if b >= keep}

    # -- what the interpreter tells ---------------------------------------------------
    def target(
        self, name: object, value: Callable[[tuple], float], col: int, subprogram: bool = False
    ) -> int:
        """The index of the label a call or jump names (OutOfScope where ncpp cannot follow);
        `subprogram`: a call without REP, which runs a straight text (`bodies`) alone."""
        if self.named_by_q:
            raise OutOfScope("a jump in a program with a label named by a Q parameter", col)
        key = label_key(value(name) if type(name) is tuple else name)
        if key == 0.0:
            raise OutOfScope("a call of LBL 0 (it only ends a subprogram)", col)
        while key not in self.labels and not self.exhausted:
            if self.base + len(self.held) > self.current + MAX_AHEAD:
                break
            self._read()
        index = self.labels.get(key)
        shown = f'"{key}"' if type(key) is str else f"{key:g}"
        if key in self.twice:
            raise OutOfScope(f"LBL {shown} (defined more than once)", col)
        if index is None:
            where = "not in the program" if self.exhausted else f"not within {MAX_AHEAD} blocks ahead"
            raise OutOfScope(f"LBL {shown} ({where})", col)
        if index < self.base:
            raise OutOfScope(f"LBL {shown} (more than {MAX_BEHIND} blocks back)", col)
        if (
            index <= self.current
            and self.last_run_move >= index
            and not (subprogram and index in self.bodies)
        ):
            raise OutOfScope(f"a jump back to LBL {shown} over moves that ran in their place", col)
        return index

    def goto(self, index: int) -> None:
        """FN 9-12 whose condition holds: on at the label."""
        self.next = index

    def refuse_without_way_out(self, index: int, block: Block, col: int) -> None:
        """A jump back to `index` whose condition never changes (its operands are numbers): refused
        where no block from the label to the jump can leave the loop (`endless.py`): no other jump,
        call, FN 14 error or program end."""
        if index > self.current or any(
            _way_out(self.held[i - self.base]) for i in range(index, self.current)
        ):
            return
        raise without_way_out(self.held[index - self.base].line, Location(self.file, block.line, col))

    def call(self, index: int, repeat: int, key: float | str, col: int, compensating: bool = False) -> None:
        """`CALL LBL n [REP k]`: the subprogram at `index`, or the section from it once more;
        `compensating`: radius compensation is in effect (no run of it is CALLED)."""
        first = key not in self.entered
        self._entered(key)
        if repeat:
            if index >= self.current:
                raise OutOfScope("CALL LBL ... REP with the label after the call", col)
            left = self.counters.get(self.current, repeat)
            if left:
                self.counters[self.current] = left - 1
                line = self.held[self.current - self.base].line
                first = self.current not in self.marks  # (the section's first pass ended)
                mark = self.marks.get(self.current, self.label_steps.get(index))
                self.sections[self.current] = (index, repeat + 1)
                around = (lambda current=self.current: self._around(index, current)) if first else None
                self.marks[self.current] = self.passes.ended(
                    mark, self.rerun, left - 1, line, "CALL LBL ... REP", None, around, repeat + 1
                )
                self.next = index + 1
            else:
                del self.counters[self.current]
                self.marks.pop(self.current, None)
                self.sections.pop(self.current, None)
            return
        if any(label == key for _, label in self.frames):
            raise OutOfScope("a subprogram that calls itself", col)
        if len(self.frames) >= MAX_NESTING:
            raise OutOfScope(f"subprograms nested more than {MAX_NESTING} deep", col)
        if first and not compensating and self._runs_once(index, key):
            self.called = self.once_called[key] = label_name(key)
        self.frames.append((self.current + 1, key))
        self.next = index + 1

    def _runs_once(self, index: int, key: float | str) -> bool:
        """Whether a call may be its subprogram's only run, whose text may then be rewritten for it
        where it stands: called from the main program's straight code (in its place, in no section
        that runs again), its text after the call, from its label to the first LBL 0 (within
        `held_most` blocks) a run of blocks with no control line (no label, call, jump, FN 14,
        program end, M2 or M30: each runs once, in order) and no radius compensation RL/RR."""
        once = self.once
        name = label_name(key)
        if once is None or not once.may_run_once(name) or self.frames or not self.straight:
            return False
        if index <= self.current:
            return name in once.waiting  # (its text stands before the call, behind a jump: `_wait_for_call`)
        return self._straight_end(index, once.held_most) is not None

    def _wait_for_call(self, skipped: int) -> None:
        """A jump in the main program's straight code went over the block at `skipped`: a label whose
        straight text (`_straight_end`) it went over whole, not yet run, waits for a call that may be
        its only run (`OnceRuns.meet`: the writer holds the lines from its text on).  Whether it is
        called once is known only at the program's end."""
        once, label = self.once, self.label_at.get(skipped)
        if once is None or label is None or label == 0.0 or label in self.entered or not self.straight:
            return
        if self.frames or not once.may_run_once(label_name(label)):
            return
        end = self._straight_end(skipped, once.held_most)
        if end is None or end >= self.next_in_place:
            return
        once.meet(label_name(label), [b for i in range(skipped, end + 1) if (b := self.block(i)) is not None])

    def _entered(self, key: float | str) -> None:
        """The text after label `key` runs (a call of it, its LBL block): a CALLED one's again."""
        if key in self.once_called:
            self.called_again.append(self.once_called[key])
        self.entered.add(key)

    def _around(self, label: int, call: int, depth: int | None = None) -> list[Around]:
        """The REP sections around the section from `label` to its REP `call`, innermost first: the
        REP calls the program comes to from `call` on, before any other call, jump or end, each of
        a section that holds the one before (its label before that one's).  One not under way yet
        runs its REP k passes after the one under way.  In a subprogram (`depth` calls deep, None:
        as deep as the flow is), its LBL 0 goes on with the sections around its call; the END PGM of
        a program CALL PGM runs, with those around the CALL PGM (`outside`)."""
        depth = len(self.frames) if depth is None else depth
        loops: list[Around] = []
        index = call + 1
        while index < call + MAX_AROUND and (block := self.block(index)) is not None:
            item = next((i for i in block.items if type(i) is Statement), None)
            if item is None and any(type(w) is Word and w.letter == "M" and w.value in (2.0, 30.0)
                                    for w in block.items):  # fmt: skip
                break
            if item is not None and item.kind == "label" and item.node[0] == 0 and depth > 0:
                caller = self.frames[depth - 1][0] - 1  # (the call's index: it returns to the next)
                return loops + self._around(caller, caller, depth - 1)
            if item is not None and item.kind == "program_end" and depth == 0:
                return loops + self.outside()
            if item is not None and item.kind != "label":
                name, repeat = item.node if item.kind == "call_label" else (None, 0)
                if type(repeat) is not int:  # (a count from a Q parameter: out of scope where it runs)
                    break
                start = self.labels.get(label_key(name)) if repeat and type(name) is not tuple else None
                if start is None or start >= label:
                    break
                left, passes = (
                    self.counters.get(index, repeat),
                    self.sections.get(index, (start, repeat + 1))[1],
                )
                loops.append(Around(left, passes, block.line, "CALL LBL ... REP", self.file))
                label = start
            index += 1
        return loops

    def around_call(self) -> list[Around]:
        """The REP sections around the block running (a CALL PGM), innermost first (`_around`)."""
        return self._around(self.current, self.current)

    def end_subprogram(self) -> None:
        """`LBL 0`: back after the call (in the main program it only marks a place)."""
        if self.frames:
            back, key = self.frames.pop()
            self.next = back
            self.called_text.add((self.labels[key], self.current))
            if not self.frames:
                self.called = None

    def moved(self, once: bool = False) -> None:
        """The block running in its place, or in a CALLED run (then: its call), moved (its text may
        be rewritten for that run); `once`: in a loop's first pass (ONCE), not yet told."""
        if once:
            self.once_move = self.current
        else:
            self.last_run_move = self.frames[0][0] - 1 if self.frames else self.current

    def told(self, again: bool) -> None:
        """A loop's first pass was told (`ncpp.motion.once`): run once, its moves are as those run in
        place (no jump back may run them again)."""
        if not again:
            self.last_run_move = max(self.last_run_move, self.once_move)
        self.once_move = -1

    def in_straight_code(self) -> bool:
        """Whether the block running runs in its place with no loop under way (none can go back)."""
        return self.straight

    def watch(self, quick: Callable[[], object], state: Callable[[], object]) -> None:
        """Refuse a loop that comes back to a state it had (`endless.py`): `state()` is the
        interpreter's, `quick()` a cheap part of it (a copy)."""
        self.revisits = Revisits(None, None, quick, lambda: self._with_flow(state()))

    def _with_flow(self, state: object) -> tuple:
        """The interpreter's `state` and the flow's own: where it stands, its calls and REP counts,
        what it has read and holds; not its counts of blocks run."""
        held = (self.base, len(self.held), self.exhausted, len(self.labels), len(self.again), len(self.twice),
                self.named_by_q, self.last_run_move, self.once_move)  # fmt: skip
        return state, self.at, tuple(self.frames), tuple(self.counters.items()), held, self.called

    def _arrived(self, block: Block, pc: int, written: int) -> None:
        """Back at a label (`pc`) from `block`: refused where the state is one it had there."""
        self.at = (pc, written)
        depth, revisits = len(self.frames), self.revisits
        assert revisits is not None  # (`steps` asks only when watching)
        found = revisits.arrived((pc, id(block), depth), (depth, pc), (pc, block))
        if found is not None:
            jumps, (start, end) = found
            raise endless(jumps, self.held[start - self.base].line, Location(self.file, end.line, 1))

    def _in_place(self, pc: int) -> str:
        """RUN, or FIXED for a block in its place that runs again (between a label and a later call
        of it, a subprogram's text a call ran), or ONCE where only jumps back may run it again."""
        if not self.again and not self.called_text:
            return RUN
        if _within(pc, self.called_text):
            return FIXED
        ends = [b for a, b in self.again if a <= pc <= b]
        if not ends:
            return RUN
        return ONCE if all(b in self.jumps_back for b in ends) else FIXED

    # -- the order ----------------------------------------------------------------------
    def steps(self, done: Callable[[], bool], stop: Callable[[str, Block], None]) -> Iterator[tuple]:
        """(block, kind, owner) in the order the blocks run; the rest as TEXT once `done()`."""
        pc = written = 0
        while True:
            if done():
                break
            in_place = not self.frames and pc >= written
            if in_place:
                self.next_in_place = pc
                while written < pc:  # jumped over: written, not run
                    self._wait_for_call(written)
                    yield self.block(written), SKIP, None
                    written += 1
                if self.labels:  # (before the first label no block can run again: the text streams)
                    self._look_ahead(pc)
            block = self.block(pc)
            if block is None:
                owner = self.block(written - 1)
                if self.frames and owner is not None:
                    stop("a subprogram without LBL 0 before the end of the program", owner)
                break
            self.current, self.next = pc, None
            self.passes.steps += 1
            if pc in self.label_at:
                self.label_steps[pc] = self.passes.steps
                self._entered(self.label_at[pc])
            if in_place:
                kind = self._in_place(pc)
                self.straight = kind is RUN
                yield block, kind, None
                written = pc + 1
            else:
                owner = self.block(written - 1)
                self.rerun += 1
                if self.rerun > MAX_RERUN:
                    raise NcppError(
                        f"the program runs more than {MAX_RERUN} blocks in loops and subprograms: "
                        "a loop that never ends?",
                        Location(self.file, owner.line if owner is not None else None),
                    )
                self.straight = False
                yield block, FIXED if self.called is None else CALLED, owner
            if self.next is not None and self.next <= pc and self.revisits is not None:
                self._arrived(block, self.next, written)
            pc = self.next if self.next is not None else pc + 1
            if min(pc, written - 1) - self.base >= _DROP:
                self._trim(min([pc, written - 1] + [i for i, _ in self.frames]))
        while (rest := self.block(written)) is not None:
            yield rest, TEXT, None
            written += 1
            self._trim(written)


# Statements that keep a subprogram's text from being rewritten for its one run (`_runs_once`)
_NOT_ONCE = frozenset(("label", "program_end", "contour_label"))


def _within(index: int, ranges: Iterable[tuple[int, int]]) -> bool:
    return any(a <= index <= b for a, b in ranges)


def label_name(key: float | str) -> str:
    """A label as a subprogram's name (`OnceRuns`): `5`, `"CONTOUR"`."""
    return f'"{key}"' if type(key) is str else f"{key:g}"


def _head(block: Block) -> Statement | None:
    """The block's first statement (a `/` aside)."""
    return next((i for i in block.items if type(i) is Statement and i.kind != "block_delete"), None)


def _compensates(block: Block) -> bool:
    """Whether the block turns radius compensation RL or RR on."""
    return any(type(i) is Statement and i.kind == "radius_comp" and i.node[0] != "R0" for i in block.items)


def _way_out(block: Block) -> bool:
    """Whether the block may leave a loop or end the program: a jump (FN 9-12), a call of a label
    or a program, an FN 14 error, M2 or M30."""
    for item in block.items:
        if type(item) is Word and item.letter == "M" and item.value in (2.0, 30.0):
            return True
        if type(item) is Statement and (
            item.kind in ("call_label", "call_program") or item.kind == "fn" and item.node[0] in (*JUMPS, 14)
        ):
            return True
    return False


__all__ = [
    "CALLED",
    "FIXED",
    "ONCE",
    "RUN",
    "SKIP",
    "TEXT",
    "KlartextFlow",
    "JUMPS",
    "jump_parts",
    "label_key",
]
