"""O-word control flow, as LinuxCNC runs it: the order a program's blocks run in.

`Flow.steps(blocks)` reads the blocks once, in order, and yields each block
with what the interpreter is to do with it (`kind`):

* RUN   — execute it in its place in the text;
* FIXED — execute it as part of a loop or a subroutine: its moves are left
  as programmed (a body runs many times from one text);
* ONCE  — execute it in its place, in a loop's first pass: whether its text runs
  again is told by the next block the flow yields (RUN: the loop ended and the
  body ran once, its moves may be rewritten for that run as RUN's; a block run
  again, FIXED: they are left as programmed as FIXED's);
* CALLED — execute it in the first run of a subroutine called from straight code whose
  definition stands after the call, or before it where the program met it in straight code
  (`_runs_once`, `_wait_for_call`): its owner is the call; if no other call runs it before the
  program ends, its text ran once and may be rewritten for that run where it stands
  (`called_again` names the subroutines another call ran);
* SKIP  — write its text; it does not run (an untaken branch, a subroutine's
  definition, a loop that runs no time);
* TEXT  — write its text: a control line this module has executed
  (`o100 if`, `o100 call`), or a line after the program's end.

A subroutine runs where it is called and a loop's second iteration where
its end line sends the program back: out of the text's order.  Their blocks
come again as FIXED with an `owner`, the line whose text the output is at
(the call, the `endwhile`): the interpreter gives their moves to that line,
so that every block's text is written once, where it stands.  Control lines
that run out of the text's order yield nothing.

Fanuc subprograms run the same way: `M98 P<n> [L<repeats>]` calls the
program `O<n>` of the file, or of a file `O<n>` (`O<n>.nc`) on the subroutine path, which
ends with `M99` (#1-#30 are the caller's, as in LinuxCNC; the other scoping is a call's).
A Fanuc or Haas file may hold more programs after the first one's closing `%`, each a program
in the control's memory that a call finds (`Dialect.programs_after_end`); the main program
ends at that `%`, and the text after it runs only where called.  Where a Fanuc or Haas file's
first program ends with M99, its subprograms stand before its main program: the one later program
that ends with M30 or M2 runs as the main one, and those before it only where called
(`_stored_first`).

Haas's local subprograms run the same way (`_m97`): `M97 P<n> [L<repeats>]` runs the blocks of
the program's own text from the one numbered Nn to its M99, then goes on after the call (Haas
Mill Operator's Manual 96-8000 and its NGC edition, M-codes, "M97 Local Sub-Program Call": "a
subroutine referenced by a line number (N) within the same program", which "must end with an
M99"; "Lnn ... repeats the subprogram call nn times", 1-99; "The subprogram is within the body
of the main program, placed after the M30").  Nn is searched forward from the call; a block Nn
before the call makes the call out of scope (which of them the control runs is not ncpp's to
guess), and so does a local call in a program M98 or G65 calls (its own text).

Fanuc macro B runs here too (the Fanuc operator's manuals, Series 16i/18i B-63684EN and 0i,
"Custom macro": "Branch and repetition", "Macro call"):

* `GOTO n`, `IF [cond] GOTO n` (n an expression: `GOTO#10`) jump to the block with
  sequence number Nn, searched forward from the jump, then from the program's (or the
  subprogram's) top; a number 1-99999 that is there, else the control alarms; a subprogram's
  search goes on past its first M99 to the next program number or `%` (`_rest_of_program`);
* `WHILE [cond] DOm` ... `ENDm`, m = 1, 2 or 3 (`WH` for `WHILE`: Series 0i-D B-64304EN,
  "Abbreviations of custom macro words"): the body runs while the condition
  holds, loops nest (each its own m) and do not cross (else alarms); a GOTO may
  leave a loop, not enter one;
* `G65 P<n> L<count> <arguments>` calls `O<n>` as a macro (`_g65`): a new level of local
  variables #1-#33, argument specification I (A #1, B #2, C #3, I #4, J #5, K #6, D #7,
  E #8, F #9, H #11, M #13, Q #17, R #18, S #19, T #20, U #21, V #22, W #23, X #24,
  Y #25, Z #26), the others vacant; M99 returns.  With L the macro runs again with the
  locals it left (as Haas, a Fanuc-compatible control, documents);
* argument specification II (`_argument_variables`): A, B, C as in I and up to ten sets of
  I J K, the n-th set #(3n+1) #(3n+2) #(3n+3), so I J K may repeat in a G65 or G66 block
  (and only there).  The sets are counted in the order written, a letter not after the
  last of its set opening the next, and the n-th I (J, K) written is the n-th set's: a
  block these two readings place apart (`J1 I2`, `I1 J2 I3 K4`) is not guessed at, it
  leaves the scope.  Both specifications in one block: "the type of argument specification
  specified later takes precedence" for a variable both set (B-63684EN, "Mixture of argument
  specifications I and II": `G65 A1.0 B2.0 I-3.0 I4.0 D5.0 P1000` leaves #7 = 5.0);
* `G66 P<n> <arguments>` ... `G67`: the macro is called so after each block that moves
  (the interpreter says which: `moved`), not after its own moves (`_g66`).

A backward jump runs the blocks from its target again, out of the text's order.  The
first `_TRIM` blocks are read ahead at the start to find the literal backward jumps
among them: their bodies run FIXED from their first pass, as loops.  Past them, a
backward jump over a move that ran in place (RUN: its text may be rewritten for that one
run) leaves the scope, and so does one whose target is no longer held (blocks are held
to `_TRIM` back, and while a loop runs).

Subroutines are those of the program's own text (defined before or after the
call, like LinuxCNC, which searches the rest of the file: here up to MAX_AHEAD blocks
ahead) or `name.ngc` in the first folder of the search path that has it (`_from_file`:
LinuxCNC's [RS274NGC]SUBROUTINE_PATH, given as `--subroutine-path`; looked for before
the rest of the file); a call of a subroutine found in neither is outside the scope.
Blocks stay in memory only while a loop may go back to them, or a search ahead holds
them, and subroutine bodies for the call.
"""

from __future__ import annotations

import os
import re
from collections.abc import Callable, Iterable, Iterator, Sequence
from dataclasses import dataclass, field, replace
from pathlib import Path

from ncpp.errors import Location, NcppError, printable
from ncpp.motion.endless import Journal, Revisits, endless, exact, never_changes, without_way_out
from ncpp.motion.expressions import SUBROUTINE_PARAMETERS, normalise_name, round_half_away, vacant
from ncpp.motion.modal import OutOfScope
from ncpp.motion.once import OnceRuns
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word
from ncpp.program.parser import parse_stream

RUN, FIXED, ONCE, CALLED, SKIP, TEXT = "run", "fixed", "once", "called", "skip", "text"
_TRIM = 4096  # blocks no loop can go back to are dropped in runs of this many
# Blocks after an `O<n>` line kept as Fanuc subprogram `n` until its M99: a longer one is a
# program's own number (`O1000` at its top), not a subprogram, and memory stays bounded.
MAX_SUBPROGRAM = 20_000
# Blocks read ahead to find a subroutine, a subprogram or a Haas local subprogram a call names that
# the program defines after it: past them the call is out of scope (memory stays bounded)
MAX_AHEAD = 200_000
# Lines run (or skipped) out of the text's order, loop iterations and calls, before a program
# counts as one that never ends and is refused (LinuxCNC would run it for ever; a pass over it
# must end): about a minute
MAX_RERUN = 5_000_000
# Subroutine levels (o-word calls and M98 together) as rs274ngc counts them: the tenth call is refused
MAX_CALL_LEVELS = 10
# Fanuc argument specification I: the local variable each letter of a G65 block sets
MACRO_ARGUMENTS = {"A": 1, "B": 2, "C": 3, "I": 4, "J": 5, "K": 6, "D": 7, "E": 8, "F": 9, "H": 11,
                   "M": 13, "Q": 17, "R": 18, "S": 19, "T": 20, "U": 21, "V": 22, "W": 23, "X": 24,
                   "Y": 25, "Z": 26}  # fmt: skip
# Fanuc argument specification II: I J K in sets, #4-#6 the first, #31-#33 the tenth
IJK_SETS = 10
_FANUC_FLOW = {"goto": "goto", "if": "fanuc_if", "while": "fanuc_while", "end": "fanuc_end"}
_MACRO_CALLS = {65.0: "g65", 66.0: "g66", 67.0: "g67"}
_CALLS = {97.0: "m97", 98.0: "m98"}  # M97: Haas's local call, a control line only where the flow reads it
MAX_SEQUENCE_NUMBER = 99_999


@dataclass
class MainProgram:
    """Which of a file's numbered programs the control runs as the main one, as the flow decides it
    before it yields the file's first block (`Flow._stored_first`): the one after `stored` programs
    stored before it, numbered `number` (`program_number`); `stored` 0: the file's first program (or
    a file of none), None: not decided (the file's first program ends with M99 and which later one
    runs is not ncpp's to guess).  The placement guard goes after the main program's O line
    (`guard.with_guard`)."""

    stored: int | None = 0
    number: str | None = None


@dataclass(frozen=True, slots=True)
class Control:
    """The o-word of a control line: `o100 while [#1 LT 3]` is ("100", "while", (expr,))."""

    name: (
        str | tuple | None
    )  # a tuple: `o[expr]`, an expression evaluated where the line runs; None: M98, M99
    keyword: str  # sub, call, while, ...; m97-m99; goto, fanuc_if, fanuc_while, fanuc_end; g65, g66, g67
    arguments: tuple  # expressions; M97's and M98's P and L words; G65's and G66's P, L and argument words
    item: Statement | Word | ExprWord  # where messages point


@dataclass
class _Label:
    """A loop's opening line, where its end (and `continue`) send the program back."""

    kind: str  # while, do, repeat; fanuc (WHILE ... DOm)
    start: int  # the line's index in its frame's space
    count: int = -1  # repeat: iterations still to run (-1: not counted yet)
    total: int = 0  # repeat: its iterations, all told
    mark: int | None = None  # repeat: `CountedPasses.ended`'s mark
    checked: bool = False  # while: whether it may end was looked at (`Flow._refuse_without_way_out`)


@dataclass
class _Frame:
    """A level of calls: the main program (space None: the stream) or a subroutine's body."""

    space: list[Block] | None
    pc: int  # the next block to run: an index into the space (the main program: a line number from 0)
    labels: dict[str, _Label] = field(default_factory=dict)  # its loops under way
    ifs: set[str] = field(
        default_factory=set
    )  # the if chains it has started (their elseif, else and endif may follow)
    # Per label, (index, keyword, line) of the first if, while, repeat or do it ran: rs274ngc
    # refuses a label that opens one of these at another line (`_opens`)
    opened: dict[str, tuple[int, str, int]] = field(default_factory=dict)
    # a Fanuc subprogram (M98, G65): the runs still to make after this one; -1: an o-word call
    repeats: int = 0
    runs: int = 0  # a Fanuc subprogram's runs, all told (M98's or G65's L)
    mark: int | None = None  # its runs: `CountedPasses.ended`'s mark (set at the call: its first run counts)
    source: str | None = None  # the subroutine file its lines are from (None: the program's)
    macro: bool = False  # a Fanuc G65 macro call (its own level of local variables)
    modal: bool = False  # a macro G66 calls after a move
    called: str | None = None  # a run that may be its subroutine's only one: its name (`_runs_once`)
    local: bool = False  # a Haas local subprogram (M97): its space starts with its Nn block, which runs


class CountedPasses:
    """The passes of counted loops (LinuxCNC's repeat, Klartext's CALL LBL REP, Sinumerik's FOR), each
    measured in blocks stepped through: a loop whose passes still to run, each as long as the one just
    ended, would run more than MAX_RERUN lines again is refused at once, at its line, not after them.
    So is a counted loop around it whose passes, each a whole run of the inner loop, would: at its
    own line, as soon as the inner loop's first pass has shown its length, not after that run."""

    def __init__(self, file: str):
        self.file = file
        self.steps = 0  # blocks the flow stepped through (in place or again): its flow counts them

    def ended(self, mark: int | None, rerun: int, left: int, line: int | None, what: str,
              file: str | None = None, around: Callable[[], list[Around]] | None = None,
              total: int = 0) -> int:  # fmt: skip
        """A loop ended a pass with `rerun` lines run again so far and `left` passes to run; `mark` is
        what this returned when its previous pass ended (None: this is its first).  Returns the mark.
        `file`: where `line` is, where not the program's.  `around()`: the counted loops around it,
        innermost first, given with the pass that first shows its length (`total`: its passes)."""
        if mark is not None:
            length = self.steps - mark
            if rerun + length * left > MAX_RERUN:
                raise NcppError(
                    f"{what} would run {left:,} more passes of {length:,} blocks: more than "
                    f"{MAX_RERUN:,} lines run again, taken for a loop that does not end",
                    Location(file or self.file, line, 1),
                )
            if around is not None:
                self._around(around(), length * total, rerun)
        return self.steps

    def _around(self, loops: list[Around], run: int, rerun: int) -> None:
        """Refuse the first of the counted `loops` around a loop whose runs (`run` blocks each, one a
        pass of the next loop out) would make more than MAX_RERUN lines run again."""
        for loop in loops:
            if rerun + run * loop.left > MAX_RERUN:
                raise NcppError(
                    f"{loop.what} would run {loop.left:,} more passes of about {run:,} blocks each (the "
                    f"loops inside it run through): more than {MAX_RERUN:,} lines run again, taken for a "
                    "loop that does not end",
                    Location(loop.file or self.file, loop.line, 1),
                )
            run *= max(loop.total, 1)


@dataclass(frozen=True)
class Around:
    """A counted loop under way around another (`CountedPasses.ended`): its passes still to run
    after the one under way, all its passes, its line (in `file`, None: the program's)."""

    left: int
    total: int
    line: int | None
    what: str
    file: str | None = None


@dataclass(frozen=True)
class _ModalCall:
    """G66 in effect: the macro it calls after each move of the frame at `depth`."""

    body: list[Block]
    runs: int
    values: dict[int, float]
    depth: int  # the index in `Flow.frames` of the frame that gave G66


class Flow:
    """The blocks of a program in the order they run (see the module docstring).

    `evaluate(expr, block, item)` is the interpreter's (its parameters, its
    errors); `parameters` gets `enter(args)` and `leave(value)` at calls and
    returns; `done()` says the program has ended (M2, M30, or a construct
    outside the interpreter's scope), after which the rest is text;
    `stop(reason, block, col)` ends it where the flow leaves the scope;
    `path`: the folders of subroutine files; `state()`: the interpreter's state but for the
    parameters (`endless.exact`; None where it cannot be told) and `position()` a cheap part of
    it, with which a loop that comes back to the state it had is refused (`endless.py`; None:
    only at MAX_RERUN)."""

    def __init__(
        self,
        file: str,
        evaluate: Callable,
        parameters,
        done: Callable[[], bool],
        stop: Callable,
        path: Sequence[Path] = (),
        state: Callable[[], object] | None = None,
        position: Callable[[], object] = lambda: None,
        repeats_in_p: bool = False,
        once: OnceRuns | None = None,
        local_calls: bool = False,
        main_after_subprograms: bool = False,
        warn: Callable[[str, Block], None] | None = None,
        main_program: MainProgram | None = None,
    ):
        self.file, self.evaluate, self.parameters, self.done, self.stop, self.path = (
            file,
            evaluate,
            parameters,
            done,
            stop,
            tuple(path),
        )
        self.files: dict[str, str] = {}  # subroutine name -> the file it was read from
        self.program_files: dict[str, str] = {}  # Fanuc program number -> the file it was read from
        self.buffer: list[Block] = []  # main-program blocks read and still wanted, from line `base`
        self.base = 0
        self.read = 0  # main-program blocks read from the stream
        self.written = 0  # main-program blocks yielded in text order (the next one written is this)
        self.owner: Block | None = None  # the last block yielded in text order
        self.subroutines: dict[str, list[Block]] = {}  # name -> its lines, `sub` to `endsub`
        self.subprograms: dict[str, list[Block]] = {}  # Fanuc: number -> its lines, `O<n>` to `M99`
        self.defined_at: dict[
            str, int
        ] = {}  # subroutine name -> the line of the definition the program met (run or called)
        self._definitions: dict[
            int, list[Block]
        ] = {}  # every o-word definition read, by the line of its `sub`
        self._defining: tuple[dict, str, list[Block]] | None = (
            None  # a definition being read: where it goes, its name, lines
        )
        self.frames = [_Frame(None, 0)]
        self.stream: Iterator[Block] = iter(())
        # rs274ngc's state, global as there (its quirks come with it: a `break` out of a while loop
        # stops the next do-while end from looping, a `continue` in a do loop makes the next
        # skipped-to endwhile loop once more)
        self.skipping: str | None = None  # the o-word the lines up to its next line are skipped for
        self.executed_if = False  # a branch of the if chain under way has run
        self.doing_break = self.doing_continue = False
        self.rerun = 0  # blocks run out of the text's order so far
        self.passes = CountedPasses(file)
        # Control lines of the blocks held (a loop goes over them again and again), by id: an
        # entry leaves with its block (`_drop`), so an id is never that of another block
        self._controls: dict[int, Control | None] = {}
        self.dropped: set[int] = set()  # sequence numbers of main-program blocks no longer held
        self.looped: set[int] = set()  # main-program lines a backward GOTO read ahead runs again
        self.last_run_move = -1  # the text line of the last move run in place (RUN): the interpreter's
        self.once_move = -1  # and of a loop's first pass (ONCE) not yet told: it may be rewritten too
        # A Fanuc macro program: a macro statement or G65 among the blocks read ahead (which
        # LinuxCNC refuses; its M98, M99 and O numbers may be LinuxCNC's): its locals start
        # vacant, #1000 and up are the control's system variables, #3000 an alarm
        self.fanuc = False
        self.modal: _ModalCall | None = None  # G66 in effect
        self.moved = False  # the interpreter's: the block just run moved (under G66)
        self._fault: NcppError | None = None  # the parser's, met reading ahead (`_raise_fault`)
        # A Fanuc subprogram's lines to the next program number (`_rest_of_program`), by the id of
        # its lines to its first M99 (kept in `subprograms`, so an id is never another's)
        self._whole_programs: dict[int, list[Block]] = {}
        # The verbatim blocks the text starts with: a Fanuc tape leader (`parser._leader`, within
        # the blocks read ahead); a verbatim block after them stands after the closing `%`
        self.leader = 0
        self.repeats_in_p = repeats_in_p  # Fanuc: `M98 P51002` runs O1002 five times (`_m98`)
        # Haas: `M97 P<n>` runs the program's own blocks from Nn to M99 (`_m97`); the main program's
        # sequence numbers are noted (`dropped`, `_numbered_before`) to tell a block Nn before a call
        self.local_calls = local_calls
        self.locals: dict[str, list[Block]] = {}  # "N<n>" -> the local subprogram's lines, Nn to M99
        self._first_numbered: dict[int, int] = {}  # sequence number -> its first main-program line looked at
        self._numbers_read = 0  # the main-program lines looked at so far for `_first_numbered`
        self.once = once  # the subroutines whose first run may be CALLED (`_runs_once`; None: none)
        # definitions met before any call of them that wait for it (`_wait_for_call`): name -> lines
        self.ahead: dict[str, list[Block]] = {}
        self.ran: set[str] = set()  # the subroutines a call has run (o-word calls, M98, G65, G66)
        self.called_again: list[str] = []  # the CALLED subroutines another call has run since told
        self.once_called: set[str] = set()  # the subroutines whose first run was CALLED
        # Fanuc: a file whose first program ends with M99 runs a later one as the main program
        # (`_stored_first`); `stored`: the lines yielded are the programs' before it, `main_top` its O line
        self.main_after_subprograms = main_after_subprograms
        self.main_program = main_program if main_program is not None else MainProgram()  # (what is decided)
        self.warn = warn or (lambda message, block: None)
        self.stored = False
        self.main_top = 0
        self.cut_short = False  # a search for a definition stopped at MAX_AHEAD blocks (`_defined`)
        self.revisits: Revisits | None = None
        self._jumps_checked: set[tuple[int, int, int]] = set()  # (`_refuse_jump_without_way_out`)
        if state is not None:
            parameters.journal = Journal()
            self.revisits = Revisits(parameters.journal, parameters.entry, position,
                                     lambda: self._with_flow(state()))  # fmt: skip

    # -- the stream ------------------------------------------------------------
    def steps(self, blocks: Iterable[Block]) -> Iterator[tuple[Block, str, Block | None]]:
        """(block, kind, owner): see the module docstring; owner is None but for
        blocks that run out of the text's order."""
        self.stream = iter(blocks)
        main = self.frames[0]
        block: Block | None
        self._read_ahead()
        if self.fanuc or self.parameters.fanuc:  # (a macro program, or any read as Fanuc's or Haas's)
            self.parameters.start_fanuc()
        if self.main_after_subprograms:
            yield from self._stored_first()
        while not self.done():
            frame = self.frames[-1]
            if (
                frame is main
                and main.pc == self.read
                and not main.labels
                and self.skipping is None
                and self._defining is None
                and self.modal is None
            ):
                # the common case, nothing read ahead and no loop to go back to: straight from the
                # stream (a Fanuc program's last blocks held for a backward GOTO; a Haas program's
                # sequence numbers noted for its local calls, `_numbered_before`)
                buffer, hold, numbered, dropped = self.buffer, self.fanuc, self.local_calls, self.dropped
                self._raise_fault()
                if not hold:
                    self._drop(len(buffer))
                for block in self.stream:
                    signature = block.signature
                    if (
                        signature is None
                        or "M" in signature
                        or "O" in signature
                        or "P" in signature
                        or "G6" in signature
                    ) and (block.verbatim or _notable(block)):
                        if not hold:
                            self.base = self.read
                        self._keep(block)
                        break
                    if hold:
                        buffer.append(block)
                        if len(buffer) > 2 * _TRIM:
                            self._drop(_TRIM)
                    elif numbered and (signature is None or "N" in signature):
                        number = sequence_number(block)
                        if number is not None:
                            dropped.add(number)
                    self.owner, self.read = block, self.read + 1
                    self.written = main.pc = self.read
                    yield block, RUN, None
                    if self.done():
                        break
                else:
                    return
                continue
            block = self._block(frame, frame.pc)
            if block is not None and block.verbatim and frame.space is None and frame.pc >= self.leader:
                break  # past the closing `%`: the programs after it run only when called
            if block is None:  # the end of the text (a subroutine's ends with its endsub)
                if frame.space is not None:  # skipped past its endsub
                    skipped = self.skipping or ""
                    raise NcppError(
                        f"WHILE ... {skipped} has no END{skipped[2:]} in its subprogram"
                        if skipped.startswith("DO")
                        else f"o{_shown(skipped)} is not closed in its subroutine",
                        Location(self.file, frame.space[-1].line, None),
                    )
                return  # LinuxCNC too ends a program whose file ends, in a loop or skipping
            self.passes.steps += 1
            if not self._in_place(frame):
                self.rerun += 1
                if self.rerun > MAX_RERUN:
                    line = self.owner.line if self.owner is not None else block.line
                    raise NcppError(f"a loop that does not end: {MAX_RERUN:,} lines run again (the control would run "
                                    "it for ever; ncpp follows a program to its end)", Location(self.file, line, 1))  # fmt: skip
            control = self._control_of(block)
            if self.skipping is not None and (
                control is None or control.name != self.skipping
            ):  # (M98, M99: None)
                if self._in_place(frame):
                    yield block, SKIP, None
                self._advance(frame)
                continue
            if control is None:
                yield block, *self._kind(frame)
                self._advance(frame)
                if self.moved:
                    self.moved = False
                    self._modal_call(block)
                continue
            yield from self._control(frame, block, control)
        yield from self._rest()

    def _kind(self, frame: _Frame) -> tuple[str, Block | None]:
        if self._in_place(frame):
            if frame.pc in self.looped:
                return FIXED, None
            return (ONCE if frame.labels else RUN), None
        return (CALLED if frame.called is not None else FIXED), self.owner

    def _runs_once(self, frame: _Frame, block: Block, name: str, body: list[Block], runs: int,
                   first: int = 1) -> bool:  # fmt: skip
        """Whether a call may be its subroutine's only run, whose text may then be rewritten for
        it where the definition stands: one run, called from the main program's straight code in its
        place, the subroutine's first, defined in the program's own text after the call (where the
        program's end comes before its text is written) or before it, met in straight code
        (`_wait_for_call`: the writer holds its text), with no control line in its body (no
        loop, branch, call or return: each of its lines runs once, in order).  `first`: the index of
        its first line that runs (a Haas local subprogram's Nn line runs, an `O<n>` or `sub` line not)."""
        return (
            self.once is not None
            and self.once.may_run_once(name)
            and runs == 1
            and frame.space is None
            and len(self.frames) == 1
            and not frame.labels
            and self.modal is None
            and self._in_place(frame)
            and frame.pc not in self.looped
            and name not in self.ran
            and name not in self.files
            and self._source_of(body) is None
            and (body[0].line > block.line or self.ahead.get(name) is body)
            and all(self._control_of(b) is None for b in body[first:-1])
        )

    def _once(self, name: str, once: bool) -> str | None:
        """The `called` of a run (`_runs_once`): its name where it may be the only one."""
        if not once:
            return None
        self.once_called.add(name)
        return name

    def _count_call(self, name: str) -> None:
        """A run of subroutine `name` starts: a CALLED one's text runs again."""
        if name in self.ran and name in self.once_called:
            self.called_again.append(name)
        self.ran.add(name)

    def in_straight_code(self) -> bool:
        """Whether the program runs its main text with no loop under way (none can go back)."""
        return len(self.frames) == 1 and not self.frames[0].labels

    def _in_place(self, frame: _Frame) -> bool:
        return frame.space is None and frame.pc == self.written

    def _advance(self, frame: _Frame) -> None:
        if self._in_place(frame):
            self._wrote(frame.pc)
        frame.pc += 1

    def _wrote(self, line: int) -> None:
        self.owner = self.buffer[line - self.base]
        self.written = line + 1
        if len(self.buffer) > 2 * _TRIM and not self.frames[0].labels:
            keep = self.written - self.base  # nothing before the next block is read again
            if not self.fanuc and keep > _TRIM:
                self._drop(keep)
            elif keep > 2 * _TRIM:  # but by a Fanuc backward GOTO: the last _TRIM held
                self._drop(keep - _TRIM)

    def _drop(self, n: int) -> None:
        """The first `n` blocks of the buffer, no longer wanted (the sequence numbers of the main program's
        noted: those of programs stored before it, `main_top`, are theirs)."""
        for index, block in enumerate(self.buffer[:n], self.base):
            self._controls.pop(id(block), None)
            number = sequence_number(block) if self.fanuc or self.local_calls else None
            if number is not None and index >= self.main_top:
                self.dropped.add(number)
        del self.buffer[:n]
        self.base += n

    def _read_ahead(self) -> None:
        """The first `_TRIM` blocks, read ahead: the lines a literal backward GOTO among them
        goes back over are `looped` (they run again; their first pass is FIXED too)."""
        first: dict[int, int] = {}  # sequence number -> its first line (index)
        while self.read < _TRIM:
            try:
                if not self._read():
                    break
            except NcppError as fault:  # (raised where the flow reaches its line)
                self._fault = fault
                break
            index = self.read - 1
            block = self.buffer[index]
            if block.verbatim and index == self.leader:
                self.leader += 1
            number = sequence_number(block)
            if number is not None:
                first.setdefault(number, index)
            elif program_number(block) is not None:  # another program (a macro after M30): its own numbers
                first.clear()
            control = self._control_of(block)
            if (
                control is not None
                and control.keyword in ("g65", "g66")
                or block.signature is None
                and _macro_b(block)
            ):
                self.fanuc = True
            if control is None or control.keyword not in ("goto", "fanuc_if"):
                continue
            target = control.arguments[-1]
            if target[0] == "num":
                start = first.get(int(round_half_away(target[1])))
                if start is not None:  # (a forward one the search finds first: FIXED too, which is safe)
                    self.looped.update(range(start, index + 1))

    def _control_of(self, block: Block) -> Control | None:
        key = id(block)
        try:
            return self._controls[key]
        except KeyError:
            found = control_of(block)
            if found is not None and found.keyword == "m97" and not self.local_calls:
                found = None  # (Haas's call: elsewhere the interpreter reads the line)
            self._controls[key] = found
            return found

    def _nothing_after(self, block: Block, control: Control) -> None:
        """rs274ngc reads nothing after an o-word's arguments but a comment (`o1 if [1] G1 X1`
        would otherwise run the if and drop the move)."""
        items = block.items
        for item in items[items.index(control.item) + 1 :]:
            if type(item) is not Comment:
                raise NcppError(
                    "Unexpected character after O-word", Location(self.file, block.line, item.start + 1)
                )

    def _rest(self) -> Iterator[tuple[Block, str, Block | None]]:
        """After the program's end: every block not yet written, as text."""
        for line in range(self.written, self.read):
            yield self.buffer[line - self.base], TEXT, None
        self.buffer.clear()
        self._raise_fault()
        for block in self.stream:
            yield block, TEXT, None

    def _block(self, frame: _Frame, index: int) -> Block | None:
        """The frame's block at `index` (None: past the end)."""
        if frame.space is not None:
            return frame.space[index] if index < len(frame.space) else None
        while index >= self.read:
            if not self._read():
                return None
        return self.buffer[index - self.base]

    def _read(self) -> bool:
        """Read the next main-program block (False: the stream has ended); subroutine
        definitions are kept as they go by, for calls before and after them."""
        self._raise_fault()
        block = next(self.stream, None)
        if block is None:
            return False
        self._keep(block)
        return True

    def _raise_fault(self) -> None:
        """The parser's error the read-ahead met, where the flow reaches its line: an error of
        an earlier line is reported first, as without reading ahead."""
        fault, self._fault = self._fault, None
        if fault is not None:
            raise fault

    def _keep(self, block: Block) -> None:
        """A main-program block read: in the buffer, and in the definition being read."""
        self.buffer.append(block)
        self.read += 1
        control = self._control_of(block)
        number = program_number(block) if control is None else None
        starts = number is not None or (control is not None and control.keyword == "sub")
        if self._defining is not None and not (starts and self._defining[0] is self.subprograms):
            self._extend_definition(block, control)
        elif starts:  # (a Fanuc definition under way was a program's own number; else a sub's control, named)
            name = control.name if number is None else number  # type: ignore[union-attr]
            self._defining = (self.subroutines if number is None else self.subprograms, name, [block])  # type: ignore[assignment]

    def _extend_definition(self, block: Block, control: Control | None) -> None:
        found, name, lines = self._defining  # type: ignore[misc]
        lines.append(block)
        fanuc = found is self.subprograms
        if control is not None and (
            control.keyword == "m99" if fanuc else control.keyword == "endsub" and control.name == name
        ):
            found.setdefault(
                name, lines
            )  # the first definition counts, until the program meets another (`_sub`)
            if not fanuc:
                self._definitions[lines[0].line] = lines
            self._defining = None
        elif fanuc and (len(lines) > MAX_SUBPROGRAM or _starts_program(block)):
            self._defining = None  # a program's own number (or one ended by `%`), not a subprogram

    # -- control lines -----------------------------------------------------------
    # _NAMED: an o-word line's handler sees its name as a str (`_control` evaluates `o[expr]`
    # first; None is M98's and M99's, whose handlers use no label)
    def _control(
        self, frame: _Frame, block: Block, control: Control
    ) -> Iterator[tuple[Block, str, Block | None]]:
        """Run one control line: decide (errors point at it), write it, then jump."""
        if control.keyword not in ("m97", "m98", "m99", "g65", "g66", "g67"):
            self._nothing_after(block, control)
        try:
            jump = self._decide(frame, block, control)
        except OutOfScope as leaving:  # (`IF [#1005 EQ 0]`: a value ncpp is not told decides)
            self.stop(leaving.reason, block, leaving.col)
            jump = _nothing
        if self._in_place(frame):
            yield block, (SKIP if control.keyword == "sub" else TEXT), None
            self._wrote(frame.pc)
        result = jump()
        if result is not None:
            yield from result

    def _decide(self, frame: _Frame, block: Block, control: Control):
        """Evaluate and check a control line: a function that moves the frame(s) on, or a
        generator doing so."""
        if type(control.name) is tuple:
            value = self.evaluate(control.name, block, control.item)
            control = Control(
                str(int(round_half_away(value))), control.keyword, control.arguments, control.item
            )
        act = getattr(self, "_" + control.keyword)
        arrived, self.skipping = self.skipping is not None, None  # (skipping to this line: it runs)
        return act(frame, block, control, arrived)

    # Each handler decides (evaluates, checks) and returns what moves the program on, run once
    # the line is written; `arrived`: the program was skipping to this line (rs274ngc's skipping_o).
    def _sub(self, frame, block, control, arrived):
        """A definition in the way: it does not run (its lines are text).  As rs274ngc, another
        definition of a name the program has met is refused."""
        if frame.space is None:
            first = self.defined_at.setdefault(control.name, -1)  # (-1: none before)
            if first == block.line:  # called ahead of it, or met in a loop before
                raise self._error(
                    "sub found in illegal location: the program met this definition before (a call ahead of it, a loop)",
                    block,
                    control,
                )
            if first != -1:
                raise self._error(f"sub redefines the subroutine defined in line {first}", block, control)
            self.defined_at[control.name] = block.line
            self._wait_for_call(frame, block, control.name)

        def skip():
            yield from self._skip_definition(frame, control.name)
            met = self._definitions.get(block.line) if frame.space is None else None
            if (
                met is not None
            ):  # rs274ngc calls the definition the program met (one in an untaken branch it did not)
                self.subroutines[control.name] = met

        return skip

    def _wait_for_call(
        self, frame: _Frame, block: Block, name: str, lines: list[Block] | None = None
    ) -> None:
        """A definition the main program's straight code meets before any call of it, whose lines
        (read ahead to its endsub, at most `held_most`; a Fanuc program's, `O<n>` to M99, given)
        hold no control line: if the program calls it once, its run may be written here
        (`OnceRuns.meet`: the writer holds the lines from here on until the run is told).  Whether
        it is called once is known only at the program's end."""
        once = self.once
        if (
            once is None
            or not once.may_run_once(name)
            or not self.in_straight_code()
            or not self._in_place(frame)
            or self.modal is not None
            or frame.pc in self.looped
            or name in self.ran
            or name in self.files
        ):
            return
        index = frame.pc
        while lines is None and index - frame.pc < once.held_most:
            if (lines := self._definitions.get(block.line)) is None:
                index += 1
                if self._block(frame, index) is None:
                    return
        if lines is None or lines[0] is not block or any(self._control_of(b) for b in lines[1:-1]):
            return
        self.ahead[name] = lines
        once.meet(name, lines)

    def _stored_first(self) -> Iterator[tuple[Block, str, Block | None]]:
        """Fanuc: a file whose first program ends with M99 before any M30 or M2 holds subprograms
        before its main program, the one later program that ends with M30 or M2 (a control stores
        each program of a file as its own, and the operator runs the main one; Fanuc Series 0i-MC
        operator's manual, B-64124EN, "Subprogram (M98, M99)": a subprogram ends with M99).  The
        programs before it are yielded as definitions that do not run (SKIP, `stored`), each
        waiting for a call that may be its only run (`_wait_for_call`), and the flow goes on at the
        main program's O line.  Where no later program, or more than one, ends with M30 or M2, or one
        before it ends with neither, which program runs is not guessed: the flow stops at the first.
        A file of one program ending with M99 is an endless main program (`_m99`).

        The text is read ahead to its end, or to MAX_SUBPROGRAM blocks past the main program's O line
        (memory stays bounded): past them the program the blocks read make the main one runs so, and
        the rest of the text is checked as it is read (`_confirmed`): where it makes another program
        the main one, or none, the program is refused."""
        first = self._first_subprogram()
        if first is None:
            return
        scan, cut = self._programs(first)
        programs = scan.found
        if len(programs) == 1 and cut is None:
            return
        main, why = _main_program(scan.provisional() if cut is not None else programs)
        if cut is not None and main is None and not scan.open and scan.candidate() is None:
            why = f"the text after {programs[-1].name}'s M99 runs on past {MAX_SUBPROGRAM:,} blocks"
        if main is None:
            self.main_program.stored = None
            self.stop(f"a file whose first program {programs[0].name} ends with M99 (a subprogram) while {why} "
                      "(which program the operator runs as the main one is not ncpp's to guess)",
                      self._block(self.frames[0], first), 1)  # fmt: skip
            return
        if cut is not None:
            for index in range(cut, self.read):  # (the blocks read past the scan's end)
                scan.add(index, self.buffer[index - self.base])
            self.stream = self._confirmed(scan, self.stream, main)
        names = [p.name for p in programs if p.index < main.index]
        said = (
            f"{names[0]} is a subprogram"
            if len(names) == 1
            else f"{', '.join(names[:-1])} and {names[-1]} are subprograms"
        )
        self.warn(f"the file's first program ends with M99: ncpp runs {main.name} as the main program; {said} "
                  "(run where M98 or G65 calls it)", main.block)  # fmt: skip
        self.main_program.stored, self.main_program.number = len(names), program_number(main.block)
        yield from self._skip_stored(first, main.index)

    def _confirmed(self, scan: _ProgramScan, blocks: Iterator[Block], main: _Program) -> Iterator[Block]:
        """The blocks after those read ahead, each told to `scan`: at the end of the text, the programs
        it found must make `main` the main program (`_main_program`), else the program is refused
        (its compensated lines were written for a main program the file does not name)."""
        index = self.read
        for block in blocks:
            scan.add(index, block)
            index += 1
            yield block
        found, why = _main_program(scan.found)
        if found is None or found.index != main.index:
            said = why or f"{found.name} is the main program"  # type: ignore[union-attr]
            raise NcppError(f"ncpp ran {main.name} as the main program, from the first {MAX_SUBPROGRAM:,} blocks after "
                            f"its O line, but the file goes on and {said} (which program the operator runs as the main "
                            "one is not ncpp's to guess): put the main program first, or each subprogram in a file "
                            "of its own (--subroutine-path)", Location(self.file, main.block.line, 1))  # fmt: skip

    def _skip_stored(self, first: int, main_index: int) -> Iterator[tuple[Block, str, Block | None]]:
        """The lines before the main program's O line: the leader and comments before `first` run,
        the programs from it on are text that does not run, each a definition a call may run once."""
        main = self.frames[0]
        self.stored = True
        while main.pc < main_index:
            block = self._block(main, main.pc)
            assert block is not None  # (read by `_programs`)
            number = program_number(block)
            if number is not None and main.pc >= first:
                lines = self.subprograms.get(number)
                if lines is not None and lines[0] is block:
                    self._wait_for_call(main, block, number, lines)
            yield block, (RUN if main.pc < first else SKIP), None
            self._advance(main)
        self.stored = False
        self.main_top = main_index

    def _first_subprogram(self) -> int | None:
        """Where the file's first program starts (its O line) if only the tape's leader, `%` and
        comments stand before it and it ends with M99 within MAX_SUBPROGRAM blocks, before any M30
        or M2 (a subprogram, as `_keep` tells them), else None."""
        main, index = self.frames[0], 0
        while (block := self._block(main, index)) is not None and index < MAX_SUBPROGRAM:
            if block.verbatim and index >= self.leader:
                return None
            if program_number(block) is not None:
                end = self._program_end(index, MAX_SUBPROGRAM)[0]
                return index if end == "M99" else None
            if index >= self.leader and not _no_code(block):
                return None
            index += 1
        return None

    def _programs(self, first: int) -> tuple[_ProgramScan, int | None]:
        """The numbered programs of the file from the one at `first` on (the text is read to its end, as
        a call of a subprogram after M30 reads on to it), and where the reading stopped short of the
        end (None: it did not): MAX_SUBPROGRAM blocks past the O line of the first program that does
        not end with M99 within as many blocks, or of a program whose text runs on as long after its
        M99 (`_ProgramScan.candidate`)."""
        scan = _ProgramScan(self.leader)
        main, index = self.frames[0], first
        while (block := self._block(main, index)) is not None:
            top = scan.candidate() or (scan.found[-1] if scan.found else None)
            if top is not None and index - top.index > MAX_SUBPROGRAM:
                return scan, index
            scan.add(index, block)
            index += 1
        return scan, None

    def _program_end(self, start: int, most: int | None) -> tuple[str | None, int]:
        """How the program whose O line stands at `start` ends first (M99, M30, M2, `_end_code`; None:
        neither before the next program, `%` or the end of the file, or within `most` blocks), and
        where the next program's O line (or the end of the text) stands."""
        main, index, end = self.frames[0], start + 1, None
        while (block := self._block(main, index)) is not None:
            if program_number(block) is not None:
                break
            if end is None:
                if _starts_program(block) or most is not None and index - start > most:
                    return None, index
                end = _end_code(block)
                if end is not None and most is not None:
                    return end, index
            index += 1
        return end, index

    def _endsub(self, frame, block, control, arrived):
        return self._return(frame, block, control, arrived)

    def _return(self, frame, block, control, arrived):
        if frame.space is None:
            raise self._error(f"{control.keyword} outside a subroutine", block, control)
        value = self._value(block, control)

        def leave():
            self.frames.pop()
            self.parameters.leave(value)

        return leave

    def _call(self, frame, block, control, arrived):
        arguments = [self.evaluate(a, block, control.item) for a in control.arguments]
        if len(arguments) > SUBROUTINE_PARAMETERS:
            raise self._error(f"more than {SUBROUTINE_PARAMETERS} arguments to a subroutine", block, control)
        name = control.name
        body = self.subroutines.get(name) or self._from_file(name) or self._defined(self.subroutines, name)
        if body is None:
            where = (
                f" nor is o{_shown(name)}.ngc in {os.pathsep.join(map(str, self.path))}" if self.path else ""
            )
            self.stop(f"a call of o{_shown(name)}, which the program does not define{self._not_ahead()} (a subroutine file: give its folder "
                      f"with --subroutine-path; the LinuxCNC filter reads the INI's SUBROUTINE_PATH){where}", block, control.item.start + 1)  # fmt: skip
            return lambda: None

        self._check_level(block, control)
        if name not in self.files:  # (a file's definition is no line of the program)
            self.defined_at.setdefault(name, body[0].line)
        once = self._runs_once(frame, block, name, body, 1)
        if not once and name in self.ahead:
            self.once.refuse(name)  # (its definition waits no more)

        def call():
            frame.pc += 1
            self.parameters.enter(arguments)
            self._count_call(name)
            self.frames.append(
                _Frame(body, 1, repeats=-1, source=self.files.get(name), called=self._once(name, once))
            )

        return call

    def _source_of(self, body: list[Block]) -> str | None:
        """The file a Fanuc program's lines were read from (None: the program's own)."""
        return next((self.program_files[n] for n, lines in self.subprograms.items()
                     if lines is body and n in self.program_files), None)  # fmt: skip

    def _program_from_file(self, name: str) -> list[Block] | None:
        """Fanuc program `O<name>`, `O<name>` to its first M99, from the first folder of the path
        with a file named for it (`_program_files`): a Fanuc control keeps each program under
        its number, and a file on a PC holds one so (the file must say `O<name>` itself: a file
        without that line is an error that says what the file holds instead, `_unread`)."""
        for folder in self.path:
            path = next((p for p in _program_files(folder, name) if p.is_file()), None)
            if path is None:
                continue
            lines: list[Block] = []
            numbers: list[str] = []  # the other programs' numbers the file gives
            with open(path, "rb") as stream:
                for block in parse_stream(stream, str(path), "fanuc"):
                    number = None if lines else program_number(block)
                    if number is not None and number != name and len(numbers) < 3:
                        numbers.append(number)
                    if lines or number == name:
                        lines.append(block)
                        control = control_of(block)
                        if control is not None and control.keyword == "m99":
                            self.subprograms[name], self.program_files[name] = lines, str(path)
                            return lines
                    if len(lines) > MAX_SUBPROGRAM:
                        break
            raise NcppError(f"O{name} ... M99 is not in the file{_unread(path, name, bool(lines), numbers)}",
                            Location(str(path), 1, 1))  # fmt: skip
        return None

    def _from_file(self, name: str) -> list[Block] | None:
        """Subroutine `name` from `name.ngc` in the first folder of the path that has it (as LinuxCNC)."""
        for folder in self.path:
            path = _subroutine_file(folder, name)
            if path is None or not path.is_file():
                continue
            lines: list[Block] = []
            with open(path, "rb") as stream:
                for block in parse_stream(stream, str(path)):
                    control = control_of(block)
                    if lines or (control is not None and control.keyword == "sub" and control.name == name):
                        lines.append(block)
                        if control is not None and control.keyword == "endsub" and control.name == name:
                            self.subroutines[name], self.files[name] = lines, str(path)
                            return lines
            shown = printable(name)
            raise NcppError(
                f"o<{shown}> sub ... o<{shown}> endsub is not in the file", Location(str(path), 1, 1)
            )
        return None

    def source(self) -> str | None:
        """The subroutine file the running block is from (None: the program)."""
        return self.frames[-1].source

    def _searched(self) -> str:
        """Where a called Fanuc program was looked for, for a message (nothing without a path)."""
        return f", nor is it in {os.pathsep.join(map(str, self.path))}" if self.path else ""

    def _m98(self, frame, block, control, arrived):
        """A Fanuc subprogram call: `M98 P<n> L<repeats>`, or, where the flow reads repeats in P
        (`repeats_in_p`), `M98 P<repeats><n>`: P's last four digits the program's number, those
        before them its runs, 1 where none (Fanuc Series 0i-MC operator's manual, B-64124EN,
        "Subprogram (M98, M99)": `M98 P51002` calls subprogram 1002 five times in succession).  A
        program whose own number is the whole P (eight-digit program numbers) is the one called."""
        number, repeats = (None if item is None else self._number(item, block) for item in control.arguments)
        name, runs = (
            str(int(round_half_away(number))),
            1 if repeats is None else int(round_half_away(repeats)),
        )
        body = self._defined(self.subprograms, name) or self._program_from_file(name)
        if body is None and self.repeats_in_p and repeats is None and int(name) > 9_999:
            runs, program = divmod(int(name), 10_000)
            body = self._defined(self.subprograms, str(program)) or self._program_from_file(str(program))
            name = name if body is None else str(program)
        if body is None:
            said = (
                f"M98 P{name}: a subprogram the program does not define{self._not_ahead()} (O{name} to M99)"
            )
            self.stop(said + self._searched(), block, control.item.start + 1)
            return lambda: None

        self._check_level(block, control)
        once = self._runs_once(frame, block, name, body, runs)
        if not once and name in self.ahead:
            self.once.refuse(name)  # (its definition waits no more)

        def call():
            frame.pc += 1
            self.parameters.enter(None)
            if runs > 0:
                self._count_call(name)
                self.frames.append(_Frame(body, 1, repeats=runs - 1, runs=runs, mark=self.passes.steps,
                                          source=self._source_of(body), called=self._once(name, once)))  # fmt: skip
            else:  # L0: rs274ngc runs nothing but stays a call level deeper: the caller's names, loops and ifs are gone
                frame.labels.clear()
                frame.ifs.clear()

        return call

    def _check_level(self, block: Block, control: Control) -> None:
        """Refuse a call past MAX_CALL_LEVELS, as rs274ngc does (a call of itself would nest for ever)."""
        if len(self.frames) >= MAX_CALL_LEVELS:  # frames: the program's, then one per call
            raise NcppError(f"Too many subroutine levels: calls nest at most {MAX_CALL_LEVELS - 1} deep (as in rs274ngc)",
                            Location(self.file, block.line, control.item.start + 1))  # fmt: skip

    def _m97(self, frame, block, control, arrived):
        """Haas's local subprogram call `M97 P<n> L<repeats>` (the module docstring): the lines from
        the main program's block Nn to its M99, run L times (1-99).  A P no block can have and an Nn
        the program lacks are the control's alarms; an Nn before the call, an L out of 1-99 and a call
        from a program M98 or G65 runs are out of scope."""
        number, repeats = (None if item is None else self._number(item, block) for item in control.arguments)
        col = control.item.start + 1
        n = int(round_half_away(number))
        if not 1 <= n <= MAX_SEQUENCE_NUMBER:
            raise NcppError(f"M97 P{printable(f'{number:g}')}: a sequence number is 1 to {MAX_SEQUENCE_NUMBER}, "
                            "no block has it (a Haas alarm)", Location(self.file, block.line, col))  # fmt: skip
        runs = 1 if repeats is None else int(round_half_away(repeats))
        why = (
            "(a sequence number is a whole number: which block a fraction finds is not ncpp's to guess)"
            if number != n
            else f"L{printable(f'{repeats:g}')} (Haas runs a local subprogram 1 to 99 times)"
            if repeats is not None and not (repeats == runs and 1 <= runs <= 99)
            else "in a subprogram M98 or G65 runs (its own program's sequence numbers)"
            if frame.space is not None and not frame.local
            else None
        )
        body = self._local_body(frame, n, block, col) if why is None else None
        if body is None:
            if why is not None:
                self.stop(f"M97 P{printable(f'{number:g}')} {why}", block, col)
            return lambda: None
        name = f"N{n}"
        self._check_level(block, control)
        once = _label_only(body[0]) and self._runs_once(frame, block, name, body, runs, first=0)

        def call():
            frame.pc += 1
            self.parameters.enter(None)
            self._count_call(name)
            self.frames.append(_Frame(body, 0, repeats=runs - 1, runs=runs, mark=self.passes.steps, local=True,
                                      called=self._once(name, once)))  # fmt: skip

        return call

    def _local_body(self, frame: _Frame, number: int, block: Block, col: int) -> list[Block] | None:
        """The lines of local subprogram Nn, from the first block Nn after the call to the first M99
        after it, held (None: out of scope, the flow has stopped).  Refused where the program (up to
        its closing `%`) has no block Nn after the call."""
        call = frame.pc if frame.space is None else self._main_index(block)
        if call is None:  # (a nested call whose line is no longer held: not looked for)
            self.stop(f"M97 P{number} whose line is further back than the blocks ncpp holds", block, col)
            return None
        if self._numbered_before(call, number):
            self.stop(f"M97 P{number} with a block N{number} before the call (which of them the control runs is not "
                      "ncpp's to guess; Haas places a local subprogram after M30)", block, col)  # fmt: skip
            return None
        name = f"N{number}"
        main, index = self.frames[0], call + 1
        while (ahead := self._block(main, index)) is not None and (index < self.leader or not ahead.verbatim):
            if sequence_number(ahead) == number:
                break
            index += 1
            if index > call + MAX_AHEAD:
                self.stop(f"M97 P{number}: N{number} is not within {MAX_AHEAD:,} blocks ahead (ncpp reads no further "
                          "ahead)", block, col)  # fmt: skip
                return None
        else:
            raise NcppError(f"M97 P{number}: the program has no block N{number} after the call (a Haas alarm)",
                            Location(self.file, block.line, col))  # fmt: skip
        known = self.locals.get(name)
        if known is not None and known[0] is ahead:
            return known
        lines: list[Block] = []
        while (line := self._block(main, index)) is not None and len(lines) < MAX_SUBPROGRAM:
            if lines and (_starts_program(line) or program_number(line) is not None):
                break
            lines.append(line)
            control = self._control_of(line)
            if control is not None and control.keyword == "m99":
                self.locals[name] = lines
                return lines
            index += 1
        self.stop(f"M97 P{number} (no M99 ends the local subprogram N{number} within {MAX_SUBPROGRAM:,} blocks, "
                  "before the next program or the end of the file)", block, col)  # fmt: skip
        return None

    def _main_index(self, block: Block) -> int | None:
        """Where `block` (a line of the main program's text) stands in it, if it is still held."""
        at = next((i for i, held in enumerate(self.buffer) if held is block), None)
        return None if at is None else self.base + at

    def _numbered_before(self, call: int, number: int) -> bool:
        """Whether a block of the main program's text before line `call` has sequence number `number`
        (the lines no longer held are noted as they are dropped: `dropped`)."""
        if number in self.dropped:
            return True
        first = self._first_numbered
        for index in range(max(self._numbers_read, self.base, self.main_top), call):
            found = sequence_number(self.buffer[index - self.base])
            if found is not None:
                first.setdefault(found, index)
        self._numbers_read = max(self._numbers_read, call)
        return first.get(number, call) < call

    def _m99(self, frame, block, control, arrived):
        if frame.space is None:
            self.stop("M99 in the main program (an endless main program)", block, control.item.start + 1)
            return lambda: None
        if frame.repeats < 0:
            raise NcppError(
                "an o-word subroutine ends with o... endsub or o... return, not M99",
                Location(self.file, block.line, control.item.start + 1),
            )

        def leave():
            if frame.repeats > 0:  # L: once more (a G65 macro with the locals it left)
                frame.repeats -= 1
                caller, depth = self.frames[-2], len(self.frames) - 2
                around = (  # (after its first run: the counted loops around the call, with it)
                    (lambda: self._around(caller, caller.pc, depth))
                    if frame.repeats == frame.runs - 2
                    else None
                )
                frame.mark = self.passes.ended(frame.mark, self.rerun, frame.repeats, block.line,
                                               "a subprogram's L repeats", frame.source, around,
                                               frame.runs)  # fmt: skip
                frame.pc, frame.labels = 0 if frame.local else 1, {}
                if not frame.macro:
                    self.parameters.leave(None)
                    self.parameters.enter(None)
            else:
                self.parameters.leave(None)
                self.frames.pop()

        return leave

    def _g65(self, frame, block, control, arrived):
        """A Fanuc macro call: `G65 P<n> L<repeats> <arguments>` (the module docstring)."""
        found = self._macro(block, control)
        if found is None:
            return lambda: None
        body, runs, values = found
        self._check_level(block, control)

        def call():
            frame.pc += 1
            self.parameters.enter_macro(values)
            self.frames.append(_Frame(body, 1, repeats=runs - 1, runs=runs, mark=self.passes.steps, macro=True,
                                      source=self._source_of(body)))  # fmt: skip

        return call

    def _g66(self, frame, block, control, arrived):
        """`G66 P<n> L<repeats> <arguments>`: from the next block on, O<n> is called with the
        arguments after each block of this frame that moves, until G67; the moves of the macro
        call it no more (Fanuc 16i/18i operator's manual, "Custom macro", Modal call: G66)."""
        if self.modal is not None:
            self.stop(
                "G66 while a G66 modal call is in effect (nested modal calls)", block, control.item.start + 1
            )
            return lambda: None
        found = self._macro(block, control)
        if found is None:
            return lambda: None
        depth = len(self.frames) - 1

        def start():
            frame.pc += 1
            self.modal = _ModalCall(*found, depth)

        return start

    def _g67(self, frame, block, control, arrived):
        def cancel():
            frame.pc += 1
            self.modal = None

        return cancel

    def _modal_call(self, block: Block) -> None:
        """After a block that moved under G66: the macro, called (its own moves call nothing)."""
        modal = self.modal
        if modal is None:
            return
        if len(self.frames) - 1 != modal.depth:
            if not any(f.modal for f in self.frames[modal.depth + 1 :]):
                self.stop("a move in a subprogram or macro called while G66 is in effect", block, None)
            return
        if len(self.frames) >= MAX_CALL_LEVELS:
            raise NcppError(f"Too many subroutine levels: calls nest at most {MAX_CALL_LEVELS - 1} deep",
                            Location(self.file, block.line, None))  # fmt: skip
        self.parameters.enter_macro(modal.values)
        self.frames.append(_Frame(modal.body, 1, repeats=modal.runs - 1, runs=modal.runs, mark=self.passes.steps,
                                  macro=True, modal=True, source=self._source_of(modal.body)))  # fmt: skip

    def _macro(self, block: Block, control: Control) -> tuple[list[Block], int, dict[int, float]] | None:
        """The body, runs and arguments of a G65 or G66 line (None: the program lacks the macro)."""
        program, repeats, arguments = control.arguments
        name = str(int(round_half_away(self._number(program, block))))
        runs = 1 if repeats is None else int(round_half_away(self._number(repeats, block)))
        if runs < 1:
            raise NcppError(f"{control.keyword.upper()} L{runs}: a macro runs 1 to 9999 times",
                            Location(self.file, block.line, repeats.start + 1))  # fmt: skip
        if type(arguments) is str:  # (I J K sets read two ways)
            self.stop(arguments, block, control.item.start + 1)
            return None
        values = {
            variable: self._number(item, block)
            for variable, item in arguments
            if type(item) is Word or not vacant(item.expr, self.parameters)  # (a vacant one: not given)
        }
        body = self._defined(self.subprograms, name) or self._program_from_file(name)
        if body is None:
            what = control.keyword.upper()
            said = f"{what} P{name}: a macro the program does not define{self._not_ahead()} (O{name} to M99)"
            self.stop(said + self._searched(), block, control.item.start + 1)
            return None
        self._count_call(name)  # (G66's calls after each move run it again)
        return body, runs, values

    # -- Fanuc branches and loops ------------------------------------------------
    def _goto(self, frame, block, control, arrived):
        (target,) = control.arguments
        return self._jump(frame, block, control, target)

    def _fanuc_if(self, frame, block, control, arrived):
        condition, target = control.arguments
        if self.evaluate(condition, block, control.item) == 0.0:
            return self._on(frame, None)
        return self._jump(frame, block, control, target)

    def _fanuc_while(self, frame, block, control, arrived):
        condition, m = control.arguments
        name = self._loop_name(m, block, control)
        label = frame.labels.get(name)
        if label is not None and label.start != frame.pc:
            where = Location(self.file, block.line, control.item.start + 1)
            raise NcppError(f"WHILE ... DO{m} inside the loop DO{m} under way: nested loops take different "
                            "numbers (a Fanuc alarm)", where)  # fmt: skip
        again = self.evaluate(condition, block, control.item) != 0.0

        def test():
            if again:
                frame.labels.setdefault(name, _Label("fanuc", frame.pc))
            else:  # on past its END
                self.skipping = name
            frame.pc += 1

        return test

    def _fanuc_end(self, frame, block, control, arrived):
        (m,) = control.arguments
        name = self._loop_name(m, block, control)
        if arrived:  # the WHILE's condition failed
            return self._ended(frame, name)
        label = frame.labels.get(name)
        where = Location(self.file, block.line, control.item.start + 1)
        if label is None or label.kind != "fanuc":
            raise NcppError(f"END{m} without WHILE ... DO{m} (a Fanuc alarm)", where)
        inner = [
            other
            for other, open_ in frame.labels.items()
            if open_.kind == "fanuc" and open_.start > label.start
        ]
        if inner:
            raise NcppError(f"END{m} closes DO{m} across the loop {inner[0]}: loops nest, they do not cross "
                            "(a Fanuc alarm)", where)  # fmt: skip
        opening = self._control_of(self._block(frame, label.start))
        self._refuse_without_way_out(frame, label, opening.arguments[0], block, control)
        return self._back(frame, label.start, block, control)

    def _loop_name(self, m: int, block: Block, control: Control) -> str:
        if m not in (1, 2, 3):
            raise NcppError(f"DO{m} / END{m}: a loop's number is 1, 2 or 3 (a Fanuc alarm)",
                            Location(self.file, block.line, control.item.start + 1))  # fmt: skip
        return f"DO{m}"

    def _jump(self, frame: _Frame, block: Block, control: Control, target: tuple) -> Callable:
        """GOTO: on at the block numbered `target`, forward (the blocks between are skipped) or back."""
        col = control.item.start + 1
        if frame.local:  # (which text the control searches from there is not documented)
            self.stop("GOTO in a Haas local subprogram (M97)", block, col)
            return lambda: None
        value = self.evaluate(target, block, control.item)
        number = int(round_half_away(value))
        if not 1 <= number <= MAX_SEQUENCE_NUMBER:
            shown = printable(f"{value:g}")
            raise NcppError(f"GOTO {shown}: a sequence number is 1 to {MAX_SEQUENCE_NUMBER} "
                            "(a Fanuc alarm)", Location(self.file, block.line, col))  # fmt: skip
        index = self._sequence_index(frame, number, block, col)
        if index is None:
            return lambda: None
        if index > frame.pc:
            return lambda: self._forward(frame, index, number, block, col)
        target_line = self._block(frame, index).line  # type: ignore[union-attr]  # (found: held)
        if frame.space is None and not self.fanuc:  # (its moves run in place were not noted)
            self.stop(f"GOTO {number} back, the program's first macro statement past the {_TRIM:,} blocks "
                      "read ahead", block, col)  # fmt: skip
            return lambda: None
        if frame.space is None and max(self.last_run_move, self.once_move) >= target_line:
            self.stop(f"GOTO {number} back over moves that ran once in their place (their text may be "
                      "rewritten for that run; a WHILE ... DO loop or a loop near the top of the program is "
                      "followed)", block, col)  # fmt: skip
            return lambda: None
        if control.keyword == "goto" or never_changes(control.arguments[0]):
            self._refuse_jump_without_way_out(frame, index, block, control)

        def back():
            for name in [
                n for n, label in frame.labels.items() if label.kind == "fanuc" and label.start >= index
            ]:
                del frame.labels[name]  # left: the jump goes back before its WHILE
            self._back(frame, index, block, control)()

        return back

    def _forward(self, frame: _Frame, index: int, number: int, block: Block, col: int) -> Iterator:
        """Past the blocks up to `index`: text that does not run; a loop whose END it passes is
        left, one whose WHILE it passes is entered, which Fanuc refuses."""
        entered: dict[str, int] = {}
        frame.pc += 1
        while frame.pc < index:
            passed = self._block(frame, frame.pc)
            control = self._control_of(passed)  # type: ignore[arg-type]  # (held: read by the search)
            if control is not None and control.keyword == "fanuc_end":
                frame.labels.pop(control.name, None)  # type: ignore[arg-type]  # (a str: DOm)
                entered.pop(control.name, None)  # type: ignore[arg-type]
            elif control is not None and control.keyword == "fanuc_while":
                entered[f"DO{control.arguments[1]}"] = passed.line  # type: ignore[union-attr]
            if self._in_place(frame):
                yield passed, SKIP, None
                self._wrote(frame.pc)
            frame.pc += 1
        if entered:
            name, line = next(iter(entered.items()))
            raise NcppError(f"GOTO {number} jumps into the loop WHILE ... {name} of line {line}: a branch "
                            "may leave a loop, not enter one",
                            Location(self.file, block.line, col))  # fmt: skip

    def _sequence_index(self, frame: _Frame, number: int, block: Block, col: int) -> int | None:
        """Where block Nn stands in the frame: searched forward from the jump, then from the top
        (None: ncpp cannot tell, the flow has stopped)."""
        if frame.space is not None:
            found = _numbered(frame.space, frame.pc, number)
            if found is None and frame.repeats >= 0:  # (a Fanuc subprogram, past its first M99)
                whole = self._whole_programs.get(id(frame.space))
                if whole is None:
                    rest = self._rest_of_program(frame.space)
                    whole = self._whole_programs[id(frame.space)] = frame.space + (rest or [])
                frame.space = whole
                found = _numbered(frame.space, frame.pc, number)
            if found is None:
                self.stop(f"GOTO {number}: no N{number} in the subprogram (to the next program number or "
                          "%, with no M2 or M30)", block, col)  # fmt: skip
            return found
        index = frame.pc + 1
        while (ahead := self._block(frame, index)) is not None:
            if ahead.verbatim and index >= self.leader:  # past the closing `%`: another program
                break
            if sequence_number(ahead) == number:
                return index
            index += 1
            if index > frame.pc + MAX_SUBPROGRAM:
                self.stop(f"GOTO {number}: N{number} is not within {MAX_SUBPROGRAM:,} blocks ahead and "
                          "the blocks before are not all held", block, col)  # fmt: skip
                return None
        if number in self.dropped or not self.fanuc and self.base > 0:  # (not a Fanuc one: none noted)
            self.stop(f"GOTO {number}: N{number} is further back than the blocks ncpp holds", block, col)
            return None
        for index in range(max(self.base, self.main_top), frame.pc + 1):  # (the main program's own)
            if sequence_number(self.buffer[index - self.base]) == number:
                return index
        raise NcppError(f"GOTO {number}: the program has no block N{number} (a Fanuc alarm)",
                        Location(self.file, block.line, col))  # fmt: skip

    def _rest_of_program(self, space: list[Block]) -> list[Block] | None:
        """A Fanuc subprogram's blocks after its first M99 (where `space` ends), to the next
        program number, `%` or the end of the file: a program is all of them on a Fanuc.  None
        where they are not all held, or one ends a program (M2, M30: the main program's text)."""
        last = space[-1]
        start = next((i for i, held in enumerate(self.buffer) if held is last), None)
        if start is None:
            return None
        rest: list[Block] = []
        main = self.frames[0]
        index = self.base + start + 1
        while len(rest) < MAX_SUBPROGRAM:
            block = self._block(main, index)
            if block is None or program_number(block) is not None or _starts_program(block):
                return rest
            if _ends_program(block):
                return None
            rest.append(block)
            index += 1
        return None

    def _defined(self, found: dict[str, list[Block]], name: str) -> list[Block] | None:
        """The lines of subroutine (or subprogram) `name`, read on for if it comes later in the text, at
        most MAX_AHEAD blocks past those read (None: nowhere, or not so near: `cut_short`)."""
        most, self.cut_short = self.read + MAX_AHEAD, False
        while name not in found:
            if self.read >= most:
                self.cut_short = True
                return None
            if not self._read():
                return None
        return found[name]

    def _not_ahead(self) -> str:
        """What a call's message adds where the search for its definition stopped at MAX_AHEAD blocks."""
        cut, self.cut_short = self.cut_short, False
        return f" within {MAX_AHEAD:,} blocks ahead (ncpp reads no further ahead)" if cut else ""

    def _if(self, frame, block, control, arrived):
        self._opens(frame, block, control)
        frame.ifs.add(control.name)
        self.executed_if = self._condition(block, control)
        return self._on(frame, None if self.executed_if else control.name)

    def _elseif(self, frame, block, control, arrived):
        self._started(frame, block, control)
        if not self.executed_if and self._condition(block, control):
            self.executed_if = True
            return self._on(frame, None)
        return self._on(frame, control.name)

    def _else(self, frame, block, control, arrived):
        self._started(frame, block, control)
        if self.executed_if:
            return self._on(frame, control.name)
        self.executed_if = True  # (reached running, not skipping, only from a chain it did not see start)
        return self._on(frame, None)

    def _endif(self, frame, block, control, arrived):
        self._started(frame, block, control)
        self.executed_if = True  # the chain around this one ran, or this line would be skipped
        return self._on(frame, None)

    def _started(self, frame: _Frame, block: Block, control: Control) -> None:
        if control.name not in frame.ifs:
            raise self._error(f"{control.keyword} without o{_shown(control.name)} if", block, control)  # type: ignore[arg-type]  # (_NAMED)

    def _while(self, frame, block, control, arrived):
        self._opens(frame, block, control)
        label = frame.labels.get(control.name)
        again = self._condition(block, control)
        if label is not None and label.kind == "do":  # the end of a do loop
            if again and not self.doing_break:
                self._refuse_without_way_out(frame, label, control.arguments[0], block, control)
                return self._back(frame, label.start, block, control)
            self.doing_break = False
            return self._ended(frame, control.name)

        def test():
            if label is None:
                frame.labels[control.name] = _Label("while", frame.pc)
            self._on(frame, None if again else control.name)()

        return test

    def _endwhile(self, frame, block, control, arrived):
        return self._loop_end(frame, block, control, arrived, "while")

    def _endrepeat(self, frame, block, control, arrived):
        return self._loop_end(frame, block, control, arrived, "repeat")

    def _loop_end(self, frame, block, control, arrived, kind):
        """Back to the loop's opening line, or, skipping to here (a false test, a `break`), past it."""
        label = self._label(frame, block, control, (kind,))
        if arrived:
            if not self.doing_continue:
                return self._ended(frame, control.name)
            self.doing_continue = False  # (only here: a `continue` in a do loop leaves it set)
        if kind == "while":
            opening = self._control_of(self._block(frame, label.start))
            self._refuse_without_way_out(frame, label, opening.arguments[0], block, control)
        return self._back(frame, label.start, block, control)

    def _do(self, frame, block, control, arrived):
        frame.opened.setdefault(control.name, (frame.pc, "do", block.line))

        def enter():
            frame.labels.setdefault(control.name, _Label("do", frame.pc))
            frame.pc += 1

        return enter

    def _repeat(self, frame, block, control, arrived):
        self._opens(frame, block, control)
        (count,) = self._arguments(block, control, 1)

        def test():
            label = frame.labels.setdefault(control.name, _Label("repeat", frame.pc))
            if label.count == -1:  # counted where the loop starts
                label.count = label.total = int(round_half_away(count))
            if label.count > 0:
                label.count -= 1
                what = f"o{_shown(control.name)} repeat"
                around = (
                    (lambda: self._around(frame, label.start)) if label.count == label.total - 2 else None
                )
                label.mark = self.passes.ended(label.mark, self.rerun, label.count, block.line, what,
                                               frame.source, around, label.total)  # fmt: skip
                self._on(frame, None)()
            else:
                label.count, label.mark = -1, None
                self._on(frame, control.name)()

        return test

    def _around(self, frame: _Frame, start: int, top: int | None = None) -> list[Around]:
        """The counted loops around the loop at `start` of `frame` (the frame at depth `top`, None:
        the innermost), innermost first, as far as counted loops go: o-word repeats, and Fanuc
        subprograms' L repeats around their calls."""
        loops: list[Around] = []
        for depth in range(len(self.frames) - 1 if top is None else top, -1, -1):
            level = self.frames[depth]
            inside = [(n, b) for n, b in level.labels.items() if level is not frame or b.start < start]
            opened = sorted(inside, key=lambda item: -item[1].start)
            for name, label in opened:
                if label.kind != "repeat" or label.count < 0:
                    return loops
                line = self._block(level, label.start).line  # type: ignore[union-attr]  # (held: under way)
                loops.append(Around(label.count, label.total, line, f"o{_shown(name)} repeat", level.source))
            if level.repeats > 0 and depth > 0:  # (its caller's line before its pc called it)
                caller = self.frames[depth - 1]
                line = self._block(caller, caller.pc - 1).line  # type: ignore[union-attr]
                loops.append(Around(level.repeats, level.repeats + 1, line, "a subprogram's L repeats",
                                    caller.source))  # fmt: skip
        return loops

    def _break(self, frame, block, control, arrived):
        self._label(frame, block, control, ("while", "do"))
        self.doing_break = True
        return self._on(frame, control.name)

    def _continue(self, frame, block, control, arrived):
        self._label(frame, block, control, ("while", "do"))
        if not arrived:
            self.doing_continue = True
        return self._on(frame, control.name)

    # -- helpers ---------------------------------------------------------------
    def _opens(self, frame: _Frame, block: Block, control: Control) -> None:
        """An if, while or repeat line opens its label: as rs274ngc, the first line of its frame to
        run one (the `while` of a do loop closes it), else a duplicate label (a reused `o1 if`)."""
        first = frame.opened.setdefault(control.name, (frame.pc, control.keyword, block.line))  # type: ignore[arg-type]  # (_NAMED)
        if first[0] != frame.pc and not (first[1] == "do" and control.keyword == "while"):
            raise self._error(
                f"is a duplicate O-word label: already defined in line {first[2]}", block, control
            )

    def _back(self, frame: _Frame, head: int, block: Block, control: Control) -> Callable[[], None]:
        """Back to a loop's head (its index in the frame), where a loop that comes back to a state
        it had is refused (`endless.py`), at the line that goes back."""

        def step():
            frame.pc = head
            if self.revisits is None:
                return
            depth = len(self.frames)
            found = self.revisits.arrived(
                (depth, id(frame.space), head, id(block)), (depth, head), (frame, head, block, control)
            )
            if found is not None:
                jumps, (level, start, end, its) = found
                where = Location(level.source or self.file, end.line, its.item.start + 1)
                raise endless(jumps, self._block(level, start).line, where)

        return step

    def _refuse_without_way_out(self, frame: _Frame, label: _Label, condition: tuple, block: Block,
                                control: Control) -> None:  # fmt: skip
        """At the end of a while loop's first pass: refuse it where it can never end (`endless.py`)."""
        if label.checked:
            return
        label.checked = True
        if not never_changes(condition):
            return
        body = (self._block(frame, index) for index in range(label.start + 1, frame.pc))
        if not any(self._way_out(b, True, set()) for b in body):  # type: ignore[arg-type]  # (held: under way)
            where = Location(frame.source or self.file, block.line, control.item.start + 1)
            raise without_way_out(self._block(frame, label.start).line, where)  # type: ignore[union-attr]

    def _refuse_jump_without_way_out(self, frame: _Frame, index: int, block: Block, control: Control) -> None:
        """A GOTO back (or an IF of a constant): refused where no block from its target on can leave
        the loop it makes (`endless.py`); each jump looked at once."""
        key = (id(frame.space), index, id(block))
        if key in self._jumps_checked:
            return
        self._jumps_checked.add(key)
        body = (self._block(frame, i) for i in range(index, frame.pc))
        if not any(self._way_out(b, True, set()) for b in body):  # type: ignore[arg-type]  # (held)
            where = Location(frame.source or self.file, block.line, control.item.start + 1)
            raise without_way_out(self._block(frame, index).line, where)  # type: ignore[union-attr]

    def _way_out(self, block: Block, in_loop: bool, seen: set[str]) -> bool:
        """Whether running `block` may end the program or, `in_loop`, leave the loop it stands in: a
        break, return, jump or M99 there; anywhere a program end, an alarm (an `(abort, ...)`
        comment, a Fanuc `#3000`), or a call of a body that does (one that cannot be seen counts)."""
        control = self._control_of(block)
        if control is None:
            return _ends_program(block) or any(
                type(item) is Statement
                and "3000" in block.raw[item.start : item.end]
                or type(item) is Comment
                and item.text.lstrip().lower().startswith("abort")
                for item in block.items
            )
        keyword = control.keyword
        if keyword in ("break", "return", "goto", "fanuc_if", "m99", "endsub"):
            return in_loop
        if keyword not in ("call", "m97", "m98", "g65", "g66"):
            return False
        name = control.name
        if keyword != "call":
            number = control.arguments[0]
            if type(number) is not Word:
                return True
            name = ("N" if keyword == "m97" else "") + str(int(round_half_away(number.value)))
        if type(name) is not str:
            return True  # (a name computed where the call runs)
        if name in seen:
            return False
        seen.add(name)
        bodies = {"call": self.subroutines, "m97": self.locals}.get(keyword, self.subprograms)
        body = bodies.get(name)
        return body is None or any(self._way_out(b, False, seen) for b in body)

    def _with_flow(self, state: object) -> tuple | None:
        """The interpreter's `state` and the flow's own (None: not told): its calls, loops and
        branches, where it stands in the text, what it has read; not its counts of lines run."""
        if state is None:
            return None
        frames = tuple((id(f.space), f.pc, tuple((n, b.kind, b.start, b.count) for n, b in f.labels.items()),
                        frozenset(f.ifs), tuple(f.opened.items()), f.repeats, f.source, f.macro, f.modal)
                       for f in self.frames)  # fmt: skip
        modal = self.modal and (
            id(self.modal.body),
            self.modal.runs,
            exact(self.modal.values),
            self.modal.depth,
        )
        defining = self._defining and (self._defining[1], len(self._defining[2]))
        held = (self.written, self.base, self.read, self.leader, id(self.owner), self._fault is None,
                defining, self.last_run_move, self.once_move, self.fanuc, len(self.dropped), len(self.looped),
                len(self.subroutines), len(self.subprograms), len(self.defined_at), len(self.files),
                len(self.program_files), len(self._whole_programs), len(self._definitions))  # fmt: skip
        flags = (self.skipping, self.executed_if, self.doing_break, self.doing_continue, self.moved)
        return state, frames, modal, flags, held

    def _on(self, frame: _Frame, skipping: str | None) -> Callable[[], None]:
        """On to the next line, skipping to the next line of o-word `skipping` (None: not)."""

        def step():
            self.skipping = skipping
            frame.pc += 1

        return step

    def _ended(self, frame: _Frame, name: str) -> Callable[[], None]:
        """Past a loop's end: no line goes back to it."""

        def step():
            frame.labels.pop(name, None)
            frame.pc += 1

        return step

    def _skip_definition(self, frame: _Frame, name: str) -> Iterator[tuple[Block, str, Block | None]]:
        """Past a subroutine's definition to its endsub: lines that do not run."""
        opening = frame.pc
        while True:
            block = self._block(frame, frame.pc)
            if block is None:
                shown = _shown(name)
                raise NcppError(f"o{shown} sub has no o{shown} endsub", self._sub_place(frame, opening))
            control = self._control_of(block)
            if (
                control is not None and control.keyword == "sub" and frame.pc != opening
            ):  # (rs274ngc: none in another)
                raise NcppError(
                    "Nested subroutine definition", Location(self.file, block.line, control.item.start + 1)
                )
            if self._in_place(frame):
                yield block, SKIP, None
                self._wrote(frame.pc)
            frame.pc += 1
            if control is not None and control.name == name and control.keyword == "endsub":
                return

    def _sub_place(self, frame: _Frame, opening: int) -> Location:
        """Where the `sub` statement at `opening` in the frame's text stands (for messages)."""
        block = self._block(frame, opening)
        control = None if block is None else self._control_of(block)
        if block is None or control is None:
            return Location(self.file, self._opening_line(frame), 1)
        return Location(self.file, block.line, control.item.start + 1)

    def _opening_line(self, frame: _Frame) -> int:
        """The line a construct left open at the end of the text started at (for messages)."""
        if frame.space is not None:
            return frame.space[0].line
        return self.owner.line if self.owner is not None else 1

    def _label(self, frame: _Frame, block: Block, control: Control, kinds: tuple[str, ...]) -> _Label:
        """The running loop the line names, of one of `kinds` (rs274ngc: no other)."""
        label = frame.labels.get(control.name)  # type: ignore[arg-type]  # (_NAMED)
        if label is None or label.kind not in kinds:
            found = "no loop" if label is None else f"a {label.kind} loop"
            raise self._error(
                f"{control.keyword} names {found}, not a {' or '.join(kinds)} loop", block, control
            )
        return label

    def _condition(self, block: Block, control: Control) -> bool:
        (value,) = self._arguments(block, control, 1)
        return value != 0.0

    def _value(self, block: Block, control: Control) -> float | None:
        values = self._arguments(block, control, None)
        return values[0] if values else None

    def _arguments(self, block: Block, control: Control, wanted: int | None) -> list[float]:
        if wanted is not None and len(control.arguments) != wanted:
            raise self._error(
                f"{control.keyword} wants {'an expression' if wanted == 1 else f'{wanted} expressions'} in [ ]",
                block,
                control,
            )
        if wanted is None and len(control.arguments) > 1:
            raise self._error(f"{control.keyword} takes one value", block, control)
        return [self.evaluate(a, block, control.item) for a in control.arguments]

    def _number(self, item: Word | ExprWord, block: Block) -> float:
        return item.value if type(item) is Word else self.evaluate(item.expr, block, item)

    def _error(self, message: str, block: Block, control: Control) -> NcppError:
        name: str = control.name  # type: ignore[assignment]  # (_NAMED)
        return NcppError(
            f"o{_shown(name)} {message}", Location(self.file, block.line, control.item.start + 1)
        )


def control_of(block: Block) -> Control | None:
    """The block's control line, if it is one: an o-word (`O<name>` alone, a program
    name, is not), a line of only M97 P.. L.., M98 P.. L.. or M99, a Fanuc GOTO, IF ... GOTO, WHILE or
    END, or a G65, G66 or G67 line (N, comments and a leading `/` aside)."""
    words: dict[str, Word | ExprWord] = {}
    for item in block.items:
        kind = type(item)
        if kind is Statement:
            statement: Statement = item  # type: ignore[assignment]  # (`kind` says so; one type() per item)
            if (
                statement.kind == "block_delete" and not words
            ):  # `/o1 endsub`: with the switch off (rs274's) the line runs
                continue
            if statement.kind in _FANUC_FLOW:
                return _fanuc_control(block, statement, words)
            if statement.kind != "oword" or len(statement.node) < 2 or words:
                return None
            head, rest = statement.node[0], statement.node[1:]
            if head.endswith("["):  # o[expr] keyword ...: the name is evaluated where the line runs
                head, rest = rest[0], rest[1:]
                return Control(head, rest[0].lower(), tuple(rest[1:]), statement) if rest else None
            return Control(oword_name(head), rest[0].lower(), tuple(rest[1:]), statement)
        if kind is Word or kind is ExprWord:
            word: Word | ExprWord = item  # type: ignore[assignment]  # (as above)
            if (
                word.letter not in "NMPL" or word.letter in words
            ):  # (most lines end here, at their first word)
                if (
                    word.letter == "G"
                    and type(word) is Word
                    and word.value in _MACRO_CALLS
                    and words.keys() <= {"N"}
                ):
                    return _macro_call(block, word)
                return None
            words[word.letter] = word
        elif kind is not Comment:
            return None
    words.pop("N", None)
    m = words.get("M")
    if m is None or type(m) is not Word:
        return None
    if m.value in _CALLS and "P" in words and words.keys() <= {"M", "P", "L"}:
        return Control(None, _CALLS[m.value], (words["P"], words.get("L")), m)
    if m.value == 99.0 and len(words) == 1:
        return Control(None, "m99", (), m)
    return None


def _fanuc_control(block: Block, statement: Statement, words: dict) -> Control | None:
    """A Fanuc GOTO, IF ... GOTO, WHILE ... DO or END line (an N and comments aside); None for
    IF ... THEN, which the interpreter runs, and for a line with more on it."""
    items = block.items
    if words.keys() - {"N"} or any(type(i) is not Comment for i in items[items.index(statement) + 1 :]):
        return None
    node = statement.node
    keyword = _FANUC_FLOW[statement.kind]
    if keyword == "goto":
        return Control(None, keyword, (node[1],), statement)
    if keyword == "fanuc_if":
        return Control(None, keyword, (node[1], node[3]), statement) if node[2].upper() == "GOTO" else None
    if keyword == "fanuc_while":
        return Control(None, keyword, (node[1], _integer(node[3])), statement)
    m = _integer(node[1])
    return Control(f"DO{m}", keyword, (m,), statement)


def _macro_call(block: Block, g65: Word) -> Control | None:
    """`G65 P.. L.. <arguments>` (each letter once, but I J K, which specification II repeats),
    `G66` alike, `G67` alone; else None.  The arguments: (variable, word) pairs in the order
    written, or why their variables cannot be told (`_argument_variables`)."""
    keyword = _MACRO_CALLS[g65.value]
    if keyword == "g67":
        rest = block.items[block.items.index(g65) + 1 :]
        return Control(None, keyword, (), g65) if all(type(i) is Comment for i in rest) else None
    program = repeats = None
    arguments: list[Word | ExprWord] = []
    seen: set[str] = set()
    for item in block.items[block.items.index(g65) + 1 :]:
        kind = type(item)
        if kind is Comment:
            continue
        if kind is not Word and kind is not ExprWord:
            return None
        word: Word | ExprWord = item  # type: ignore[assignment]  # (`kind` says so)
        letter = word.letter
        if letter in seen or (letter not in MACRO_ARGUMENTS and letter not in "PL"):
            return None
        if letter not in "IJK":
            seen.add(letter)
        if letter == "P":
            program = word
        elif letter == "L":
            repeats = word
        else:
            arguments.append(word)
    if program is None:
        return None
    return Control(None, keyword, (program, repeats, _argument_variables(arguments, keyword)), g65)


def _argument_variables(words: list[Word | ExprWord], keyword: str) -> tuple | str:
    """Each argument word's local variable, (variable, word) in the order written (the module
    docstring: argument specifications I and II); a str says why I J K cannot be read."""
    pairs: list[tuple[int, Word | ExprWord]] = []
    sets, last = 0, "K"  # the I J K sets opened, the letter the last one ends with so far
    written = {"I": 0, "J": 0, "K": 0}  # how many of each letter so far
    for word in words:
        letter = word.letter
        if letter not in written:
            pairs.append((MACRO_ARGUMENTS[letter], word))
            continue
        if letter <= last:  # (I, J, K in alphabetical order)
            sets += 1
        last = letter
        written[letter] += 1
        if sets > IJK_SETS:
            return f"{keyword.upper()} with more than {IJK_SETS} sets of I J K arguments"
        if written[letter] != sets:
            return (f"{keyword.upper()} with I J K arguments out of order ({letter} number {written[letter]} "
                    f"in set {sets}): which local variable it sets is not ncpp's to guess")  # fmt: skip
        pairs.append((3 * sets + 1 + "IJK".index(letter), word))
    return tuple(pairs)


def _numbered(space: list[Block], pc: int, number: int) -> int | None:
    """Where Nn stands in a subprogram's lines: forward from `pc`, then from its top."""
    for index in (*range(pc + 1, len(space)), *range(1, pc + 1)):
        if sequence_number(space[index]) == number:
            return index
    return None


def _label_only(block: Block) -> bool:
    """Whether the block is a sequence number and comments alone (`N1000 (FACING)`): the line a
    local subprogram's call finds, which compensation writes as it is."""
    return all(type(item) is Comment or (type(item) is Word and item.letter == "N") for item in block.items)


def _starts_program(block: Block) -> bool:
    """A `%` line or a program's name (`OCIRCLE`): where a Fanuc program ends."""
    return any(type(item) is Statement and item.kind in ("tape", "program_name") for item in block.items)


def _ends_program(block: Block) -> bool:
    return any(
        type(item) is Word and item.letter == "M" and item.value in (2.0, 30.0) for item in block.items
    )


@dataclass(frozen=True)
class _Program:
    """A numbered program of a file (`Flow._programs`): where its O line stands, the line, its name
    as written, how it ends first (M99, M30, M2; None: neither before the next program, `%` or the
    end of the file) and whether it stands after the closing `%`."""

    index: int
    block: Block
    name: str
    end: str | None
    after: bool


class _ProgramScan:
    """The numbered programs of a text read a block at a time from a program's O line on (`Flow._programs`):
    each one's O line and how it ends first (`_end_code`; None: neither before the next program or
    `%`), `open` while the last one's end is still looked for."""

    def __init__(self, leader: int) -> None:
        self.leader = leader
        self.found: list[_Program] = []
        self.open = False
        self.other: _Program | None = None  # the first program whose end is known not to be M99

    def add(self, index: int, block: Block) -> None:
        if program_number(block) is not None:
            if self.open:
                self._ended()
            after = block.verbatim and index >= self.leader
            self.found.append(_Program(index, block, _program_name(block), None, after))
            self.open = True
        elif self.open:
            end = None if _starts_program(block) else _end_code(block)
            if end is not None:
                self.found[-1] = replace(self.found[-1], end=end)
            if end is not None or _starts_program(block):
                self._ended()

    def _ended(self) -> None:
        """The last program's end is known."""
        self.open = False
        if self.other is None and self.found[-1].end != "M99":
            self.other = self.found[-1]

    def candidate(self) -> _Program | None:
        """The first program found that does not end with M99 (one whose end is still looked for: None)."""
        return self.other

    def provisional(self) -> list[_Program]:
        """The programs found, the last one's end still looked for taken as M30 where it would be the
        main program (one that runs on past MAX_SUBPROGRAM blocks is no subprogram: `Flow._keep`)."""
        if not self.open or self.other is not None:
            return self.found
        return [*self.found[:-1], replace(self.found[-1], end="M30")]


def _main_program(programs: list[_Program]) -> tuple[_Program | None, str]:
    """Of a file's programs, the first of which ends with M99, the main one: the one later program
    that ends with M30 or M2, within the first `%` ... `%`, with only programs that end with M99
    before it; else None and why not."""
    ends = [p for p in programs if p.end in ("M2", "M30")]
    if not ends:
        return None, "no later program of the file ends with M30 or M2"
    if len(ends) > 1:
        return None, f"{len(ends)} later programs end with M30 or M2 ({', '.join(p.name for p in ends)})"
    main = ends[0]
    if main.after:
        return None, f"the one that ends with M30 or M2, {main.name}, stands after the file's closing %"
    between = next((p for p in programs if p.index < main.index and p.end != "M99"), None)
    if between is not None:
        return None, f"{between.name}, before {main.name}, ends with neither M99 nor M30 or M2"
    return main, ""


_ENDS = {99.0: "M99", 30.0: "M30", 2.0: "M2"}


def _end_code(block: Block) -> str | None:
    """The code that ends a program in the block, M99 (with other words too: `G90 M99`), M30 or M2."""
    if block.signature is not None and "M" not in block.signature:
        return None
    return next((_ENDS[item.value] for item in block.items
                 if type(item) is Word and item.letter == "M" and item.value in _ENDS), None)  # fmt: skip


def _no_code(block: Block) -> bool:
    """A line of comments, a `%` or nothing."""
    return all(
        type(item) is Comment or type(item) is Statement and item.kind == "tape" for item in block.items
    )


def _program_name(block: Block) -> str:
    """`O2000` of a line `O2000 (SUB)`, as written."""
    return next(f"O{item.number}" for item in block.items if type(item) is Word and item.letter == "O")


def _macro_b(block: Block) -> bool:
    """A line with a Fanuc macro statement (IF, WHILE, END, GOTO)."""
    return any(type(item) is Statement and item.kind in _FANUC_FLOW for item in block.items)


def _integer(digits: str) -> int:
    return int("".join(digits.split()))


def sequence_number(block: Block) -> int | None:
    """The block's sequence number (its N word, first but for a block delete), else None."""
    for item in block.items:
        kind = type(item)
        if kind is Word:
            return int(item.value) if item.letter == "N" else None  # type: ignore[union-attr]
        if kind is not Statement or item.kind != "block_delete":  # type: ignore[union-attr]
            return None
    return None


def program_number(block: Block) -> str | None:
    """`n` of a line `O<n>` (a Fanuc program number, or a subprogram's start), else None."""
    for item in block.items:
        if type(item) is Word and item.letter == "O":
            return str(int(round_half_away(item.value)))
        if type(item) is not Comment:
            return None
    return None


def _notable(block: Block) -> bool:
    """A control line, or where a Fanuc subprogram may start."""
    return control_of(block) is not None or program_number(block) is not None


def oword_name(text: str) -> str:
    """`o100`, `O0100`, `o1 00` -> "100"; `o<My Sub>` -> "mysub" (rs274ngc ignores case and spaces)."""
    label = text[1:].strip()
    name = normalise_name(label)  # without case and blanks, a number's too (`o1 00`)
    return name if label.startswith("<") else str(int(name))


def _subroutine_file(folder: Path, name: str) -> Path | None:
    """The file of subroutine `name` in `folder` as rs274ngc names it: the name joined to the
    folder as text (`find_ngc_file`: "folder/name.ngc"), so `o</etc/x>` is folder/etc/x.ngc;
    None for a name that leads out of the folder (`..`), which ncpp does not follow."""
    inside = os.path.abspath(folder)  # (a relative folder, `.`, counts from the working directory)
    path = os.path.normpath(f"{inside}/{name}.ngc")
    return Path(path) if path.startswith(inside.rstrip(os.sep) + os.sep) else None


def _nothing() -> None:
    """The jump of a control line the program left the scope at: none."""


def _program_files(folder: Path, name: str) -> list[Path]:
    """The files Fanuc program `name` may be kept in: `O1234`, `O1234.nc` (and `.NC`, `.txt`),
    the number also as written (`O12` besides `O0012`), or without its O (`1234.nc`, as PC folders of
    programs name them); the file must say `O1234` itself (`_program_from_file`)."""
    stems = dict.fromkeys((f"O{int(name):04d}", f"O{name}", f"{int(name):04d}", name))
    return [Path(folder) / f"{stem}{suffix}" for stem in stems for suffix in ("", ".nc", ".NC", ".txt")]


def _shown(name: str) -> str:
    return name if name.isdigit() else f"<{printable(name)}>"


def _unread(path: Path, name: str, started: bool, numbers: list[str]) -> str:
    """Why program file `path` gave no `O<name>` ... M99 (`Flow._program_from_file`): its O line stands
    in the tape's leader, its program has no M99, its programs are others, or it has no O line at all,
    which a program file ncpp runs for a call must have (no Fanuc or Haas manual ncpp follows says a
    control takes a program's number from its file's name)."""
    above = _above_the_tape(path, name)
    if above:
        return above
    if started:
        return f": O{name} has no M99 after it (a subprogram ends with M99)"
    if numbers:
        others = ", ".join(f"O{n}" for n in numbers)
        return f": its program is {others}, not O{name} (a call runs the program whose O line says O{name})"
    return (
        f": the file has no O line, and ncpp runs a file for a call of O{name} only where the file gives that "
        f"number itself, not from the file's name (put `O{name}` on the line after the file's first `%`)"
    )


def _above_the_tape(path: Path, name: str) -> str:
    """Why a program file's `O<name>` was not read, where it stands above the file's first `%`
    (the tape's leader, which a Fanuc control skips); else nothing."""
    with open(path, "rb") as stream:
        head = stream.read(1 << 16)
    start = re.search(rb"^[ \t]*%", head, re.MULTILINE)
    if start is not None and re.search(
        rb"(?im)^[ \t]*O0*" + name.lstrip("0").encode() + rb"\b", head[: start.start()]
    ):
        return (
            ": it stands above the file's first `%`, and a Fanuc control reads the text before that as "
            "the tape's leader and skips it (put a `%` line above it)"
        )
    return ""
