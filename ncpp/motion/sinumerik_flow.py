"""Sinumerik control flow: the order a program's blocks run in.

The rules are those of the SINUMERIK 840D sl Programming Manual, Job Planning
(6FC5398-2BP40-1AA0), "Flexible NC programming": "Program jumps and branches" and
"Control structures":

* `GOTOF label` searches forward for the jump destination, `GOTOB` backward, `GOTO`
  forward then backward, `GOTOC` as GOTO but a destination not found raises no alarm:
  the program goes on with the next block; a destination is a label (`NAME:`) or a
  block number (`N100`, `GOTOF 100`);
* `IF condition GOTOx destination` jumps when the condition holds (a conditional jump);
* `CASE (expression) OF constant GOTOx destination ... DEFAULT GOTOx destination`
  jumps at the first constant equal to the expression, else at DEFAULT, else goes on;
* `IF ... ELSE ... ENDIF`, `WHILE ... ENDWHILE`, `FOR variable = start TO end ...
  ENDFOR` (the variable counts up by 1 while it is not above the end), `REPEAT ...
  UNTIL condition`, `LOOP ... ENDLOOP` (endless, left by a jump) are the control
  structures; they nest.  The manual advises against mixing control structures and
  program jumps: ncpp does not follow a jump while a structure is open;
* program section repetition ("Program section repetition (REPEAT, REPEATB, ENDLABEL, P)"):
  `REPEATB label P=n` runs the block the label marks (searched toward the program's start,
  then toward its end) n times, `REPEAT label P=n` the blocks from the label (before it) to the
  line before the REPEAT, `REPEAT start end P=n` those from the start label (searched as
  REPEATB's) to the end label after it; without P once; then the program goes on after the
  REPEAT line.  Not followed: a section closed by ENDLABEL, one that holds its REPEAT line, a
  control structure or a jump, or a repetition inside another or inside a structure.

`SinumerikFlow.steps(blocks)` yields each block with what the interpreter is to do
with it, as `ncpp.motion.flow` does for o-words (its RUN, FIXED, ONCE, SKIP, TEXT): a
block that runs once where it stands is RUN; the first pass of a loop (WHILE, FOR, REPEAT,
LOOP) where it stands is ONCE (whether its text runs again is told later: `ncpp.motion.once`);
the blocks a backward jump among the first `_TRIM` blocks goes back over are FIXED from their
first pass (one text runs many times: its moves are left as programmed); a loop's second and
later passes come again, FIXED, with an `owner`, the line that sent the program back
(ENDWHILE, UNTIL, a GOTOB), whose text holds them.  Past the first
`_TRIM` blocks, a backward jump over a move that ran in place (its text may be
rewritten for that one run) leaves the scope.  A jump into or out of an open
structure, a destination not found (but GOTOC's) or no longer held (blocks are held
`_TRIM` back, and while a loop runs) leave the scope too: the rest passes through.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass

from ncpp.errors import Location, NcppError
from ncpp.motion.endless import Revisits, endless, exact, never_changes, without_way_out
from ncpp.motion.flow import _TRIM, FIXED, MAX_RERUN, ONCE, RUN, SKIP, TEXT, Around, CountedPasses
from ncpp.motion.modal import OutOfScope
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word

# Statements that steer the flow (the builder's kinds: ncpp/program/dialects/sinumerik.py)
CONTROLS = frozenset(("if", "else", "endif", "while", "endwhile", "for", "endfor", "repeat", "until",
                      "loop", "endloop", "goto", "case"))  # fmt: skip
OPENERS = {"if": "endif", "while": "endwhile", "for": "endfor", "repeat": "until", "loop": "endloop"}
CLOSERS = frozenset(OPENERS.values())
# Blocks a forward search for a jump destination reads ahead before it gives up (memory stays bounded)
MAX_AHEAD = 100_000
SECTION = "section"  # the kind `_controls` gives a program section repetition (`_repetition`)
# Calls that neither end nor leave anything: a message and the frame instructions (`sinumerik.FRAMES`)
_NO_WAY_OUT = frozenset(("MSG", "TRANS", "ATRANS", "ROT", "AROT", "SCALE", "ASCALE", "MIRROR", "AMIRROR"))
# The label that ends a section `REPEAT start P=n` repeats (not followed: `_repetition`)
END_LABEL = "ENDLABEL"


@dataclass
class _Open:
    """A control structure under way."""

    kind: str  # if, while, for, repeat, loop
    start: int  # the index of its opening block
    end: float = 0.0  # FOR: the end value
    mark: int | None = None  # FOR: `CountedPasses.ended`'s mark
    total: int = 0  # FOR: its passes, all told (as counted where it starts)
    left: int = 0  # FOR: its passes after the one under way
    checked: bool = False  # WHILE, LOOP: whether it may end was looked at (`_refuse_without_way_out`)


@dataclass
class _Section:
    """A program section repetition under way (REPEAT, REPEATB)."""

    start: int  # the index of its first block
    end: int  # the index of its last block
    runs: int  # runs still to come after the one under way
    back: int  # the index of the block after the REPEAT line, where the program goes on


class SinumerikFlow:
    """The blocks of a Sinumerik program in the order they run (see the module docstring).

    `value(expr, block, item)` and `assign(target, expr, block, item)` are the
    interpreter's; `done()` says the program has ended; `stop(reason, block, col, owner)`
    ends interpretation where the flow leaves the scope; `revisits`, given the interpreter's
    state, refuses a loop that comes back to a state it had (`endless.py`)."""

    def __init__(
        self, file: str, value: Callable, assign: Callable, done: Callable[[], bool], stop: Callable,
        revisits: Revisits | None = None, outside: Callable[[], list[Around]] = list,
    ):  # fmt: skip
        self.file, self.value, self.assign, self.done, self.stop = file, value, assign, done, stop
        self.outside = outside  # the counted loops around this program's run (a subprogram's call's)
        self.revisits = revisits
        if revisits is not None:  # (the interpreter's state, then the flow's)
            interpreters = revisits.state
            revisits.state = lambda: self._with_flow(interpreters())
        self.stream: Iterator[Block] = iter(())
        self.buffer: list[Block] = []  # blocks read and still held, from index `base`
        self.base = 0
        self.read = 0  # blocks read from the stream
        self.written = 0  # the next block to write in the text's order
        self.pc = 0  # the next block to run
        self.open: list[_Open] = []
        self.looped: set[int] = set()  # blocks a backward jump read ahead runs again
        self.last_run_move = -1  # the index of the last block that moved in place (RUN): the interpreter's
        self.once_move = -1  # and of a loop's first pass (ONCE) not yet told: it may be rewritten too
        self.rerun = 0  # blocks run out of the text's order so far
        self.section: _Section | None = None  # a REPEAT's section running
        self.passes = CountedPasses(file)

    # -- the stream ------------------------------------------------------------------
    def steps(self, blocks: Iterable[Block]) -> Iterator[tuple[Block, str, Block | None]]:
        """(block, kind, owner): owner is None but for blocks that run out of the text's order."""
        self.stream = iter(blocks)
        self._read_ahead()
        while not self.done():
            block = self._block(self.pc)
            if block is None:
                break
            in_place = self.pc == self.written
            owner = None if in_place else self.buffer[self.written - 1 - self.base]
            self.passes.steps += 1
            if not in_place:
                self.rerun += 1
                if self.rerun > MAX_RERUN:
                    raise NcppError(
                        f"a loop that does not end: {MAX_RERUN:,} blocks run again (the control would "
                        "run it for ever; ncpp follows a program to its end)",
                        Location(self.file, owner.line, 1),  # type: ignore[union-attr]
                    )
            try:
                control = _controls(block)
                target = self._decide(block, control) if control else None
            except OutOfScope as leave:
                self.stop(leave.reason, block, leave.col, owner)
                break
            if target is None:
                if self.pc in self.looped or not in_place:
                    yield block, FIXED, owner
                else:
                    yield block, (ONCE if self._looping() else RUN), owner
                self._advance()
                continue
            if in_place:
                yield block, TEXT, None
                self._wrote()
            if self.section is not None and target == self.section.start:  # (the blocks between run later)
                self.pc = target
            else:
                back = target <= self.pc
                yield from self._go(target)
                if back and self.revisits is not None:
                    self._arrived(block)
        yield from self._rest()

    def _arrived(self, block: Block) -> None:
        """Back at a loop's head (`pc`) from `block`: refused where the state is one it had there."""
        revisits = self.revisits
        assert revisits is not None  # (`steps` asks only when watching)
        found = revisits.arrived((self.pc, id(block)), (self.pc,), (self.pc, block))
        if found is not None:
            jumps, (start, end) = found
            raise endless(jumps, self.buffer[start - self.base].line, Location(self.file, end.line, 1))

    def _with_flow(self, state: object) -> tuple:
        """The interpreter's `state` and the flow's own: where it stands, its structures and
        section under way, what it has read and holds; not its counts of blocks run."""
        opened = tuple((o.kind, o.start, exact(o.end)) for o in self.open)
        section = self.section and exact(self.section)
        held = (self.written, self.base, self.read, self.last_run_move, self.once_move, len(self.looped))
        return state, self.pc, opened, section, held

    def _advance(self) -> None:
        if self.pc == self.written:
            self._wrote()
        section = self.section
        if section is not None and self.pc == section.end:  # a run of a REPEAT's section is over
            section.runs -= 1
            self.pc = section.start if section.runs > 0 else section.back
            if section.runs <= 0:
                self.section = None
            return
        self.pc += 1

    def _wrote(self) -> None:
        self.written = self.pc + 1
        if len(self.buffer) > 2 * _TRIM and not self._looping():
            keep = self.written - self.base - _TRIM  # a backward jump may go back _TRIM blocks
            if keep > 0:
                del self.buffer[:keep]
                self.base += keep

    def in_straight_code(self) -> bool:
        """Whether the program runs its text with no loop or section under way (none can go back)."""
        return not self._looping() and self.section is None

    def _ran_in_place(self) -> int:
        """The index of the last block whose moves ran in place, or may have (ONCE, not yet told)."""
        return max(self.last_run_move, self.once_move)

    def _looping(self) -> bool:
        """A loop is under way: its blocks run again (an IF's do not: they are not held for it)."""
        return any(o.kind != "if" for o in self.open)

    def _go(self, target: int) -> Iterator[tuple[Block, str, Block | None]]:
        """On to block `target`: the blocks a forward jump passes that stand where the text
        is written are written, and do not run."""
        for index in range(max(self.written, self.pc + 1), target):
            yield self.buffer[index - self.base], SKIP, None
            self.written = index + 1
        self.pc = target

    def _rest(self) -> Iterator[tuple[Block, str, Block | None]]:
        """After the program's end: every block not yet written, as text."""
        for index in range(self.written, self.read):
            yield self.buffer[index - self.base], TEXT, None
        self.buffer.clear()
        for block in self.stream:
            yield block, TEXT, None

    def _block(self, index: int) -> Block | None:
        while index >= self.read:
            block = next(self.stream, None)
            if block is None:
                return None
            self.buffer.append(block)
            self.read += 1
        return self.buffer[index - self.base]

    def _read_ahead(self) -> None:
        """The first `_TRIM` blocks, read ahead: the blocks a literal backward jump among them
        goes back over are `looped` (they run again; their first pass is FIXED too)."""
        seen: dict[str, int] = {}  # a destination -> the first block it names
        for index in range(_TRIM):
            block = self._block(index)
            if block is None:
                return
            for name in _destinations(block):
                seen.setdefault(name, index)
            try:
                controls = _controls(block)
            except OutOfScope:  # (met where the flow reaches it)
                continue
            for statement in controls:
                for keyword, destination in _jumps(statement):
                    start = None if keyword == "GOTOF" else seen.get(destination.upper())
                    if start is not None:  # (GOTO may find one ahead first: FIXED too, which is safe)
                        self.looped.update(range(start, index + 1))
                if statement.kind == SECTION:  # (a section before its REPEAT: its first run FIXED too)
                    self.looped.update(_section_before(statement, seen, index))

    # -- control blocks ---------------------------------------------------------------
    def _decide(self, block: Block, control: list[Statement]) -> int:
        """Run a control block: the index of the block that runs next."""
        first = control[0]
        if self.section is not None:
            raise OutOfScope(f"{_name(first)} in a section a REPEAT runs (not followed)", first.start + 1)
        if first.kind == "if" and len(control) == 2 and control[1].kind == "goto":  # a conditional jump
            return (
                self._jump(block, control[1], *control[1].node) if self._holds(block, first) else self.pc + 1
            )
        if len(control) > 1:
            raise OutOfScope(
                f"{control[1].kind.upper()} after {first.kind.upper()} in one block", control[1].start + 1
            )
        return getattr(self, "_" + first.kind)(block, first)

    def _holds(self, block: Block, statement: Statement) -> bool:
        return self.value(statement.node[0], block, statement) != 0.0

    def _if(self, block: Block, statement: Statement) -> int:
        if self._holds(block, statement):
            self.open.append(_Open("if", self.pc))
            return self.pc + 1
        match = self._match(self.pc, "if", statement)
        if _controls(self.buffer[match - self.base])[0].kind == "else":  # the ELSE branch runs
            self.open.append(_Open("if", self.pc))
        return match + 1

    def _else(self, block: Block, statement: Statement) -> int:
        self._top("if", statement)
        self.open.pop()
        return self._match(self.pc, "if", statement, past_else=True) + 1

    def _endif(self, block: Block, statement: Statement) -> int:
        self._top("if", statement)
        self.open.pop()
        return self.pc + 1

    def _while(self, block: Block, statement: Statement) -> int:
        again = bool(self.open) and self.open[-1].kind == "while" and self.open[-1].start == self.pc
        if self._holds(block, statement):
            if not again:
                self.open.append(_Open("while", self.pc))
            return self.pc + 1
        if again:
            self.open.pop()
        return self._match(self.pc, "while", statement) + 1

    def _endwhile(self, block: Block, statement: Statement) -> int:
        opened = self._top("while", statement)
        condition = _controls(self.buffer[opened.start - self.base])[0].node[0]  # (held while the loop runs)
        self._refuse_without_way_out(opened, never_changes(condition), block, statement)
        return opened.start

    def _for(self, block: Block, statement: Statement) -> int:
        target, start, end = statement.node
        self.assign(target, ("num", self.value(start, block, statement)), block, statement)
        last = self.value(end, block, statement)
        if self.value(target, block, statement) <= last:
            passes = int(min(last - self.value(target, block, statement), MAX_RERUN)) + 1
            self.open.append(_Open("for", self.pc, last, self.passes.steps, passes, passes - 1))
            return self.pc + 1
        return self._match(self.pc, "for", statement) + 1

    def _endfor(self, block: Block, statement: Statement) -> int:
        opened = self._top("for", statement)
        counter = _controls(self.buffer[opened.start - self.base])[0].node[0]  # (held while the loop runs)
        self.assign(counter, ("bin", "+", counter, ("num", 1.0)), block, statement)
        value = self.value(counter, block, statement)
        if value <= opened.end:
            left = int(min(opened.end - value, MAX_RERUN))  # (an end of 1e308 runs no more than this)
            around = self._around if opened.left == opened.total - 1 else None  # (its first pass ended)
            opened.left = left
            opened.mark = self.passes.ended(opened.mark, self.rerun, left, block.line, "FOR ... ENDFOR",
                                            self.file, around, opened.total)  # fmt: skip
            return opened.start + 1
        self.open.pop()
        return self.pc + 1

    def _around(self) -> list[Around]:
        """The counted loops around the innermost structure (`enclosing`)."""
        return self.enclosing(self.open[:-1])

    def enclosing(self, structures: list[_Open] | None = None) -> list[Around]:
        """The counted loops around the block running (inside `structures`, None: all under way),
        innermost first, as far as counted loops go: the FOR loops, then those around this
        program's run (a subprogram's P runs, the loops around its call)."""
        loops: list[Around] = []
        for opened in reversed(self.open if structures is None else structures):
            if opened.kind != "for":
                return loops
            line = self.buffer[opened.start - self.base].line  # (held while the loop runs)
            loops.append(Around(opened.left, opened.total, line, "FOR ... ENDFOR", self.file))
        return loops + self.outside()

    def _repeat(self, block: Block, statement: Statement) -> int:
        self.open.append(_Open("repeat", self.pc))
        return self.pc + 1

    def _until(self, block: Block, statement: Statement) -> int:
        opened = self._top("repeat", statement)
        if self._holds(block, statement):
            self.open.pop()
            return self.pc + 1
        return opened.start + 1

    def _loop(self, block: Block, statement: Statement) -> int:
        self.open.append(_Open("loop", self.pc))
        return self.pc + 1

    def _endloop(self, block: Block, statement: Statement) -> int:
        opened = self._top("loop", statement)
        self._refuse_without_way_out(opened, True, block, statement)
        return opened.start + 1

    def _refuse_without_way_out(
        self, opened: _Open, endless_condition: bool, block: Block, statement: Statement
    ) -> None:
        """At the end of a WHILE's (of a constant condition: `endless_condition`) or a LOOP's first pass: refuse
        it where nothing in it can leave it (`endless.py`).  A jump out of it leaves the scope (`_jump`),
        so the ways out are the program's or the subprogram's end and a call (what it does is not seen)."""
        if opened.checked:
            return
        opened.checked = True
        body = self.buffer[opened.start + 1 - self.base : self.pc - self.base]
        if endless_condition and not any(_way_out(b) for b in body):
            where = Location(self.file, block.line, statement.start + 1)
            raise without_way_out(self.buffer[opened.start - self.base].line, where)

    def _goto(self, block: Block, statement: Statement) -> int:
        return self._jump(block, statement, *statement.node)

    def _section(self, block: Block, statement: Statement) -> int:
        """REPEAT or REPEATB: on to the section's first block, the runs counted (`_advance`)."""
        keyword, start_label, end_label, times = statement.node
        where = statement.start + 1
        if self.open:
            raise OutOfScope(f"{keyword} inside {self.open[-1].kind.upper()} (not followed)", where)
        runs = 1.0 if times is None else self.value(times, block, statement)
        if runs != int(runs) or runs < 1:
            raise OutOfScope(f"{keyword} with P={runs:g} (a whole number of runs, 1 or more)", where)
        backward = keyword == "REPEAT" and end_label is None  # (the label before the REPEAT line)
        start = self._backward(start_label, self.pc - 1)
        if start is None and not backward:
            start = self._forward(start_label)
        if start is None:
            raise OutOfScope(f"{keyword} {start_label}: the label is not found (or no longer held)", where)
        end = start if keyword == "REPEATB" else self.pc - 1 if backward else self._after(start, end_label)
        if end is None:
            raise OutOfScope(f"{keyword}: the end label {end_label} is not found after {start_label}", where)
        self._check_section(keyword, start, end, where)
        blocks = runs * (end - start + 1)
        if blocks > MAX_RERUN - self.rerun:  # (refused before they run, as `steps` would)
            raise NcppError(f"{keyword} P={runs:.15g}: {blocks:,.0f} blocks run again, more than the "
                            f"{MAX_RERUN:,} ncpp follows", Location(self.file, block.line, where))  # fmt: skip
        self.section = _Section(start, end, int(runs), self.pc + 1)
        return start

    def _check_section(self, keyword: str, start: int, end: int, where: int) -> None:
        """Refuse what the section may hold that this flow does not follow: its REPEAT line, a
        control statement or a jump, ENDLABEL; and a backward run over moves compensated where
        they stand (as `_jump`)."""
        if start <= self.pc <= end:
            raise OutOfScope(f"{keyword}: a section that holds its REPEAT line", where)
        for index in range(start, end + 1):
            block = self.buffer[index - self.base]
            if END_LABEL in _destinations(block) and keyword == "REPEAT":
                raise OutOfScope(f"{keyword}: a section with {END_LABEL} (not followed)", where)
        looped = all(index in self.looped for index in range(start, end + 1))  # (a looped block runs FIXED)
        if start <= self.pc and self._ran_in_place() >= start and not looped:
            raise OutOfScope(f"{keyword}: a section of moves compensated where they stand, run again", where)

    def _after(self, start: int, name: str) -> int | None:
        """The first block from `start` on that the label `name` marks."""
        for index in range(start, start + MAX_AHEAD):
            block = self._block(index)
            if block is None:
                return None
            if name in _destinations(block):
                return index
        return None

    def _case(self, block: Block, statement: Statement) -> int:
        expr, branches, default = statement.node
        value = self.value(expr, block, statement)
        for constant, keyword, destination in branches:
            if self.value(constant, block, statement) == value:
                return self._jump(block, statement, keyword, destination)
        return self.pc + 1 if default is None else self._jump(block, statement, *default)

    # -- helpers ---------------------------------------------------------------------
    def _top(self, kind: str, statement: Statement) -> _Open:
        """The structure a closing statement closes: the innermost open one, of its kind."""
        if not self.open or self.open[-1].kind != kind:
            found = f"the {self.open[-1].kind.upper()} open" if self.open else "no open structure"
            raise OutOfScope(
                f"{statement.kind.upper()} with {found} (not {kind.upper()})", statement.start + 1
            )
        return self.open[-1]

    def _match(self, start: int, kind: str, statement: Statement, past_else: bool = False) -> int:
        """The index of the block closing the structure opened at `start` (an IF's ELSE, unless
        `past_else`, or its ENDIF; `start` may be the ELSE), reading ahead as far as it takes."""
        depth = 0
        index = start
        while True:
            index += 1
            if index - start > MAX_AHEAD:
                raise OutOfScope(f"{kind.upper()} with no end in {MAX_AHEAD:,} blocks", statement.start + 1)
            block = self._block(index)
            if block is None:
                raise OutOfScope(f"{kind.upper()} with no {OPENERS[kind].upper()}", statement.start + 1)
            for found in _controls(block):
                if found.kind in OPENERS and not _conditional_jump(block, found):
                    depth += 1
                elif found.kind in CLOSERS:
                    if depth == 0:
                        if found.kind != OPENERS[kind]:
                            raise OutOfScope(
                                f"{kind.upper()} closed by {found.kind.upper()}", statement.start + 1
                            )
                        return index
                    depth -= 1
                elif found.kind == "else" and depth == 0 and kind == "if" and not past_else:
                    return index

    def _jump(self, block: Block, statement: Statement, keyword: str, destination: str) -> int:
        """Where GOTOF, GOTOB, GOTO or GOTOC goes (a destination GOTOC does not find: on)."""
        if self.open:
            raise OutOfScope(f"{keyword} inside {self.open[-1].kind.upper()} (a jump in or out of a control "
                             "structure)", statement.start + 1)  # fmt: skip
        name = destination.upper()
        found = None
        if keyword != "GOTOB":
            found = self._forward(name)
        if found is None and keyword != "GOTOF":
            found = self._backward(name)
        if found is None:
            if keyword == "GOTOC":
                return self.pc + 1
            held = (
                "no longer held (ncpp holds the last blocks only)"
                if self.base > 0 and keyword != "GOTOF"
                else "not found"
            )
            raise OutOfScope(f"{keyword} {destination}, a jump destination {held}", statement.start + 1)
        if found <= self.pc and self._ran_in_place() >= found:  # (a looped block runs FIXED)
            raise OutOfScope(
                f"{keyword} {destination}, a backward jump over moves compensated where they stand",
                statement.start + 1,
            )
        return found

    def _forward(self, name: str) -> int | None:
        return self._after(self.pc + 1, name)

    def _backward(self, name: str, first: int | None = None) -> int | None:
        for index in range(self.pc if first is None else first, self.base - 1, -1):
            if name in _destinations(self.buffer[index - self.base]):
                return index
        return None


def _controls(block: Block) -> list[Statement]:
    """The block's control statements; OutOfScope when more than its block number, labels
    and comments stand beside them."""
    repetition = _repetition(block)
    if repetition is not None:
        return [repetition]
    found = [i for i in block.items if type(i) is Statement and i.kind in CONTROLS]
    if found:
        for item in block.items:
            if not (item in found or type(item) is Comment or (type(item) is Word and item.letter in "N:")
                    or (type(item) is Statement and item.kind == "label")):  # fmt: skip
                raise OutOfScope(f"{found[0].kind.upper()} with more in its block", item.start + 1)
    return found


def _way_out(block: Block) -> bool:
    """Whether the block may end the program or the subprogram, or leave a loop: M2, M17 or M30, a
    jump, or a call (RET, an alarm's SETAL, a subprogram's; a message's MSG and a frame's are none)."""
    for item in block.items:
        if type(item) is Word and item.letter == "M" and item.value in (2.0, 17.0, 30.0):
            return True
        if type(item) is Statement and (
            item.kind in ("goto", "case")
            or item.kind == "call"
            and str(item.node[0]).upper() not in _NO_WAY_OUT
        ):
            return True
    return False


def _conditional_jump(block: Block, statement: Statement) -> bool:
    """`IF condition GOTOx destination`: an IF that opens no structure."""
    controls = _controls(block)
    return statement.kind == "if" and len(controls) == 2 and controls[1].kind == "goto"


def _destinations(block: Block) -> list[str]:
    """The names a jump may reach the block by: its labels and its block number (`N100`, `100`)."""
    names = []
    for item in block.items:
        if type(item) is Statement and item.kind == "label":
            names.append(item.node[0].upper())
        elif type(item) is Word and item.letter == "N":
            names += [f"N{item.number}", item.number]
    return names


def _jumps(statement: Statement) -> list[tuple[str, str]]:
    """The (keyword, destination) pairs of a GOTO or CASE statement."""
    if statement.kind == "goto":
        return [statement.node]
    if statement.kind == "case":
        _, branches, default = statement.node
        return [(keyword, destination) for _, keyword, destination in branches] + (
            [default] if default else []
        )
    return []


def _repetition(block: Block) -> Statement | None:
    """A program section repetition (`REPEAT label P=n`, `REPEAT start end P=n`, `REPEATB label
    P=n`) as one statement of kind SECTION: (keyword, start label, end label or None, P's
    expression or None); None for a block that is none.  OutOfScope for one with more in its block."""
    items = [i for i in block.items if not (type(i) is Comment or (type(i) is Word and i.letter in "N:")
                                            or (type(i) is Statement and i.kind == "label"))]  # fmt: skip
    if not items or type(items[0]) is not Statement:
        return None
    first = items[0]
    if first.kind == "repeat" and len(items) > 1:
        keyword = "REPEAT"
    elif first.kind == "call" and first.node[0].upper() == "REPEATB" and not first.node[1]:
        keyword = "REPEATB"
    else:
        return None
    labels, times = [], None
    for item in items[1:]:
        if type(item) is Statement and item.kind == "call" and not item.node[1] and times is None:
            labels.append(item.node[0].upper())
        elif type(item) is ExprWord and item.letter == "P" and times is None:
            times = item.expr
        elif type(item) is Word and item.letter == "P" and times is None:
            times = ("num", item.value)
        else:
            raise OutOfScope(f"{keyword} with more in its block", item.start + 1)
    if not 1 <= len(labels) <= (1 if keyword == "REPEATB" else 2):
        raise OutOfScope(f"{keyword} with {len(labels)} labels", first.start + 1)
    node = (keyword, labels[0], labels[1] if len(labels) > 1 else None, times)
    return Statement(SECTION, node, first.start, block.items[-1].end)


def is_repetition(block: Block) -> bool:
    """Whether the block repeats a program section (REPEAT, REPEATB: its line runs other blocks)."""
    try:
        return _repetition(block) is not None
    except OutOfScope:
        return False


def _section_before(statement: Statement, seen: dict[str, int], index: int) -> range:
    """The blocks before the REPEAT line at `index` its section runs again (`seen`: where each
    label was first met); empty where the section lies ahead or is not found."""
    keyword, start_label, end_label, _ = statement.node
    start = seen.get(start_label)
    if start is None:
        return range(0)
    if keyword == "REPEATB":
        return range(start, start + 1)
    if end_label is None:
        return range(start, index)
    end = seen.get(end_label)
    return range(start, end + 1) if end is not None and end >= start else range(0)


def _name(statement: Statement) -> str:
    return statement.node[0] if statement.kind == SECTION else statement.kind.upper()
