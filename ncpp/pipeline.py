"""The one NC pipeline every front end runs.

    NC text -> blocks -> interpreter -> passes -> writer -> NC text

`ncpp`, `ncpp compensate`, the LinuxCNC filter and the FreeCAD post all call
`process`; the CL-data postprocessor enters at the events.  With no error
map there are no passes and the output equals the input byte for byte.
"""

from __future__ import annotations

import gc
import hashlib
import re
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field, replace
from itertools import chain, count, islice, tee
from operator import itemgetter
from pathlib import Path
from typing import TYPE_CHECKING, BinaryIO

import numpy as np

from ncpp import __version__
from ncpp.errors import Location, NcppError, Warnings
from ncpp.guard import (
    ISO_SYNTAX,
    Placement,
    PlacementChecks,
    ToolGuard,
    touch_off_ahead,
    with_guard,
    without_guard,
)
from ncpp.lathe import refuse_lathe
from ncpp.motion.flow import MainProgram
from ncpp.motion.offsets import AT_MACHINE_ZERO, WorkOffsets
from ncpp.motion.once import OnceRuns
from ncpp.motion.segments import (
    COMP,
    CYCLE,
    DRILLED,
    FLOW,
    HELD,
    HOLE,
    PATTERN,
    Arc,
    Event,
    Line,
    Pass,
    stores_a_cycle,
)
from ncpp.passes import PASSES, PassContext, run_passes
from ncpp.passes.context import Corrections, ErrorMap, is_directional
from ncpp.passes.inverse import iterations_for
from ncpp.program.blocks import STRAY_TAPE, Block, Comment, Statement, Word
from ncpp.program.dialects import FAMILY, dialect_tools, get_dialect, parse_program
from ncpp.program.dialects.iso import ChecksAfter, ChecksBefore, IsoWriter
from ncpp.program.parser import LEADER_LINES
from ncpp.runtime import keep_freed_memory
from ncpp.summary import Summary

if TYPE_CHECKING:
    from ncpp.verify import Following

HEADER_TAG = "ncpp compensated"  # (lower case: `header_comment` finds it in any case)
HEADER_SCAN = 30  # blocks at the top searched for an earlier header, and on while only comments follow
# Blocks the parser reads ahead of the interpreter at most (`_parsed_ahead`), and in its
# first run: ~0.8 kB each (16k: 13 MB, whatever the program's length).
PARSED_AHEAD = 16384
FIRST_RUN = 1024


@dataclass
class ErrorSource:
    """The error map to compensate with, and how the header names it."""

    model: ErrorMap  # Machine or a measured map
    name: str
    digest: str
    max_correction: float = 0.5
    limits: dict = field(default_factory=dict)
    rotary_xyz_are_axis_positions: bool = False  # the machine file's [compensation] key
    kinematics_m_codes: tuple[int, ...] = ()  # and the M codes it says switch the kinematics

    @classmethod
    def from_machine_file(cls, path: str) -> ErrorSource:
        from ncpp.machine import load_machine

        machine = load_machine(path)
        limits = {a: lim for a, lim in machine.limits.items()}
        rotary = machine.rotary_xyz_are_axis_positions
        return cls(
            MachineMap(machine),
            Path(path).name,
            _digest(path),
            machine.max_correction_mm,
            limits,
            rotary,
            machine.kinematics_m_codes,
        )

    @classmethod
    def from_measurement(cls, path: str) -> ErrorSource:
        from ncpp.passes.measured import map_from_file

        return cls(map_from_file(path), Path(path).name, _digest(path))


@dataclass(frozen=True, eq=False)
class MachineMap:
    """A machine as compensation sees it: geometry plus its position-only effects
    (backlash, servo lag and spikes depend on the motion and are left to the control)."""

    machine: object

    def deviation(self, P, direction=None, tool_offset=None):
        return self.machine.static_deviation(P, direction, tool_offset)

    @property
    def bow_bound(self):
        """`Machine.bow_bound`: what keeps lines whole unsampled (`passes/subdivide.py`)."""
        return self.machine.bow_bound

    @property
    def ripple(self):
        """`Machine.ripple`: how short the cyclic effects make the pieces (`passes/subdivide.py`)."""
        return self.machine.ripple


def _digest(path: str) -> str:
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]


@dataclass
class Stats:
    lines_in: int = 0
    lines_out: int = 0
    summary: Summary | None = None  # what a compensating run did


def header_text(source: ErrorSource, tolerance: float, offsets: WorkOffsets | None = None, dialect: str = "iso") -> str:  # fmt: skip
    """The output's first comment: what compensated it, for which machine file (its hash), how closely;
    with `offsets`, more lines (`header.placement_lines`): where it was placed, with which tool table."""
    first = f"{HEADER_TAG} for {source.name} sha256:{source.digest} tolerance {tolerance:g} mm by ncpp {__version__}"
    if offsets is None:
        return first
    from ncpp.header import placement_lines

    return "\n".join([first, *placement_lines(offsets, dialect)])


def refuse_compensated(blocks: Iterable[Block], file: str) -> Iterator[Block]:
    """Pass blocks through; stop with an error if an ncpp header is found in the program's head."""
    blocks = iter(blocks)
    for block in program_head(blocks):
        item = header_comment(block)
        if item is not None:
            raise NcppError(
                "program is already compensated by ncpp (use --force to compensate again)",
                Location(file, block.line, item.start + 1),
            )
        yield block
    yield from blocks


def program_head(blocks: Iterator[Block]) -> Iterator[Block]:
    """The blocks an ncpp header may stand among: the first HEADER_SCAN, and on from there up
    to the first block with more than comments (any number of comments may come before it)."""
    for n, block in enumerate(blocks):
        yield block
        if n >= HEADER_SCAN - 1 and not _comments_only(block):
            return


# `%` (a tape mark or, in grbl's programs, a `%` it does not read), `%_N_PART_MPF`, `BEGIN PGM`
_HEAD_STATEMENTS = frozenset({"tape", STRAY_TAPE, "program_name", "program_begin"})


def _comments_only(block: Block) -> bool:
    """Nothing in the block but comments, a block number, a tape mark or the program's name."""
    return all(type(i) is Comment or (type(i) is Word and i.letter == "N") or (type(i) is Statement and i.kind in _HEAD_STATEMENTS)
               for i in block.items)  # fmt: skip


def header_comment(block: Block) -> Comment | None:
    """The block's comment that is an ncpp header, whatever its case (every dialect's comments:
    `( )`, `;`), or None."""
    for item in block.items:
        if type(item) is Comment and HEADER_TAG in item.text.lower():
            return item
    return None


# Why moves are left as programmed (`Line.fixed`), as the warning says it
UNCOMPENSATED = {
    CYCLE: "canned cycle: its moves pass through uncompensated, from its programmed start (the holes are where the "
    "program puts them, with the machine's errors); compensation resumes with the next move",
    FLOW: "loop or subroutine: its moves pass through uncompensated (one text runs several times, "
    "or away from where it stands, so it cannot carry one correction); compensation resumes with the next move after it "
    "(--expand writes an ISO, Klartext or Sinumerik program's loops and subroutines out as straight code, "
    "each move compensated)",
    DRILLED: "drilling cycle: it drills where the move before it leaves the tool (X and Y compensated), its moves "
    "along the tool axis as programmed (the depth with the machine's error); compensation resumes with the next move",
    PATTERN: "hole pattern: the control places its holes and moves between them itself, from one block that "
    "cannot carry a correction for each: its holes and moves pass through uncompensated, where the pattern puts "
    "them; compensation resumes with the next move",
    COMP: "cutter compensation: its moves pass through uncompensated (the control offsets them by the tool radius, "
    "so the tool is not where their points are; ncpp follows it in ISO programs in G17 and G18 without a lathe "
    "tool orientation, and in Klartext and Sinumerik in every working plane, but not in loops and subroutines, "
    "at Fanuc corners, in a Klartext or Sinumerik entry or exit arc, or where a block turns it to the other "
    "side); compensation resumes with the next line it follows, or after the first move with it off (G40, R0), "
    "or after the move that one's Fanuc corner rounds into",
}
# An entry move under cutter compensation whose tool centre ends on its point: the radius is unknown
UNKNOWN_RADIUS = (
    "cutter compensation with the tool radius not known (G41/G42 and no tool table: --tool-table; in Klartext no "
    "R in TOOL.T or TOOL DEF, in Sinumerik none in _N_TO_INI): its moves are corrected for their programmed points, "
    "from which the tool centre stands off by that radius"
)
INCREMENTAL_CYCLE = (
    "a G91 move right after a canned cycle in G90: it starts where the cycle left the tool (a G98 retract "
    "ends at the compensated level the cycle started from), which ncpp does not follow; from this line on "
    "the program passes through uncompensated"
)

UNKNOWN_SETTING = (
    "G92, G10 L10/L11/L20 or PRESETON right after moves left as programmed in G90: it sets an offset from where the control "
    "stands, which ncpp does not know exactly there; from this line on the program passes through uncompensated"
)

UNKNOWN_STEP = (
    "this line runs a loop or subroutine in which interpretation ends, right after moves left as programmed in "
    "G90: ncpp does not know exactly where the control stands there, so it writes no step back to the programmed "
    "point before it; an offset the loop or subroutine sets from where the control stands (G92, G10 L10/L11/L20), "
    "and every move after it, may carry a correction; from this line on the program passes through uncompensated"
)


def warn_fixed(events: Iterable[Event], warnings: Warnings, file: str) -> Iterator[Event]:
    """Pass events through; warn where a series of moves the passes leave as programmed
    (`fixed`, UNCOMPENSATED: a canned cycle's, a drilling cycle's along the tool axis, a hole
    pattern's, a loop's or a subroutine's, or those under cutter compensation) starts (refused
    with --strict).

    In G91 such a move starts from where the control is (the compensated position): the
    moves of loops and subroutines and those under cutter compensation run their increments
    from there, which apply_error_map follows (`_carry`); a cycle after a compensated move
    starts from its programmed start, stepped to (`apply_error_map._lead_in`).  A cycle in G90 goes to its
    programmed points, but its G98 retract ends at the compensated level it started from:
    from a G91 move right after one, the rest of the program passes through, as after an
    out-of-scope construct."""
    events = iter(events)
    series = ""  # why the moves of the series under way are fixed ("": none is)
    absolute = True  # whether the series' last move was in G90
    # the last warning's reason and block, while that block's moves go on (a pattern's holes: one warning)
    said: tuple[str, Block] | None = None
    for event in events:
        kind = type(event)
        if kind is Line or kind is Arc:  # (not a Pass, nor a dialect's own: Klartext's pole)
            fixed = event.fixed  # type: ignore[union-attr]
            if stores_a_cycle(event):  # type: ignore[arg-type]
                yield event
                continue
            if said is not None and said[1] is not event.block:
                said = None
            cycle = series == CYCLE or series == HOLE
            # (a G91 move before the program names G0-G3 runs its increment from there too)
            if (not fixed or fixed == HELD) and cycle and absolute and not event.context.absolute:  # type: ignore[union-attr]
                yield from _passed_on(event, events, warnings, file)
                return
            # (a G28/G30's moves are the control's own)
            if fixed and fixed != series and fixed in UNCOMPENSATED and (said is None or said[0] != fixed):
                warnings.warn(UNCOMPENSATED[fixed], Location(file, event.block.line, 1))
                said = (fixed, event.block)
            shift = event.centre_shift  # type: ignore[union-attr]
            if shift is not None and shift[0] is None and not any(shift[1]):
                warnings.warn(UNKNOWN_RADIUS, Location(file, event.block.line, 1))
            series, absolute = fixed, event.context.absolute  # type: ignore[union-attr]
        elif kind is Pass and event.setting is not None and series in UNCOMPENSATED and absolute:  # type: ignore[union-attr]
            why = UNKNOWN_SETTING if event.setting.values else UNKNOWN_STEP  # type: ignore[union-attr]
            yield from _passed_on(event, events, warnings, file, why)
            return
        yield event


def _passed_on(
    first: Event, rest: Iterator[Event], warnings: Warnings, file: str, why: str = INCREMENTAL_CYCLE
) -> Iterator[Pass]:
    """`first`'s block (none of its events went by yet) and every later one, as `Pass`."""
    warnings.warn(why, Location(file, first.block.line, 1))
    last = None
    for event in chain((first,), rest):
        if event.block is not last:
            last = event.block
            yield Pass(event.block)


def _parsed_ahead(blocks: Iterable[Block], most: int = PARSED_AHEAD) -> Iterator[Block]:
    """The blocks, parsed in runs ahead of the interpreter: the first alone, then runs of
    FIRST_RUN blocks, each twice the last up to `most`.

    Each stage running over many lines at once is faster than the stages taking turns a
    line at a time.  A run that meets a line the parser refuses is passed on first: a fault
    in an earlier line is reported first, as without runs."""
    blocks = iter(blocks)
    yield from islice(blocks, 1)
    size = FIRST_RUN
    while True:
        run: list[Block] = []
        try:
            run.extend(islice(blocks, size))
        except NcppError:  # (as the passes' batches: `ncpp/passes/__init__.py`)
            yield from run
            raise
        if not run:
            return
        yield from run
        size = min(2 * size, most)


def _counted(
    blocks: Iterable[Block], counter: Iterator[int], progress: Callable[[int], None] | None
) -> Iterator[Block]:
    """The blocks, each taking a number from `counter` (itertools.count: the next number
    it gives is how many went by); `progress` is told every 1000."""
    if progress is None:  # zip and itemgetter run in C: no Python frame per block
        return map(itemgetter(0), zip(blocks, counter))
    return _reported(blocks, counter, progress)


def _reported(
    blocks: Iterable[Block], counter: Iterator[int], progress: Callable[[int], None]
) -> Iterator[Block]:
    for block, n in zip(blocks, counter):
        if (n + 1) % 1000 == 0:
            progress(n + 1)
        yield block


# A line of a program's text: its number, or a G or M code or an X Y Z word first (a leader's own
# directives are comments)
_PROGRAM_TEXT = re.compile(r"[ \t]*(?:N\d+[ \t]*)?(?:[O:]\d|[GM]\d|[XYZ][-+.\d])", re.IGNORECASE)


def _leader_told(blocks: Iterable[Block], warnings: Warnings, file: str) -> Iterator[Block]:
    """The blocks, with a warning where the tape leader above the file's first `%` (which a Fanuc
    control skips: `parser._leader`) holds a program's lines, as a file whose only `%` closes it
    does: the control reads none of them, and ncpp compensates none of them."""
    blocks = iter(blocks)
    for block in blocks:
        if not block.verbatim:
            yield block
            break
        if _PROGRAM_TEXT.match(block.raw):
            warnings.warn(
                "this line stands above the file's first `%`, which a Fanuc control takes for the start of "
                "the tape: the lines above it are the tape's leader, which the control skips, and they pass "
                "through as they are, none compensated (put a `%` line above the program)",
                Location(file, block.line, None),
            )
            yield block
            break
        yield block
    yield from blocks


def _continued(blocks: Iterable[Block], tally: list[int]) -> Iterator[Block]:
    """The blocks, adding to tally[0] the lines past its first each spans (its raw text holds their ends)."""
    for block in blocks:
        tally[0] += block.raw.count("\n")
        yield block


def with_header(lines: Iterable[str], header: str, writer: IsoWriter, leader: bool = False) -> Iterator[str]:
    """Put the header comment first (a comment line per line of it), after a leading `%`
    tape mark line, or the first `%` below a tape leader the dialect's controls skip
    (`leader`), or where the dialect's writer puts it (Heidenhain after `BEGIN PGM`)."""
    own = getattr(writer, "with_header", None)
    if own is not None:
        yield from own(lines, header)
        return
    it = iter(lines)
    head: list[str] = []
    for line in it:  # (no further than the `%`: the verifier tags lines by how far the writer had read)
        head.append(line)
        if line.lstrip(" \t").startswith("%") or len(head) >= (LEADER_LINES if leader else 1):
            break
    eol = "\r\n" if head and head[0].endswith("\r\n") else "\n"
    comments = [writer.comment(line) + eol for line in header.split("\n")]
    at = len(head) if head and head[-1].lstrip(" \t").startswith("%") else 0
    yield from head[:at]
    yield from comments
    yield from head[at:]
    yield from it


# mm: the inverse map's residual allowed in a command, a quarter of the last digit mm
# programs are written with (the rounding to it is up to twice as large)
INVERSE_BUDGET = 0.000025


def make_context(
    source: ErrorSource,
    tolerance: float,
    warnings: Warnings,
    file: str,
    corrections: Corrections | None = None,
) -> PassContext:
    """The pass context every front end (filter, compensate, post) compensates with; `corrections`:
    where the largest correction made is noted (the verifier's bound follows it, `verify_bound`)."""
    return PassContext(
        model=source.model,
        tolerance=tolerance,
        max_correction=source.max_correction,
        rotary_xyz_are_axis_positions=source.rotary_xyz_are_axis_positions,
        kinematics_m_codes=source.kinematics_m_codes,
        limits=source.limits,
        directional=is_directional(source.model, source.limits),
        iterations=iterations_for(source.model, source.limits, INVERSE_BUDGET),
        warnings=warnings,
        file=file,
        corrections=corrections if corrections is not None else Corrections(),
    )


def verify_bound(source: ErrorSource, tolerance: float, corrections: Corrections) -> Following:
    """How far the written path may lie from the input's as a run goes on: the largest correction
    compensation has made so far (`geometry.compensate`) plus the tolerance; never more than the
    machine file's `max_correction_mm` plus the tolerance."""
    from ncpp.verify import Following

    return Following(source.max_correction + tolerance, tolerance, lambda: corrections.largest)


def process(
    stream: BinaryIO,
    out: BinaryIO,
    *,
    file: str = "<stdin>",
    source: ErrorSource | None = None,
    tolerance: float = 0.001,
    strict: bool = False,
    force: bool = False,
    warnings: Warnings | None = None,
    progress: Callable[[int], None] | None = None,
    dialect: str | None = None,
    offsets: WorkOffsets | None = None,
    verify: bool = True,
    guard: Placement | None = None,
    expand_cycles: bool = False,
    expand: bool = False,
    guard_tools: bool = False,
) -> Stats:
    """Read, interpret, compensate (when `source` is given) and write one program.

    The dialect is detected from the content (and the file name) unless given;
    it picks the interpreter and the writer (`ncpp.program.dialects.UNITS`).  `offsets`: the zeros
    the control holds (machine mm; none: the program zero is the machine zero),
    which place the program on the machine whose errors are compensated.
    `expand_cycles`: an ISO program's canned cycles are written as G0/G1 blocks (and G4 dwells);
    `expand`: its loops and subroutines are written out as straight code (`motion/expand.py`).

    A compensated program is verified as it is written (`ncpp/verify.py`): read back
    and compared with a reading of the input of its own; where they part an
    NcppError stops the run, and what `out` took so far must be thrown away (the
    command line writes to a temporary file or a spool).  `verify=False` skips it.  `guard`: where
    the program must find the control's work offset, checked at its start (`ncpp/guard.py`);
    `guard_tools`: the tool lengths of the told tool table are checked where the program applies them."""
    warnings = warnings or Warnings(strict=strict)
    if source is None:
        stats = _copied(stream, out, dialect, progress)
        warnings.finish()
        return stats
    stats = Stats()
    name, parsed = parse_program(stream, file, dialect)
    interpret, writer_class = dialect_tools(name)
    counter = count()
    blocks: Iterable[Block] = _counted(_parsed_ahead(parsed), counter, progress)
    continued = [0]  # the lines past their first that `~`-continued blocks span
    if get_dialect(name).continuation is not None:
        blocks = _continued(blocks, continued)
    if not force:
        blocks = refuse_compensated(blocks, file)
    else:  # compensated again: the guard of the offset it was compensated for goes
        blocks = without_guard(blocks, lambda block, said: warnings.warn(
            f"compensated again, the check \"{said}\" goes, and ncpp checks the parameter again only where "
            "the program still reads it: numbers after it may have been computed from that value of the tool "
            "table it was compensated with; compensate the original program instead",
            Location(file, block.line, None)))  # fmt: skip
    blocks = refuse_lathe(blocks, name, file)  # (ncpp's machine is a machining centre)
    if get_dialect(name).leader:
        blocks = _leader_told(blocks, warnings, file)
    offsets = offsets or AT_MACHINE_ZERO  # the control's zeros place the program on the machine
    checks = (  # the zeros of the told systems it selects, and the G92 offsets it sets (LinuxCNC's)
        PlacementChecks(offsets, name, guard.unit_mm, lambda why: warnings.warn(
            f"no placement guard: {why}", Location(file, 1, None))) if guard is not None and name in ISO_SYNTAX else None
    )  # fmt: skip
    if checks is not None:
        blocks = _touch_off_told(blocks, checks)
    expanding: dict[str, bool] = {}
    if FAMILY[name] == "iso":
        expanding = {"expand_cycles": expand_cycles, "expand": expand}
    elif FAMILY[name] in ("heidenhain", "sinumerik"):
        expanding = {"expand": expand}
    # a subroutine that runs once is rewritten for that run where its definition stands (ISO family,
    # Klartext): its blocks, which the interpreter tells the writer (both readings of the input follow it so)
    runs = OnceRuns() if FAMILY[name] in ("iso", "heidenhain") and not expand else None
    if verify:  # the verifier's own reading of the input: the blocks are held between the two
        # readings, not the events (a loop's runs read its few blocks again and again)
        from ncpp.verify import same_motion, unsaid

        written_out = any(expanding.values())
        blocks, again, *plain = _copies(blocks, 3 if written_out else 2)
        held = {"once_runs": OnceRuns()} if runs is not None else {}  # (Sinumerik has none)
        original = interpret(again, file=file, warnings=unsaid(), offsets=offsets, **expanding, **held)
        if written_out:  # (and that reading against one without --expand: the program's own run)
            original = same_motion(
                original, interpret(plain[0], file=file, warnings=unsaid(), offsets=offsets), file
            )
    # which of a Fanuc or Haas file's programs runs as the main one: the flow tells, the guard goes there
    main = MainProgram() if FAMILY[name] == "iso" else None
    tools = _tool_guard(name, offsets, warnings, file) if guard_tools else None
    if tools is not None and name == "iso":  # (LinuxCNC's tool parameters: the reads to check)
        expanding["guard_reads"] = True
    events: Iterable[Event] = interpret(
        blocks, file=file, warnings=warnings, strict=strict, offsets=offsets, **expanding,
        **({"once_runs": runs} if runs is not None else {}), **({"main_program": main} if main is not None else {}),
    )  # fmt: skip
    events = warn_fixed(events, warnings, file)  # cycles, loops, subroutines (ISO), cutter compensation
    stats.summary = summary = Summary(file)
    warnings.listeners.append(summary.heard)
    writer = writer_class()
    writer.once_runs = runs
    reached = _Reached()  # (how far the writer has read: the verifier tags the written lines by it)
    writer.stamps = reached
    writer.unpositioned = lambda axes, block: warnings.warn(
        f"{axes} not positioned by the program yet: the correction along {axes} of this feed move and "
        "the next compensated moves is left out until the program positions them (a word written here "
        "would move the axis from wherever the control has it)", Location(file, block.line, None))  # fmt: skip
    writer.unplaced_setting = lambda axes, events: _warn_unplaced(axes, events, checks, warnings, file)
    writer.unstepped = lambda block: warnings.warn(
        "this line runs a loop or subroutine in which interpretation ends, after a compensated move, in a mode "
        "other than G0 or G1 (an arc's, a canned cycle's), which a step back to the programmed point would change: "
        "an offset the loop or subroutine sets from where the control stands (G92, G10 L10/L11/L20), and every move "
        "after it, may carry that move's correction; end the mode (G80, or a G0/G1 move) before the loop or call",
        Location(file, block.line, None))  # fmt: skip
    if expand and FAMILY[name] == "heidenhain":  # (the blocks written out take numbers of their own)
        writer.renumber = True
    keep_freed_memory()  # numpy's temporaries reuse the heap, not fresh pages (runtime.py)
    ctx = make_context(source, tolerance, warnings, file)
    compensated = reached.follow(summary.written(run_passes(summary.programmed(events), ctx, PASSES)))
    header = header_text(source, tolerance, offsets, name)
    before, after = _guards(checks, tools)
    lines = with_header(writer.write(compensated, after, before), header, writer, get_dialect(name).leader)
    if guard is not None:
        said = replace(guard, dialect=name).said()  # (as the program's dialect names the system)
        lines = with_guard(lines, guard, name, HEADER_TAG, header.count("\n") + 1,
                           lambda why: warnings.warn(f"no placement guard: {why}; make sure the control has {said} "
                                                     "before the program runs", Location(file, 1, None)), checks is not None, main)  # fmt: skip
    if verify:
        from ncpp.verify import verified

        lines = verified(lines, reached, original, file=file, dialect=name, offsets=offsets, runs=runs,
                         bound=verify_bound(source, tolerance, ctx.corrections))  # fmt: skip
    lines = iter(lines)
    # (a number past a float's range, such as a tool 1e308 mm long, becomes inf or NaN, which the
    # checks before writing refuse with its line: numpy's warnings on the way would say it first, unlocated)
    with (
        _rare_collections(),
        np.errstate(over="ignore", invalid="ignore"),
        warnings.in_line_order() as release,
    ):
        while batch := list(islice(lines, 4096)):  # written in batches: one encode and write per 4096 lines
            release(reached.before - 1)  # (the writer may still warn of the block before the one it took)
            text = "".join(batch)
            out.write(text.encode("latin-1"))
            stats.lines_out += text.count("\n") + (not text.endswith("\n"))  # (a block may be continued)
    stats.lines_in = next(counter) + continued[0]
    if stats.summary is not None:
        stats.summary.lines_in, stats.summary.lines_out = stats.lines_in, stats.lines_out
    warnings.finish()
    return stats


def _guards(
    checks: PlacementChecks | None, tools: ToolGuard | None
) -> tuple[ChecksBefore | None, ChecksAfter | None]:
    """The writer's `before` and `after`: the placement guard's checks, then the tool guard's (the
    tool parameters a block reads before it, the length it applies after it)."""
    if tools is None:
        return (checks.before, checks.after) if checks is not None else (None, None)
    if checks is None:
        return tools.before, lambda events, unplaced: tools(events)
    return (
        lambda events: [*checks.before(events), *tools.before(events)],
        lambda events, unplaced: [*checks.after(events, unplaced), *tools(events)],
    )


TOUCH_OFF_SCAN = 40  # the blocks at the top a touch-off made first is looked for among (`touch_off_ahead`)


def _touch_off_told(blocks: Iterable[Block], checks: PlacementChecks) -> Iterator[Block]:
    """The blocks, `checks` told first of the touch-off the program makes before anything relies on a
    system's zero (`guard.touch_off_ahead`, among the first TOUCH_OFF_SCAN): a fault the parser meets
    there is raised where its line comes."""
    blocks = iter(blocks)
    first: list[Block] = []
    try:
        first.extend(islice(blocks, TOUCH_OFF_SCAN))
    except NcppError:
        yield from first
        raise
    checks.touch_off = touch_off_ahead(first, checks.offsets)
    yield from first
    yield from blocks


def _warn_unplaced(
    axes: list[str], events: list[Event], checks: PlacementChecks | None, warnings: Warnings, file: str
) -> None:
    """The warning of a G92 / G10 L20 (its events) that sets the offset of `axes`, which the program
    has not positioned, from where the control stands; it says whether the placement guard checks it."""
    block = events[0].block
    checked = checks is not None and checks.checks_offset(events, axes)
    then = (
        "; the placement guard's check after it stops the program where the offset it sets differs from that"
        if checked else ""
    )  # fmt: skip
    warnings.warn(
        f"this block sets its offset from where the control stands, and the program has not positioned "
        f"{' and '.join(axes)} yet: ncpp compensates the moves after it as if the tool stood at the program's "
        f"zero there (the work offset's zero){then}; jog it there before the program runs, or set the zero as a "
        "work offset (G10 L20, touch-off) and compensate for it", Location(file, block.line, None))  # fmt: skip


def _tool_guard(dialect: str, offsets: WorkOffsets, warnings: Warnings, file: str) -> ToolGuard | None:
    """The tool guard's checks where ncpp was told the tool table (`guard.ToolGuard`), else None
    (and a warning where the dialect has none)."""
    if offsets.tools is None:
        return None
    told = offsets.tools.source
    guard = ToolGuard(dialect, offsets.unit_mm, lambda why: warnings.warn(
        f"no tool guard: {why}; make sure the control's tool lengths are those of {told}", Location(file, 1, None)))  # fmt: skip
    return guard if guard.why is None else None


def _copies(blocks: Iterable[Block], n: int) -> tuple[Iterator[Block], ...]:
    """`n` readings of the blocks, each raising the parser's fault where it meets it (`tee` hands
    an error to the reading that meets it first, and the others find the program ended there)."""

    def carried() -> Iterator[Block | NcppError]:
        try:
            yield from blocks
        except NcppError as err:
            yield err

    def raised(items: Iterator[Block | NcppError]) -> Iterator[Block]:
        for item in items:
            if isinstance(item, NcppError):
                raise item
            yield item

    return tuple(raised(copy) for copy in tee(carried(), n))


def _copied(
    stream: BinaryIO, out: BinaryIO, dialect: str | None, progress: Callable[[int], None] | None
) -> Stats:
    """With nothing to compensate, the program as it is, byte for byte: not read as a program
    at all, so nothing a control would run is refused or changed on the way."""
    if dialect is not None:
        get_dialect(dialect)  # an unknown name is an error still
    stats = Stats()
    for line in stream:
        out.write(line)
        stats.lines_in += 1
        if progress is not None and stats.lines_in % 1000 == 0:
            progress(stats.lines_in)
    stats.lines_out = stats.lines_in
    return stats


class _Reached:
    """How far the writer has read: the input line of the last event it took and of the block
    before it (a writer may take a block's first event before it writes the lines of the block
    before), and how many blocks it has taken, in the order they run (loops run lines again).
    `verify.verified` tags written lines with these."""

    def __init__(self) -> None:
        self.line = self.before = self.blocks = 0
        self.block: Block | None = None
        self.state = (0, 0, 0)  # (a new tuple only when it changes: the verifier tells it by `is`)
        self.pinned: tuple[int, int, int] | None = None  # the state the lines handed out now are tagged with

    def follow(self, events: Iterable[Event]) -> Iterator[Event]:
        for event in events:
            block = event.block
            if block is not self.block:
                self.block = block
                self.blocks += 1
                if block.line != self.line:
                    self.before, self.line = self.line, block.line
                self.state = (self.line, self.before, self.blocks)
            yield event

    def pin(self, state: tuple[int, int, int] | None) -> None:
        """Tag the lines handed out from now with `state` (a subroutine's run written at its
        definition: `iso._AtDefinition`); None: with the state again."""
        self.pinned = state

    def __call__(self) -> tuple[int, int, int]:
        return self.state if self.pinned is None else self.pinned


@contextmanager
def _rare_collections(threshold: int = 1_000_000) -> Iterator[None]:
    """Run the cyclic garbage collector less often while a program streams through.

    Every line makes a few short-lived objects (a block, its words, events, strings)
    that reference counting frees; the collector runs when allocations outnumber
    frees by the threshold, and that count includes the tens of thousands of objects
    in flight (a `replace_arcs` batch with its blocks and words, the parser's run
    ahead), which a lower threshold would have it walk again and again for nothing.
    Memory stays flat: a whole program leaves a few thousand objects in cycles at most."""
    old = gc.get_threshold()
    gc.set_threshold(max(old[0], threshold), *old[1:])
    try:
        yield
    finally:
        gc.set_threshold(*old)
