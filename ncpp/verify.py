"""The verifier: a written program must do what the program it was made from does.

Compensation moves each point of a path by the correction the machine's errors ask
for there.  Before a rewritten program leaves ncpp, the verifier reads the written
text back with a fresh parser and interpreter (nothing of the passes' state) and
compares it with the input program's motion:

* the same actions in the same order: tool changes and length offsets,
  spindle, coolant, dwells, stops, other M codes, Klartext's TOOL CALL and
  cycle calls, program end (stops, ends, M99 and CYCL CALL POS counted after
  their block's move, where the control acts);
* between two actions, every point of the written path within the bound of
  the input's path, and every point of the input's path within it of the
  written path (rotary and other extra axes count their unit as a mm, so a
  rotation carried by the wrong piece leaves the path);
* rapids where the input rapids and feeds where it feeds, at the same feed
  rates in the same order; in inverse time (G93) the pieces of a move take
  its time together.

The bound of a compensating run (`Following`) is the largest correction compensation
has made so far in the program (noted where every command is computed,
`geometry.compensate`), plus the tolerance and the written numbers' rounding, and
never more than the machine file's `max_correction_mm` plus the tolerance: a move
the compensation did not ask for lies further off.  It is read as each section is
compared, once the written program's lines of it are read back (the passes have
made their corrections), and the section is sampled then.

Paths are compared in machine coordinates (mm, tool length and work offsets
applied); under cutter compensation ncpp follows, the path compared is the tool
centre's as the control joins the offset moves (`ncpp.motion.centre_path`), so a short
move written turned round, which the control offsets to its other side, is told
apart from one a µm off.  They are compared as straight segments, arcs in chords within an eighth of the bound:
a segment of one path whose two ends lie within the bound of one segment of
the other (or of two of a few that follow one another, less how far the
vertices between lie from the line between the ends' closest points) lies
within it along its length; any other is looked at at points a quarter of the
bound apart.  Every point passed lies within 1.6 times the
bound, and no correction within the bound is refused.  A violation is an
`NcppError` at the input line where it happens.

A long run of moves between two actions is compared in chunks of about
`CHUNK_MOVES` moves (memory stays flat in program length).  The pipeline tags
each written line with the input line the writer had reached (`verified`), and
the written program's chunk ends where the input's does by those tags; as a
writer may be a block ahead of the lines it hands out, each side of a chunk is
also compared with the other side's samples just across the cut.  A loop's or a
call's runs are its control line's moves, cut at the same counts on both sides; the
one run of a subroutine written where its definition stands (`Interpreter.run`) is
read so on both sides, its lines tagged as where they ran (a definition before its call: no
chunk ends before text that does not run, which its lines also are where they stand).
"""

from __future__ import annotations

import io
import math
import re
from bisect import bisect_right
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from dataclasses import dataclass, field, replace
from functools import lru_cache
from itertools import islice
from typing import BinaryIO

import numpy as np
from scipy.spatial import cKDTree

from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion.centre_path import CentrePath
from ncpp.motion.offsets import AT_MACHINE_ZERO, WorkOffsets
from ncpp.motion.once import MAX_ONCE, OnceRuns
from ncpp.motion.segments import EXTRA_AXES, PLANE_AXES, Arc, Event, Line, Pass
from ncpp.program.actions import actions_of
from ncpp.program.blocks import Block, Word

CHUNK_MOVES = 4096  # moves of the input compared at a time between two actions
# Events of a written program held for a subroutine's one run (`_interpreted`): the written lines of
# the input's MAX_ONCE (its moves split into pieces, with steps between them)
WRITTEN_HELD = 8 * MAX_ONCE
MAX_CHORDS = 1 << 19  # chords the arcs of a section are sampled along at most (about 1 kB of memory each)
ACROSS = 0.25  # the share of a neighbouring chunk's samples each side is also compared with


Position = tuple[int, int]  # where in the input a chunk ends: (blocks run, moves of the last of them before)


@dataclass(frozen=True)
class Action:
    """What a block does besides moving, as text two programs can be compared by."""

    text: str
    line: int


@dataclass
class Section:
    """The motion between two actions (or a chunk of it, `cut`), sampled; `action` is the
    one that ends it (None at a cut and at the program's end)."""

    # Straight segments (arcs in chords within `Bound.chord`), their starts and ends: (n, 4) machine
    # mm X Y Z, or (n, 10) with A B C U V W (each in its own unit) after them, and last a
    # coordinate that is 0 for a feed and `Bound.apart` for a rapid
    starts: np.ndarray
    ends: np.ndarray
    rapid: np.ndarray  # (n,) bool
    lines: np.ndarray  # (n,) source line of each segment
    feeds: list[tuple[float, int]]  # G94/G95 feed rates in order, each once per run, with its first line
    inverse_time: float  # minutes the G93 moves take
    action: Action | None
    first_line: int
    cut: Position | None = None  # a chunk's end, where the next chunk starts (None: not a chunk)


NO_EXTRA = (0.0,) * len(EXTRA_AXES)


@dataclass
class _Moves:
    """Moves collected for one section (in flat lists: a move's own work is a few appends, and
    one array is made of each list), sampled when the comparison takes it (`sample`), with the
    bound as it stands then."""

    points: list = field(default_factory=list)  # per move x0 y0 z0 x1 y1 z1, program coordinates
    lines: list = field(default_factory=list)  # per move the line its samples are told by
    frames: list = field(default_factory=list)  # (first move, context) where the context changes
    frame: object = None  # the last context
    extra: dict = field(default_factory=dict)  # move -> its extra axes' start and end, where any is not 0
    rapids: list = field(default_factory=list)  # the moves that are rapids
    arcs: list = field(default_factory=list)  # per arc: its move and its turn
    centres: list = field(default_factory=list)  # per arc its centre's x y z, program coordinates
    feeds: list = field(default_factory=list)
    feed: float = math.nan  # the last feed move's F and units (a new one is looked at)
    feed_inch: bool = False
    inverse_time: float = 0.0
    action: Action | None = None  # the action that ends the section (None: a cut, or the program's end)
    first_line: int = 1
    cut: Position | None = None  # a chunk's end, where the next chunk starts (None: not a chunk)
    # under cutter compensation: where the tool centre runs, and the last move added along it
    centre_path: CentrePath = field(default_factory=CentrePath)
    centre_last: int = -2
    centre_in_plane: int = -1  # the last move along it in the plane (the moves after it stand)

    def closed(self, action: Action | None, first_line: int, cut: Position | None = None) -> _Moves:
        """The moves, told the action that ends them (or the `cut` of a chunk) and their first line."""
        self.action, self.first_line, self.cut = action, first_line, cut
        return self

    def sample(self, bound: Bound) -> Section:
        """The moves as segments, arcs in chords within `bound.chord` (each move from its start to
        its end, both included)."""
        action, first_line = self.action, self.first_line
        if not self.lines:
            empty = np.zeros((0, 4))
            return Section(
                empty,
                empty,
                np.zeros(0, bool),
                np.zeros(0, int),
                self.feeds,
                self.inverse_time,
                action,
                first_line,
                self.cut,
            )
        raw = np.array(self.points, dtype=float).reshape(-1, 2, 3)  # (move, its start and end, X Y Z)
        firsts = [first for first, _ in self.frames]
        spans = np.diff(firsts + [len(raw)])  # each context's moves
        # (np.repeat, not indexing: numpy's indexing by an array of rows is many times slower)
        offsets = np.repeat([f.offset for _, f in self.frames], spans, axis=0)
        units = np.repeat([f.unit_mm for _, f in self.frames], spans)[:, None]
        raw += offsets[:, None]
        raw *= units[:, None]
        starts, ends = raw[:, 0], raw[:, 1]
        if self.extra:
            extra = np.zeros((len(raw), 2 * len(EXTRA_AXES)))
            for k, (s, e) in self.extra.items():
                extra[k] = s + e
            starts = np.hstack((starts, extra[:, : len(EXTRA_AXES)]))
            ends = np.hstack((ends, extra[:, len(EXTRA_AXES) :]))
        counts = np.ones(len(starts), dtype=np.int64)
        arcs = None
        if self.arcs:
            axes = np.repeat([PLANE_AXES[f.plane][:2] for _, f in self.frames], spans, axis=0)
            arcs = _Arcs(self.arcs, self.centres, axes, starts, ends, offsets, units)
        if arcs is not None:
            counts[arcs.move] = arcs.chords(bound.chord)
            # (the section's samples are held at once; a move's chords are rounded up, so the pieces a
            # written program makes of an arc take up to one more each than the arc)
            if counts.sum() > MAX_CHORDS + len(counts):
                k = int(np.argmax(counts))
                raise NcppError(
                    f"verification: an arc of {int(counts[k]):,} chords within the tolerance is more "
                    f"than ncpp verifies at once ({MAX_CHORDS:,}): split it, or give a wider --tolerance",
                    Location("", self.lines[k], 1),
                )
        # each segment starts at its piece's start (t from 0 on) and ends where the next starts, but a
        # move's last, which ends at the move's end
        move = np.repeat(np.arange(len(counts)), counts)  # each segment's move
        last = np.cumsum(counts) - 1  # each move's last segment
        width = starts.shape[1]
        begins = np.empty((len(move), width + 1))
        if arcs is None:  # (a segment a move)
            begins[:, :width] = starts
        else:
            t = (np.arange(len(move)) - (last + 1 - counts)[move]) / counts[move]
            along = t[:, None] * np.repeat(ends - starts, counts, axis=0)
            begins[:, :width] = np.repeat(starts, counts, axis=0) + along
            arcs.bend(begins, move, t)
        rapid = np.zeros(len(counts), dtype=bool)
        rapid[self.rapids] = True
        begins[:, width] = rapid[move] * bound.apart
        finish = np.empty_like(begins)
        finish[:-1] = begins[1:]
        finish[last, :width] = ends
        finish[last, width] = begins[last, width]
        return Section(begins, finish, rapid[move], np.array(self.lines)[move], self.feeds, self.inverse_time,
                       action, first_line, self.cut)  # fmt: skip


class _Arcs:
    """A section's arcs, as arrays: what their samples need to lie on them."""

    def __init__(self, arcs: list, centres: list, axes: np.ndarray, starts: np.ndarray, ends: np.ndarray,
                 offsets: np.ndarray, units: np.ndarray):  # fmt: skip
        """`arcs`, `centres`: `_Moves`'; `axes` (the two of the plane), `offsets`, `units`: per move."""
        table = np.array(arcs, dtype=np.int64).reshape(-1, 2)  # (move, turn)
        self.move = rows = table[:, 0]
        i, j = axes[rows].T
        centre = (np.array(centres).reshape(-1, 3) + offsets[rows]) * units[rows]  # machine mm
        at = np.arange(len(rows))
        self.i, self.j, self.ci, self.cj = i, j, centre[at, i], centre[at, j]
        s_i, s_j = starts[rows, i] - self.ci, starts[rows, j] - self.cj
        e_i, e_j = ends[rows, i] - self.ci, ends[rows, j] - self.cj
        self.a0 = np.arctan2(s_j, s_i)
        self.r0, self.r1 = np.hypot(s_i, s_j), np.hypot(e_i, e_j)
        self.sweep = _sweeps(self.a0, np.arctan2(e_j, e_i), table[:, 1])

    def chords(self, within: float) -> np.ndarray:
        """How many chords each arc takes for none to lie further than `within` from it."""
        radius = np.maximum(np.maximum(self.r0, self.r1), within)
        angle = 2 * np.arccos(np.clip(1 - within / radius, -1.0, 1.0))  # what one chord may span
        return np.maximum(1, np.ceil(np.abs(self.sweep) / np.maximum(angle, 1e-6))).astype(np.int64)

    def bend(self, points: np.ndarray, move: np.ndarray, t: np.ndarray) -> None:
        """Put the arcs' samples (made along their chords) on the arcs, in place; the radius
        changes linearly from start to end, as rs274 interpolates an arc whose radii differ."""
        which = np.full(int(move.max()) + 1, -1)
        which[self.move] = np.arange(len(self.move))
        k = which[move]
        on = np.flatnonzero(k >= 0)
        k = k[on]
        angle = self.a0[k] + self.sweep[k] * t[on]
        radius = self.r0[k] + (self.r1[k] - self.r0[k]) * t[on]
        points[on, self.i[k]] = self.ci[k] + radius * np.cos(angle)
        points[on, self.j[k]] = self.cj[k] + radius * np.sin(angle)


def _sweeps(a0: np.ndarray, a1: np.ndarray, turn: np.ndarray) -> np.ndarray:
    """Signed angles arcs turn (rs274's ARC_FEED rotation: +1 counter-clockwise, |turn| > 1 adds turns)."""
    full = 2 * np.pi
    ccw = (a1 - a0) % full
    cw = (a0 - a1) % full
    ccw = np.where(ccw > 1e-12, ccw, full) + full * (turn - 1)
    cw = -(np.where(cw > 1e-12, cw, full) + full * (-turn - 1))
    return np.where(turn > 0, ccw, cw)


# (a block, the chunk's moves so far, the blocks run so far with it, its moves run so far) -> where
# the next chunk starts (None: no cut)
Cut = Callable[[Block, int, int, int], Position | None]


def sections(events: Iterable[Event], cut: Cut = lambda block, moves, run, into: None,
             line_of: Callable[[int], int] | None = None,
             divisible: Callable[[Event], bool] | None = None) -> Iterator[_Moves]:  # fmt: skip
    """The motion of a program's events between its actions (unsampled), in the order it runs; a chunk
    ends before a block where `cut` says, or every `CHUNK_MOVES` moves into a block whose
    first event is `divisible` (a loop's end line, which owns the moves of all its runs but the
    first).  `line_of` gives the line a block's samples are told by (its own by default)."""
    moves = _Moves()
    into = 0  # moves of the block run so far, where it is divisible (-1: it is not)
    extra: tuple[float, ...] = NO_EXTRA
    last: Block | None = None
    after: list[str] = []
    first_line = 1
    inverse_time = False
    run = 0  # blocks run so far
    for event in events:
        kind = type(event)
        block = event.block
        if block is not last:
            told = line_of(block.line) if line_of else block.line
            if after:
                for text in after:
                    yield moves.closed(Action(text, last.line), first_line)  # type: ignore[union-attr]
                    moves, first_line = _Moves(), last.line  # type: ignore[union-attr]
                after = []
            last = block
            run += 1
            into = 0 if divisible is not None and divisible(event) else -1
            # (not before text that does not run: a definition's lines written with its run where it
            # stands are tagged as where the run is, further on)
            runs_here = not (kind is Pass and event.skipped)  # type: ignore[union-attr]
            if moves.lines and runs_here and (at := cut(block, len(moves.lines), run, 0)):
                yield moves.closed(None, first_line, at)
                moves, first_line = _Moves(), block.line
            if not (kind is Pass and event.skipped) and _may_act(block.signature):  # type: ignore[union-attr]
                before, after = actions_of(block)
                inverse_time = _inverse_time(block, inverse_time)
                for text in before:
                    yield moves.closed(Action(text, block.line), first_line)
                    moves, first_line = _Moves(), block.line
        if kind is Line or kind is Arc:
            if into >= 0:
                if into and into % CHUNK_MOVES == 0 and (at := cut(block, len(moves.lines), run, into)):
                    yield moves.closed(None, first_line, at)
                    moves, first_line = _Moves(), block.line
                into += 1
            extra = _add(moves, event, extra, inverse_time, told)  # type: ignore[arg-type]
        elif kind is Pass and event.dwell is not None:  # type: ignore[union-attr]  # a cycle's, written G4 P
            for text in ("G4", f"P{event.dwell:g}"):  # type: ignore[union-attr]
                yield moves.closed(Action(text, block.line), first_line)
                moves, first_line = _Moves(), block.line
    for text in after:
        yield moves.closed(Action(text, last.line), first_line)  # type: ignore[union-attr]
        moves = _Moves()
    yield moves.closed(None, first_line)


_ACTING = re.compile(r"[MTSHDP]|G4|G9")


@lru_cache(maxsize=4096)  # (a program's blocks have few signatures)
def _may_act(signature: str | None) -> bool:
    """Whether a block may hold an action or a feed mode: its signature (the letters of a plain
    block's words, G words with their numbers) names one; None (not a plain block) may."""
    return signature is None or _ACTING.search(signature) is not None


def _add(
    moves: _Moves, event: Line | Arc, extra: tuple[float, ...], inverse_time: bool, line: int
) -> tuple[float, ...]:
    """Add a move (told by `line`); return the extra axes' positions after it.  (A move's own
    work is a few appends: the numbers are turned to machine mm a section at a time.)"""
    ctx = event.context
    n = len(moves.lines)  # the move's index
    if ctx is not moves.frame:
        moves.frame = ctx
        moves.frames.append((n, ctx))
    if event.centre_shift is None:
        moves.points += event.start
        moves.points += event.end
    else:
        n = _on_centre_path(moves, event, extra, line)
        moves.centre_last = n
    moves.lines.append(line)
    if event.extra:
        end_extra = (tuple(event.extra) + NO_EXTRA)[: len(EXTRA_AXES)]
        moves.extra[n] = (extra, end_extra)
    elif extra is not NO_EXTRA:
        moves.extra[n] = (extra, extra)
        end_extra = extra
    else:
        end_extra = extra
    if type(event) is Arc:
        rapid = False
        moves.arcs += (n, event.turn)
        moves.centres += event.center
    else:
        rapid = event.rapid
        if rapid:
            moves.rapids.append(n)
    if not rapid:
        if inverse_time:
            moves.inverse_time += 1.0 / event.feed if event.feed > 0 else math.inf
        elif event.feed != moves.feed or ctx.inch != moves.feed_inch:
            moves.feed, moves.feed_inch = event.feed, ctx.inch
            feed = event.feed * ctx.unit_mm
            if not moves.feeds or not math.isclose(moves.feeds[-1][0], feed, rel_tol=1e-9, abs_tol=1e-9):
                moves.feeds.append((feed, line))
    return end_extra


def _on_centre_path(moves: _Moves, event: Line | Arc, extra: tuple[float, ...], line: int) -> int:
    """Add a move's ends under cutter compensation where the tool centre runs (`CentrePath`): the
    corner before it first, or the move before cut back to where their offsets cross.  Returns
    the move's index."""
    n = len(moves.lines)
    on = moves.centre_path.along(event, moves.centre_last == n - 1)
    if on.cut_back is not None and moves.centre_in_plane >= 0:
        a, b, _ = PLANE_AXES[event.context.plane]
        # (the move's end, and the start and end of the moves standing after it: rs274ngc moves them all)
        for row in [6 * moves.centre_in_plane + 3] + [
            6 * k + e for k in range(moves.centre_in_plane + 1, n) for e in (0, 3)
        ]:
            moves.points[row + a], moves.points[row + b] = on.cut_back[a], on.cut_back[b]
    if on.corner is not None:
        moves.points += on.corner.start
        moves.points += on.corner.end
        moves.lines.append(line)
        moves.arcs += (n, on.corner.turn)
        moves.centres += on.corner.centre
        if extra is not NO_EXTRA:
            moves.extra[n] = (extra, extra)
        if type(event) is Line and event.rapid:
            moves.rapids.append(n)
        n += 1
    moves.points += on.start
    moves.points += on.end
    if not on.standing:
        moves.centre_in_plane = n
    return n


def _inverse_time(block: Block, now: bool) -> bool:
    """G93 / G94 / G95 as the block leaves them (the ISO family's modal group 5)."""
    for item in block.items:
        if type(item) is Word and item.letter in "Gg" and item.value in (93.0, 94.0, 95.0):
            now = item.value == 93.0
    return now


@dataclass(frozen=True)
class Bound:
    """How far a written path may lie from the programmed one (mm); `most`: the widest it is in
    the run (None: `distance`), which keeps rapids and feeds apart alike in every section."""

    distance: float
    most: float | None = None

    @property
    def chord(self) -> float:
        """How far an arc's chords may lie from it."""
        return self.distance / 8

    @property
    def within(self) -> float:
        """How far a point of either path (made of chords) may lie from the other's chords."""
        return self.distance + 2 * self.chord

    @property
    def apart(self) -> float:
        """How far apart rapids and feeds are kept, along a coordinate of their own."""
        if self.most is not None and self.most > self.distance:
            return Bound(self.most).apart
        return 4 * (self.within + self.coarse)

    @property
    def coarse(self) -> float:
        """The spacing of the points candidate segments are looked up by (`_Nearby`), at least 0.25 mm
        (at a spacing much wider than the bound, short segments lying over one another, the reversal
        steps of a helix of many turns, crowd out the segments within the bound of a point)."""
        return max(4 * self.distance, 0.25)


# mm: a written number's rounding, half the last digit of an inch program (0.00001 in) on each of
# three axes (a correction is noted before its command is rounded to the output grid)
ROUNDING = 0.00025


@dataclass(frozen=True)
class Following:
    """A compensating run's bound as it stands when a section is compared: the largest correction
    made so far (`made()`, mm) plus the tolerance and `ROUNDING`, at most `most` (the machine
    file's max_correction_mm plus the tolerance, which no correction passes)."""

    most: float
    tolerance: float
    made: Callable[[], float]

    def __call__(self) -> Bound:
        return Bound(min(self.most, self.made() + self.tolerance + ROUNDING), self.most)


# A bound, or what gives it as it stands (`Following`)
Bounds = Bound | Callable[[], Bound]


def _interpreted(
    blocks: Iterable[Block],
    file: str,
    dialect: str,
    offsets: WorkOffsets | None,
    runs: OnceRuns | None = None,
) -> Iterator[Event]:
    """A program's events as ncpp's interpreter reads its blocks, its warnings unsaid; `runs`: the
    subroutines whose one run the reading of the input found (`Interpreter.run`), read so here too,
    their blocks each its own as the writer took them (and held to WRITTEN_HELD events: a written
    run has more lines than the input's, which was held to MAX_ONCE)."""
    from ncpp.guard import without_guard
    from ncpp.pipeline import dialect_tools

    interpret, _ = dialect_tools(dialect)
    blocks = without_guard(blocks)  # (it neither moves nor acts, and reads the control's parameters)
    once = None if runs is None else OnceRuns(only=runs.names, held_most=WRITTEN_HELD)
    once_runs = {} if once is None else {"once_runs": once}  # (Sinumerik has none)
    return interpret(blocks, file=file, warnings=unsaid(), offsets=offsets or AT_MACHINE_ZERO, **once_runs)


# mm: how far a move written out by --expand may lie from the same move of the program as it runs
# (the two readings compute the same numbers; this is their rounding)
EXPANDED_SLACK = 1e-6


def same_motion(expanded: Iterable[Event], plain: Iterable[Event], file: str) -> Iterator[Event]:
    """`expanded` (a reading of the input with --expand) as it comes, each move checked against the
    next of `plain` (a reading without it): kind, rapid or feed, start and end in machine mm.  The
    verifier compares the written program with the expanded reading; this ties that reading to
    the program's own run, so a stretch written out of its place or with other numbers is refused.
    Where either reading leaves the interpreter's scope the check ends (the rest is not compared)."""
    theirs = _moves_of(plain)
    done = False
    for event in expanded:
        kind = type(event)
        if not done and (kind is Line or kind is Arc):
            other = next(theirs, None)
            if other is None:
                done = True
            elif not _alike_moves(event, other):  # type: ignore[arg-type]
                raise _Misplaced(
                    "verification: --expand wrote a move the program does not make here (its run "
                    f"makes the move of line {other.block.line}); leave --expand out",
                    Location(file, event.block.line, 1),
                )
        yield event


class _Misplaced(NcppError):
    """A move --expand wrote where the program does not make it: the first fault, wherever the
    comparison that follows it stops."""


def _moves_of(events: Iterable[Event]) -> Iterator[Line | Arc]:
    """The moves of a reading, ending quietly where it meets a fault (the other reading reports it)."""
    try:
        for event in events:
            if type(event) is Line or type(event) is Arc:
                yield event
    except NcppError:
        return


def _alike_moves(a: Line | Arc, b: Line | Arc) -> bool:
    if type(a) is not type(b) or (type(a) is Line and a.rapid != b.rapid):  # type: ignore[union-attr]
        return False
    ends = (a.context.to_machine(a.start), a.context.to_machine(a.end))
    others = (b.context.to_machine(b.start), b.context.to_machine(b.end))
    return all(math.dist(p, q) <= EXPANDED_SLACK for p, q in zip(ends, others))


def unsaid() -> Warnings:
    """Warnings that go unsaid: a second reading of a program warns of nothing the first did not."""
    return Warnings(stream=_Discard())


class _Discard:
    def write(self, text: str) -> int:
        return len(text)


def verify(original: BinaryIO, written: BinaryIO, *, file: str, dialect: str | None, offsets: WorkOffsets | None,
           bound: Bounds) -> int:  # fmt: skip
    """Compare a written program file with the original, both read afresh; raise NcppError at
    the original's line where they part.  Returns the number of sections compared."""
    from ncpp.program.dialects import parse_program

    if dialect is None:
        from ncpp.program.dialects import SNIFF_BYTES, detect

        dialect = detect(original.read(SNIFF_BYTES), file)
        original.seek(0)
    mine = sections(_interpreted(parse_program(original, file, dialect)[1], file, dialect, offsets))
    theirs = sections(_interpreted(parse_program(written, file, dialect)[1], file, dialect, offsets))
    try:
        return _Comparison(file, bound, lambda number: (_line_text(written, number), 0)).run(mine, theirs)
    except NcppError as err:
        raise _in_file(err, file) from None


def _in_file(err: NcppError, file: str) -> NcppError:
    """`err`, told in `file` when it was raised where the file was not known (`_Moves.sample`)."""
    if err.where.file == "":
        err.where = replace(err.where, file=file)
    return err


def verified(lines: Iterable[str], reached: Callable[[], tuple[int, int, int]], original: Iterable[Event], *, file: str, dialect: str,
             offsets: WorkOffsets | None, bound: Bounds, runs: OnceRuns | None = None) -> Iterator[str]:  # fmt: skip
    """The written program's `lines`, handed on as they are verified against the `original`
    events (an interpreter's reading of the input of its own): each chunk of the input's motion is
    compared with the written lines read back up to where the writer had reached the same
    input blocks (`reached()` as it hands out a line: its input line, the one before, and how
    many input blocks have run, which loops make other than the lines).  A loop's end line owns the
    moves of its runs but the first; the writer writes its text at its first event (`written_at_once`),
    so its moves are cut into chunks at the same counts on both sides: a loop of any length is
    compared a chunk at a time (its text runs the same moves read back as in the input).  Raises
    NcppError where they part, or the program's first fault: the reading of the input runs
    ahead of the passes, so a fault it meets waits until the passes have had the lines before."""
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects.iso import IsoWriter
    from ncpp.program.parser import parse_stream

    feed = _Feed(lines, reached)
    held = _Held(original)
    writer: type[IsoWriter] = dialect_tools(dialect)[1]
    divisible = writer.written_at_once if writer.control_at_once else None
    cut: list[Position | None] = [None]  # where the input's chunk under way ends (None: at an action)

    def input_cut(block: Block, moves: int, run: int, into: int) -> Position | None:
        return (run, into) if moves >= CHUNK_MOVES else None

    def written_cut(block: Block, moves: int, run: int, into: int) -> Position | None:
        return cut[0] if cut[0] and (feed.run(block.line), into) >= cut[0] else None

    mine = sections(held, input_cut, divisible=divisible)
    theirs = sections(_interpreted(parse_stream(feed, file, dialect), file, dialect, offsets, runs), written_cut,
                      lambda number: feed.tag(number, before=True), divisible)  # fmt: skip
    comparison = _Comparison(file, bound, feed.text, tagged=True)
    try:
        for a in mine:
            cut[0] = a.cut
            comparison.step(a, theirs)
            yield from feed.handed()
        comparison.end(theirs)
    except _Unread as err:  # the written program cut short where a fault of the input stopped it
        raise held.error or err from None
    except NcppError as err:
        raise held.first(_in_file(err, file)) from None
    if held.error is not None:
        raise held.error
    yield from feed.handed()
    yield from feed.rest()


class _Held:
    """The input's events up to a fault the interpreter meets, which it keeps (`error`)."""

    def __init__(self, events: Iterable[Event]):
        self.events = events
        self.error: NcppError | None = None

    def __iter__(self) -> Iterator[Event]:
        try:
            yield from self.events
        except NcppError as err:
            self.error = err

    def first(self, err: NcppError) -> NcppError:
        """`err`, or the interpreter's fault where that comes first in the program (or is a move
        --expand misplaced)."""
        if self.error is not None and (
            isinstance(self.error, _Misplaced)
            or err.where.line is None
            or (self.error.where.line or 0) <= err.where.line
        ):
            return self.error
        return err


class _Unread(NcppError):
    """The written program cannot be read back."""


class _Upstream(Exception):
    """A fault of the passes or the writer, passed through the reading of the written lines."""

    def __init__(self, error: NcppError):
        super().__init__(str(error))
        self.error = error


class _Feed:
    """Written lines as the parser reads them (bytes), each remembered with the input line the
    writer had reached when it handed the line out (its tag), until the lines are handed on."""

    # Lines taken from the writer at a time, each tagged as it comes: the writer and the parser
    # each run over many lines in turn, faster than taking turns a line at a time
    AHEAD = 256
    # Tags looked up behind the line asked (`_tag_of`; at most twice as many held but for those of the
    # lines after it): more than the input blocks a subroutine's run held to MAX_ONCE events spans,
    # whose lines are written further on
    KEPT_TAGS = 2 * MAX_ONCE

    def __init__(self, lines: Iterable[str], reached: Callable[[], tuple[int, int, int]]):
        self.lines = iter(lines)
        self.reached = reached
        self.pending: list[str] = []
        # (first written line of the texts handed out at one `reached()`, their tag, the line
        # before, the input blocks run so far), in the order of the lines: `reached()` is the same
        # object until it changes; the first lines' (`firsts`) for looking a line's up
        self.tags: list[tuple[int, int, int, int]] = []
        self.firsts: list[int] = []
        self.count = 0  # written lines taken so far
        self.recent: deque[tuple[int, str]] = deque(maxlen=self.AHEAD + 64)  # for messages
        self.fault: NcppError | None = None  # the writer's, where it stopped
        self.rest_of_line = ""  # written text after the last LF handed to the parser
        self.open_line = False  # the texts taken so far end inside a line (the next goes on it)
        self.found: tuple[int, tuple[int, int, int, int]] | None = None  # the last line looked up, its tag

    def __iter__(self) -> Iterator[bytes]:
        last = None
        recent, tags, firsts = self.recent, self.tags, self.firsts
        while True:
            pending = self.pending  # (`handed` takes the list the lines before went to)
            taken = len(pending)
            count, open_line = self.count, self.open_line
            try:
                for text in islice(self.lines, self.AHEAD):
                    reached = self.reached()
                    first = count if open_line else count + 1  # (the line it starts on)
                    if reached is not last:
                        last = reached
                        tags.append((first, *reached))
                        firsts.append(first)
                        self.found = None
                    pending.append(text)
                    if text:
                        ended = text.endswith("\n")
                        count = first + text.count("\n") - ended  # (the last line it is on)
                        open_line = not ended
                    recent.append((count, text))
            except NcppError as err:  # (the lines before it are read first)
                self.fault = err
            self.count, self.open_line = count, open_line
            batch = pending[taken:]
            # (a line at a time, as the file holds them: the parser numbers them as `count`; only
            # LF ends a line in a program file, as binary reading splits them)
            text = self.rest_of_line + "".join(batch)
            end = text.rfind("\n") + 1
            self.rest_of_line = text[end:]
            yield from io.BytesIO(text[:end].encode("latin-1"))
            if self.fault is not None or len(batch) < self.AHEAD:
                if self.rest_of_line:  # (the file's last line, unended)
                    yield self.rest_of_line.encode("latin-1")
                    self.rest_of_line = ""
            if self.fault is not None:
                raise _Upstream(self.fault) from None
            if len(batch) < self.AHEAD:
                return

    def tag(self, number: int, before: bool = False) -> int:
        """The tag of written line `number`: the input line the writer had reached, or (`before`)
        the one before it, where the line most likely is from."""
        found = self._tag_of(number)
        return found[2 if before else 1] if found else 0

    def run(self, number: int) -> int:
        """How many input blocks the writer had taken when it handed out written line `number`."""
        found = self._tag_of(number)
        return found[3] if found else 0

    def _tag_of(self, number: int) -> tuple[int, int, int, int] | None:
        """The tag of written line `number`, asked in the order the lines run (a subroutine's, written
        further on, before the lines after its call); the tags more than KEPT_TAGS behind the one
        asked go, and a line of theirs gets the first kept (memory stays flat but for the lines the
        reading holds ahead: a call that finds its subprogram after M30 has read the lines to it)."""
        if self.found is not None and self.found[0] == number:  # (a block's line is asked twice)
            return self.found[1]
        tags, firsts = self.tags, self.firsts
        at = bisect_right(firsts, number) - 1
        if len(tags) > 2 * self.KEPT_TAGS and at >= 2 * self.KEPT_TAGS:
            del tags[: self.KEPT_TAGS], firsts[: self.KEPT_TAGS]
            at -= self.KEPT_TAGS
        if not tags:
            return None
        found = tags[max(at, 0)]
        self.found = (number, found)
        return found

    def handed(self) -> list[str]:
        done, self.pending = self.pending, []
        return done

    def rest(self) -> Iterator[str]:
        """Lines after the parser's last (after the program's end: it reads no further)."""
        yield from self.lines
        if self.fault is not None:
            raise self.fault

    def text(self, number: int | None) -> tuple[str, int]:
        """Written line `number` (one of the last read) and its tag."""
        return next(
            ((t.strip()[:120], self.tag(n, before=True)) for n, t in self.recent if n == number), ("", 0)
        )


class _Comparison:
    """Sections of the original and the written program compared pairwise, in order."""

    def __init__(
        self,
        file: str,
        bound: Bounds,
        written_text: Callable[[int | None], tuple[str, int]],
        tagged: bool = False,
    ):
        """`bound`: read as each section is compared (a `Following` bound as it stands then);
        `written_text(n)`: the written program's line n, and the input line it was written from
        (0: unknown); `tagged`: the written sections' samples are told by those input lines."""
        self.bound = bound if callable(bound) else lambda: bound
        self.file, self.written_text, self.tagged = file, written_text, tagged
        self.now = self.bound()  # the bound the sections under comparison are sampled and compared with
        self.before: Section | None = None  # the last original chunk, when it ended at a cut
        self.owed: tuple[Section, Section] | None = (
            None  # an original chunk not yet checked against the written
        )
        self.feeds: tuple[deque, deque] = (deque(), deque())  # feed rates not yet matched (original, written)
        self.times = [0.0, 0.0]  # inverse-time minutes since the last action (original, written)
        self.count = 0

    def run(self, mine: Iterator[_Moves], theirs: Iterator[_Moves]) -> int:
        for a in mine:
            self.step(a, theirs)
        self.end(theirs)
        return self.count

    def step(self, moves: _Moves, theirs: Iterator[_Moves]) -> None:
        written = self._next(theirs, moves.first_line)
        if written is None:
            raise NcppError(
                "verification: the written program ends before the original",
                Location(self.file, moves.first_line, 1),
            )
        # (the bound read once the written section is: the passes have made its corrections; a bound that
        # grows only is at least that of the neighbouring chunks' samples, sampled before)
        self.now = bound = self.bound()
        a, b = moves.sample(bound), written.sample(bound)
        self.count += 1
        self._actions(a, b)
        across = _tail(self.before) if self.before is not None else None
        self._follows(b, _joined(a, across), "the written path leaves the original's", written=True)
        if self.owed is not None:
            pa, pb = self.owed
            self._follows(
                pa, _joined(pb, _head(b)), "the written path does not follow the original's", written=False
            )
            self.owed = None
        if a.cut:
            self.owed = (a, b)
        else:
            self._follows(a, b, "the written path does not follow the original's", written=False)
        self.before = a if a.cut else None
        self._feeds(a, b)

    def end(self, theirs: Iterator[_Moves]) -> None:
        self.now = self.bound()
        if self.owed is not None:
            pa, pb = self.owed
            self._follows(pa, pb, "the written path does not follow the original's", written=False)
        extra = self._next(theirs, 0)
        if extra is not None and (extra.lines or extra.action is not None):
            raise NcppError("verification: the written program goes on after the original ends",
                            Location(self.file, extra.first_line, 1))  # fmt: skip

    def _next(self, theirs: Iterator[_Moves], line: int) -> _Moves | None:
        try:
            return next(theirs, None)
        except _Upstream as up:
            raise up.error from None
        except NcppError as err:
            number = err.where.line
            text, reached = self.written_text(number)
            raise _Unread(
                f"verification: ncpp cannot read back the program it wrote: {err.message}, "
                f"at its line {number} {text!r}",
                Location(self.file, reached or line or 1, 1),
            ) from None

    def _actions(self, a: Section, b: Section) -> None:
        if (a.action is None) != (b.action is None) or (
            a.action is not None and a.action.text != b.action.text  # type: ignore[union-attr]
        ):
            where = a.action.line if a.action is not None else a.first_line
            raise NcppError(f"verification: the written program does {_what(b)} where the original does {_what(a)}",
                            Location(self.file, where, 1))  # fmt: skip

    def _follows(self, path: Section, along: Section, message: str, written: bool) -> None:
        """Raise where a point of `path` lies further than the bound from `along` (from its
        segments of the same kind, rapid or feed); a written path's fault is told at the
        original's nearest line."""
        if not len(path.starts):
            return
        file = self.file
        if not len(along.starts):
            line = along.first_line if written else int(path.lines[0])
            raise NcppError(f"verification: {message}: it has no move here", Location(file, line, 1))
        bound = self.now
        within = bound.within
        endless = np.flatnonzero(~np.isfinite(_lengths(path.starts, path.ends)))
        if len(endless):
            raise NcppError(
                "verification: a move too long to verify", Location(file, int(path.lines[endless[0]]), 1)
            )
        (starts, ends), (a, b) = _alike((path.starts, path.ends), (along.starts, along.ends))
        # (a path that runs again, a loop's, is looked up by each segment once: a lookup tree of
        # many equal points looks at all of them)
        theirs = _first_of_each(a, b)
        a, b = a[theirs], b[theirs]
        try:
            far = _Nearby(a, b, bound).first_outside(starts, ends, within)
        except NcppError as err:
            raise NcppError(err.message, Location(file, int(path.lines[0]), 1)) from None
        if far is None:
            return
        k, point = far
        gap, near = _Nearby(a[:, :-1], b[:, :-1], bound).nearest(point[:-1])  # (kinds aside)
        near = int(theirs[near])
        line = int(along.lines[near]) if written and not self.tagged else int(path.lines[k])
        if gap > within:
            message = f"{message} by more than {within:.4f} mm"
        elif written:
            message = "the written program makes a " + (
                "rapid move where the original cuts"
                if path.rapid[k]
                else "feed move where the original rapids"
            )
        else:
            message = "the written program " + (
                "feeds where the original rapids" if path.rapid[k] else "rapids where the original cuts"
            )
        raise NcppError(f"verification: {message}", Location(file, line, 1))

    def _feeds(self, a: Section, b: Section) -> None:
        """Feed rates matched in order across chunks; at an action (or the end) none may be left,
        and the inverse-time moves since the last action must take the original's time."""
        mine, theirs = self.feeds
        rate: float | None
        for queue, section in ((mine, a), (theirs, b)):
            for rate, line in section.feeds:
                if not (queue and _same_rate(queue[-1][0], rate)):
                    queue.append((rate, line))
        while mine and theirs:
            (rate, line), (other, _) = mine[0], theirs[0]
            if not _same_rate(rate, other):
                self._feed_fault(rate, other, line)
            if len(mine) == 1 or len(theirs) == 1:  # the last run may go on in the next chunk
                break
            mine.popleft()
            theirs.popleft()
        self.times[0] += a.inverse_time
        self.times[1] += b.inverse_time
        if a.cut:
            return
        if len(mine) != len(theirs):
            rate, line = mine[-1] if len(mine) > len(theirs) else (None, a.first_line)
            self._feed_fault(rate, theirs[-1][0] if len(theirs) > len(mine) else None, line)
        mine.clear()
        theirs.clear()
        t0, t1 = self.times
        if not math.isclose(t0, t1, rel_tol=1e-4, abs_tol=1e-7):
            raise NcppError(f"verification: the written program's inverse-time moves take {t1:.6g} min where "
                            f"the original's take {t0:.6g} min", Location(self.file, a.first_line, 1))  # fmt: skip
        self.times = [0.0, 0.0]

    def _feed_fault(self, rate: float | None, other: float | None, line: int) -> None:
        raise NcppError(f"verification: the written program feeds at {_rate(other)} where the original feeds at {_rate(rate)}",
                        Location(self.file, line, 1))  # fmt: skip


def _same_rate(a: float, b: float) -> bool:
    return math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9)


def _rate(value: float | None) -> str:
    return "nothing" if value is None else f"{value:g} mm/min"


def _what(section: Section) -> str:
    if section.action is not None:
        return f"'{section.action.text}'"
    return "no action" if section.cut else "nothing more"


def _tail(section: Section) -> Section:
    """The last `ACROSS` of a chunk's segments."""
    n = len(section.starts)
    return _part(section, slice(n - int(math.ceil(n * ACROSS)), n))


def _head(section: Section) -> Section:
    """The first `ACROSS` of a chunk's segments."""
    return _part(section, slice(0, int(math.ceil(len(section.starts) * ACROSS))))


def _part(section: Section, rows: slice) -> Section:
    return Section(section.starts[rows], section.ends[rows], section.rapid[rows], section.lines[rows], [], 0.0, None,
                   section.first_line)  # fmt: skip


def _joined(section: Section, other: Section | None) -> Section:
    """`section` with `other`'s segments too (its lines, first line and action its own)."""
    if other is None or not len(other.starts):
        return section
    (a, b), (c, d) = _alike((section.starts, section.ends), (other.starts, other.ends))
    return Section(np.vstack((a, c)), np.vstack((b, d)), np.concatenate((section.rapid, other.rapid)),
                   np.concatenate((section.lines, other.lines)), section.feeds, section.inverse_time, section.action,
                   section.first_line, section.cut)  # fmt: skip


Segments = tuple[np.ndarray, np.ndarray]


def _first_of_each(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """The indices of the segments not equal to one before them, in order.  (Equal segments are
    found next to one another when sorted by a mix of their coordinates, which equal ones share:
    weights of no simple ratio, so that other segments of a program's grid seldom share it.)"""
    columns = (*starts.T, *ends.T)
    key = np.zeros(len(starts))
    for column, weight in zip(columns, np.random.default_rng(0).uniform(1.0, 2.0, len(columns))):
        key += column * weight  # (a column at a time: a matrix product may round equal rows apart)
    order = np.argsort(key, kind="stable")
    ordered = key[order]
    same = np.flatnonzero(ordered[1:] == ordered[:-1]) + 1  # (only these may be equal segments)
    one, other = order[same], order[same - 1]
    equal = np.all(starts[one] == starts[other], axis=1) & np.all(ends[one] == ends[other], axis=1)
    first = np.ones(len(key), dtype=bool)
    first[one[equal]] = False
    return np.flatnonzero(first)


def _alike(one: Segments, other: Segments) -> tuple[Segments, Segments]:
    """Two sections' segments with the same columns: the extra axes, zero where a side has none,
    before the kind's column."""
    width = max(one[0].shape[1], other[0].shape[1])
    return (_widened(one[0], width), _widened(one[1], width)), (
        _widened(other[0], width),
        _widened(other[1], width),
    )


def _widened(points: np.ndarray, width: int) -> np.ndarray:
    if points.shape[1] == width:
        return points
    out = np.zeros((len(points), width))
    out[:, : points.shape[1] - 1] = points[:, :-1]
    out[:, -1] = points[:, -1]
    return out


def _lengths(starts: np.ndarray, ends: np.ndarray) -> np.ndarray:
    """The segments' lengths; inf for one too long to hold (a program's numbers may be huge)."""
    d = ends - starts
    with np.errstate(over="ignore", invalid="ignore"):
        return np.sqrt(np.einsum("nw,nw->n", d, d))


class _Nearby:
    """The segments of a path, looked up by points: the middles of the pieces at most `Bound.coarse`
    long each is cut into, so that every segment passing within r of a point has a lookup point
    within r + coarse / 2."""

    FEW, MANY = 6, 96  # nearest lookup points asked for, then for the points that found none near
    BATCH = 1 << 15  # points looked at at once
    POINTS = 1 << 20  # lookup points along the path at most: a longer path's are spaced wider

    def __init__(self, starts: np.ndarray, ends: np.ndarray, bound: Bound):
        lengths = _lengths(starts, ends)
        if not np.isfinite(lengths).all():
            raise NcppError("verification: a move too long to verify", Location("", 1, 1))
        # (wider spacing widens the reach each lookup covers: the same segments are found)
        spacing = max(bound.coarse, float(lengths.sum()) / self.POINTS)
        self.starts, self.ends, self.reach = starts, ends, spacing / 2
        counts = np.maximum(1, np.ceil(lengths / spacing)).astype(np.int64)
        self.segment = np.repeat(np.arange(len(counts)), counts)
        first = np.concatenate(([0], np.cumsum(counts)[:-1]))
        t = (np.arange(len(self.segment)) - first[self.segment] + 0.5) / counts[self.segment]
        points = np.repeat(starts, counts, axis=0) + t[:, None] * np.repeat(ends - starts, counts, axis=0)
        self.tree = cKDTree(points, balanced_tree=False, compact_nodes=False)  # (built faster, as fast)
        self.joined = np.zeros(len(starts), dtype=bool)  # each segment's end the next one's start
        self.joined[:-1] = np.all(ends[:-1] == starts[1:], axis=1)
        self.looked_at = 0

    def distances(self, points: np.ndarray, within: float, k: int) -> tuple[np.ndarray, np.ndarray]:
        """(n, k) segments near each point (-1: none) and the points' distances to them."""
        segments, distance, _ = self.closest(points, within, k)
        return segments, distance

    def closest(self, points: np.ndarray, within: float, k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """`distances`, and (n, k, width) the segments' points closest to each point."""
        k = min(k, len(self.segment))
        _, found = self.tree.query(points, k=k, distance_upper_bound=within + self.reach)
        found = found.reshape(len(points), k)
        missing = found >= len(self.segment)
        segments = np.where(missing, -1, self.segment[np.minimum(found, len(self.segment) - 1)])
        distance, closest = _to_segments(points, *self._segments(segments))
        distance[missing] = np.inf
        return segments, distance, closest

    def nearest(self, point: np.ndarray) -> tuple[float, int]:
        segments, distance = self.distances(point[None, :], np.inf, self.MANY)
        k = int(np.argmin(distance[0]))
        return float(distance[0, k]), int(segments[0, k])

    def _across_a_vertex(self, rest: np.ndarray, segments: np.ndarray, distance: np.ndarray, closest: np.ndarray,
                         starts: np.ndarray, ends: np.ndarray, n: int, within: float) -> np.ndarray:  # fmt: skip
        """Which of the segments `rest` (starts-ends) lie within `within` along their length for
        having their start near a segment q here and their end near the one after it, q + 1 from
        q's end (the chords of an arc, the sides of a corner).  A point between the two ends lies
        as far from the line between their closest points as the ends do at most, and that line
        as far from the two segments as it passes from their common vertex."""
        q = segments[rest]  # (m, k) segments near the starts
        after = np.minimum(q + 1, len(self.starts) - 1)
        joined = (q >= 0) & (q + 1 < len(self.starts)) & np.all(self.ends[q] == self.starts[after], axis=2)
        near_end, at_end = _to_segments(ends[rest], self.starts[after], self.ends[after])
        off = np.maximum(distance[rest], near_end)
        width = self.ends.shape[1]
        vertex = self.ends[q].reshape(-1, width)
        cut, _ = _to_lines(vertex, closest[rest].reshape(-1, width), at_end.reshape(-1, width))
        cut = cut.reshape(q.shape)
        return (joined & (off + cut <= within)).any(axis=1)

    def first_outside(
        self, starts: np.ndarray, ends: np.ndarray, within: float
    ) -> tuple[int, np.ndarray] | None:
        """The first segment of starts-ends with a point further than `within` from every segment
        here, and that point; None when all lie within.  Most segments lie along the segment
        whose lookup point is nearest their start, or along it and the next: those are set aside
        first, at a fraction of the cost of the search that looks at the others."""
        along = [
            self._along_the_nearest(starts[k : k + self.BATCH], ends[k : k + self.BATCH], within)
            for k in range(0, len(starts), self.BATCH)  # (memory: each segment's three candidates at once)
        ]
        rest = np.flatnonzero(~np.concatenate(along))
        if not len(rest):
            return None
        far = self._first_outside(starts[rest], ends[rest], within)
        return None if far is None else (int(rest[far[0]]), far[1])

    FOLLOWING = 3  # segments after q a segment's end is looked for near (`_along_the_nearest`)

    def _along_the_nearest(self, starts: np.ndarray, ends: np.ndarray, within: float) -> np.ndarray:
        """Which segments lie within `within` of the path here, proven from their ends: the start
        near segment q (the one whose lookup point is nearest the start), the end near q+j (0 <= j
        <= `FOLLOWING`), the segments from q to q+j joined end to start; or both ends near q-1, or
        both near q+1.  A point of such a segment lies no further than its ends do from the line
        between their closest points on the path, and a point of that line no further from the path
        than the vertices between lie from the line (the path runs from one end of the line to the
        other).  Each way is tried only on the segments the ways before left unproven, most
        frequent first."""
        _, found = self.tree.query(starts, k=1, distance_upper_bound=within + self.reach)
        proven = np.zeros(len(starts), dtype=bool)
        rest = np.flatnonzero(found < len(self.segment))
        q = self.segment[found[rest]]
        last = len(self.starts) - 1
        near, at_start = _to_lines(starts.take(rest, axis=0), *self._segments(q))
        chained = np.ones(len(rest), dtype=bool)  # the segments from q to q+j joined end to start
        for j in range(self.FOLLOWING + 1):
            after = np.minimum(q + j, last)
            if j:
                chained &= (q + j <= last) & self.joined[after - 1]
            far, at_end = _to_lines(ends.take(rest, axis=0), *self._segments(after))
            cut = np.zeros(len(rest))
            for between in range(j):
                vertex = self.ends.take(np.minimum(q + between, last), axis=0)
                cut = np.maximum(cut, _to_lines(vertex, at_start, at_end)[0])
            ok = chained & (np.maximum(near, far) + cut <= within)
            proven[rest[ok]] = True
            left = np.flatnonzero(~ok)
            rest, q, near, chained = rest[left], q[left], near[left], chained[left]
            at_start = at_start.take(left, axis=0)
        for side in (-1, 1):
            which = np.clip(q + side, 0, last)
            near, _ = _to_lines(starts.take(rest, axis=0), *self._segments(which))
            far, _ = _to_lines(ends.take(rest, axis=0), *self._segments(which))
            ok = (q + side >= 0) & (q + side <= last) & (np.maximum(near, far) <= within)
            proven[rest[ok]] = True
            rest, q = rest[~ok], q[~ok]
        return proven

    def _segments(self, which: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """The starts and ends of segments `which` (-1: the last).  (`take`: numpy's indexing by an
        array of rows is many times slower.)"""
        return self.starts.take(which, axis=0), self.ends.take(which, axis=0)

    def _first_outside(
        self, starts: np.ndarray, ends: np.ndarray, within: float
    ) -> tuple[int, np.ndarray] | None:
        """`first_outside` by the nearest few lookup points of each end.  A segment both of whose ends lie within
        `within` of one segment here lies within it along its length (the set within a distance
        of a segment is convex); the others are looked at at points a quarter of `within` apart,
        each allowed an eighth more (a point between two lies within an eighth of one)."""
        n = len(starts)
        # each segment's start, and its end where the next does not start there (most do)
        apart = np.flatnonzero(np.any(ends[:-1] != starts[1:], axis=1))
        ending = np.concatenate((apart, [n - 1]))
        where_end = np.arange(1, n + 1)
        where_end[ending] = n + np.arange(len(ending))
        segments, distance, closest = self.closest(np.vstack((starts, ends[ending])), within, self.FEW)
        order = np.concatenate((np.arange(n), where_end))
        segments, distance, closest = segments[order], distance[order], closest[order]
        near = distance <= within
        # a segment near one end, near the other too (looked at from both ends: segments lying
        # over one another, as a peck's, crowd the nearest points of either)
        ends_to_start, _ = _to_segments(ends, *self._segments(segments[:n]))
        starts_to_end, _ = _to_segments(starts, *self._segments(segments[n:]))
        common = (near[:n] & (segments[:n] >= 0) & (ends_to_start <= within)).any(axis=1)
        common |= (near[n:] & (segments[n:] >= 0) & (starts_to_end <= within)).any(axis=1)
        rest = np.flatnonzero(~common)
        if len(rest):
            rest = rest[~self._across_a_vertex(rest, segments, distance, closest, starts, ends, n, within)]
        if not len(rest):
            return None
        step = within / 4
        a, b = starts[rest], ends[rest]
        lengths = np.sqrt(((b - a) ** 2).sum(axis=1))
        samples = np.maximum(1, np.ceil(lengths / step))
        if samples.sum() > self.SAMPLED:
            raise NcppError(
                f"verification: a move of {lengths.max():,.0f} mm, too long to verify at points {step:g} mm "
                "apart (--no-verify writes the program unverified)"
            )
        counts = samples.astype(np.int64)
        held = np.cumsum(counts + 1)  # the points of the segments up to each, its ends included
        first = held - (counts + 1)
        allowed = within + step / 2
        for batch in range(0, int(held[-1]), self.BATCH):  # (memory: a batch of points at once)
            index = np.arange(batch, min(batch + self.BATCH, int(held[-1])))
            which = np.searchsorted(held, index, side="right")
            t = (index - first[which]) / counts[which]
            some = a[which] + t[:, None] * (b - a)[which]
            _, distance = self.distances(some, allowed, self.FEW)
            low = distance.min(axis=1) > allowed
            if low.any():
                _, again = self.distances(some[low], allowed, self.MANY)
                low[np.flatnonzero(low)] = again.min(axis=1) > allowed
            for k in np.flatnonzero(low).tolist():  # the nearest found were not all: every one within reach
                if self._beyond(some[k], allowed):
                    return int(rest[which[k]]), some[k]
        return None

    LOOKED_AT = 2_000_000  # segments a run may look at one by one (`_beyond`)
    SAMPLED = 50_000_000  # points of moves set aside a run may look at (a batch at a time: time, not memory)

    def _beyond(self, point: np.ndarray, allowed: float) -> bool:
        """Whether no segment here passes within `allowed` of the point, looked at one by one
        (where the path lies over itself more often than the nearest points show)."""
        found = self.tree.query_ball_point(point, allowed + self.reach)
        self.looked_at += len(found)
        if self.looked_at > self.LOOKED_AT:
            raise NcppError(
                "verification: the path lies over itself too often here to be verified "
                "(--no-verify writes the program unverified)"
            )
        if not found:
            return True
        segments = np.unique(self.segment[found])
        distance, _ = _to_segments(point[None, :], self.starts[segments][None], self.ends[segments][None])
        return bool(distance.min() > allowed)


def _to_segments(points: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n, k) distances of n points to their k segments (starts, ends: (n, k, width)), and
    (n, k, width) the segments' points closest to them."""
    # (einsum: numpy's sum over an axis of a few coordinates costs many times the arithmetic)
    d = ends - starts
    w = points[:, None, :] - starts
    length2 = np.einsum("nkw,nkw->nk", d, d)
    t = np.clip(np.einsum("nkw,nkw->nk", w, d) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    closest = starts + t[:, :, None] * d
    off = points[:, None, :] - closest
    return np.sqrt(np.einsum("nkw,nkw->nk", off, off)), closest


def _to_lines(points: np.ndarray, starts: np.ndarray, ends: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(n,) distances of n points to n segments, and (n, width) the segments' points closest to them."""
    d = ends - starts
    length2 = np.einsum("nw,nw->n", d, d)
    t = np.clip(np.einsum("nw,nw->n", points - starts, d) / np.where(length2 > 0, length2, 1.0), 0.0, 1.0)
    closest = starts + t[:, None] * d
    off = points - closest
    return np.sqrt(np.einsum("nw,nw->n", off, off)), closest


def _line_text(stream: BinaryIO, number: int | None) -> str:
    """Line `number` of a program file, stripped, for a message (at most 120 characters)."""
    if number is None:
        return ""
    stream.seek(0)
    for n, raw in enumerate(stream, 1):
        if n == number:
            return raw.decode("latin-1").strip()[:120]
    return ""
