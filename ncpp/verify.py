"""The verifier: a written program must do what the program it was made from does.

Compensation moves every point of a path by at most the machine file's
`max_correction_mm`.  Before a rewritten program leaves ncpp, the verifier
reads the written text back with a fresh parser and interpreter (nothing of
the passes' state) and compares it with the input program's motion:

* the same actions in the same order: tool changes and length offsets,
  spindle, coolant, dwells, stops, other M codes, program end;
* between two actions, every point of the written path within the bound of
  the input's path, and every point of the input's path within it of the
  written path (rotary and other extra axes count their unit as a mm, so a
  rotation carried by the wrong piece leaves the path);
* rapids where the input rapids and feeds where it feeds, at the same feed
  rate; in inverse time (G93) the pieces of a move take its time together.

Paths are compared in machine coordinates (mm, tool length and work offsets
applied), sampled every quarter of the bound: a written program passes when
each sample of either path lies within the bound and half a step of a sample
of the other's (so no correction within the bound is refused, and every point
passed is within 1.25 times the bound).  A violation is an `NcppError` at the
input line where it happens.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from itertools import zip_longest
from typing import BinaryIO, Iterable, Iterator

import numpy as np
from scipy.spatial import cKDTree

from ncpp.errors import Location, NcppError, Warnings
from ncpp.motion.offsets import AT_MACHINE_ZERO, WorkOffsets
from ncpp.motion.segments import EXTRA_AXES, PLANE_AXES, Arc, Event, Line, Pass
from ncpp.program.blocks import Block, Comment, ExprWord, Statement, Word

# G codes whose block is an action: dwell, tool length offsets
ACTION_G = {4.0, 43.0, 43.1, 43.2, 49.0}
# Word letters that are actions wherever they stand: M functions, tools, spindle speed,
# length and radius offset numbers
ACTION_LETTERS = {"M", "T", "S", "H", "D"}
# M functions that act after the block's motion (RS274/NGC 3 "order of execution"; the
# Heidenhain and Sinumerik manuals place program stops and ends at the block's end too)
AFTER_MOTION = {0.0, 1.0, 2.0, 30.0, 60.0}
# Statements that are actions: Klartext's TOOL CALL, CYCL CALL and END PGM
ACTION_STATEMENTS = {"tool_call", "cycle_call", "program_end"}


@dataclass(frozen=True)
class Action:
    """What a block does besides moving, as text two programs can be compared by."""

    text: str
    line: int


@dataclass
class Section:
    """The motion between two actions, sampled; `action` is the one that ends it."""

    points: np.ndarray  # (n, 3) machine mm, or (n, 9) with A B C U V W (each in its own unit)
    rapid: np.ndarray  # (n,) bool
    lines: np.ndarray  # (n,) source line of each sample
    feeds: list[tuple[float, int]]  # G94/G95 feed rates in order, each once per run, with its first line
    inverse_time: float  # minutes the G93 moves take
    action: Action | None
    first_line: int


NO_EXTRA = (0.0,) * len(EXTRA_AXES)


@dataclass
class _Moves:
    """Moves collected for one section, sampled when it closes."""

    step: float
    ends: list = field(default_factory=list)  # per move: (x0, y0, z0, x1, y1, z1) machine mm
    extra: list = field(default_factory=list)  # per move: its extra axes' start and end (NO_EXTRA twice: none)
    rapid: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    arcs: list = field(default_factory=list)  # (move, plane, centre's first, centre's second coordinate, turn)
    feeds: list = field(default_factory=list)
    inverse_time: float = 0.0

    def sample(self, action: Action | None, first_line: int) -> Section:
        """The moves sampled every `step` (each from its start to its end, both included)."""
        if not self.ends:
            empty = np.zeros((0, 3))
            return Section(empty, np.zeros(0, bool), np.zeros(0, int), self.feeds, self.inverse_time, action, first_line)
        ends = np.array(self.ends)
        starts, ends = ends[:, :3], ends[:, 3:]
        if any(e is not NO_EXTRA for pair in self.extra for e in pair):
            extra = np.array([s + e for s, e in self.extra])
            starts = np.hstack((starts, extra[:, : len(EXTRA_AXES)]))
            ends = np.hstack((ends, extra[:, len(EXTRA_AXES) :]))
        lengths = np.sqrt(((ends - starts) ** 2).sum(axis=1))
        arcs = _Arcs(self.arcs, starts, ends) if self.arcs else None
        if arcs is not None:
            lengths[arcs.move] += arcs.length
        counts = np.maximum(1, np.ceil(lengths / self.step).astype(np.int64))
        move = np.repeat(np.arange(len(counts)), counts + 1)
        first = np.concatenate(([0], np.cumsum(counts + 1)[:-1]))
        t = (np.arange(len(move)) - first[move]) / counts[move]
        points = starts[move] + t[:, None] * (ends - starts)[move]
        if arcs is not None:
            arcs.bend(points, move, t)
        return Section(points, np.array(self.rapid)[move], np.array(self.lines)[move], self.feeds, self.inverse_time,
                       action, first_line)  # fmt: skip


class _Arcs:
    """A section's arcs, as arrays: what their samples need to lie on them."""

    def __init__(self, arcs: list, starts: np.ndarray, ends: np.ndarray):
        table = np.array([(m, *PLANE_AXES[plane][:2], ci, cj, turn) for m, plane, ci, cj, turn in arcs])
        self.move = table[:, 0].astype(np.int64)
        i, j = table[:, 1].astype(np.int64), table[:, 2].astype(np.int64)
        self.i, self.j, self.ci, self.cj = i, j, table[:, 3], table[:, 4]
        rows = self.move
        s_i, s_j = starts[rows, i] - self.ci, starts[rows, j] - self.cj
        e_i, e_j = ends[rows, i] - self.ci, ends[rows, j] - self.cj
        self.a0 = np.arctan2(s_j, s_i)
        self.r0, self.r1 = np.hypot(s_i, s_j), np.hypot(e_i, e_j)
        self.sweep = _sweeps(self.a0, np.arctan2(e_j, e_i), table[:, 5])
        self.length = np.abs(self.sweep) * np.maximum(self.r0, self.r1)

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


def actions_of(block: Block) -> tuple[list[str], list[str]]:
    """The actions of a block: (before its motion, after it), each as normalised text."""
    before: list[str] = []
    after: list[str] = []
    dwell = False
    for item in block.items:
        kind = type(item)
        if kind is Word or kind is ExprWord:
            letter = item.letter.upper()  # type: ignore[union-attr]
            value = item.value if kind is Word else None  # type: ignore[union-attr]
            if letter == "G" and value in ACTION_G:
                dwell |= value == 4.0
                before.append(f"G{value:g}")
            elif letter in ACTION_LETTERS:
                text = f"{letter}{value:g}" if value is not None else f"{letter}{block.source(item).upper()}"
                (after if letter == "M" and value in AFTER_MOTION else before).append(text)
        elif kind is Statement and item.kind in ACTION_STATEMENTS:  # type: ignore[union-attr]
            before.append("".join(block.source(item).upper().split()))
    if dwell:  # the dwell's time: P (ISO), F or S (Sinumerik), X (Fanuc)
        before.extend(f"{w.letter.upper()}{w.value:g}" for w in block.words() if w.letter.upper() in "PFSX")
    return before, after


def sections(events: Iterable[Event], step: float) -> Iterator[Section]:
    """The motion of a program's events between its actions, in the order it runs."""
    moves = _Moves(step)
    extra: tuple[float, ...] = NO_EXTRA
    last: Block | None = None
    after: list[str] = []
    first_line = 1
    inverse_time = False
    for event in events:
        kind = type(event)
        block = event.block
        if block is not last:
            for text in after:
                yield moves.sample(Action(text, last.line), first_line)  # type: ignore[union-attr]
                moves, first_line = _Moves(step), last.line  # type: ignore[union-attr]
            after = []
            last = block
            if not (kind is Pass and event.skipped) and _may_act(block.signature):  # type: ignore[union-attr]
                before, after = actions_of(block)
                inverse_time = _inverse_time(block, inverse_time)
                for text in before:
                    yield moves.sample(Action(text, block.line), first_line)
                    moves, first_line = _Moves(step), block.line
        if kind is Line or kind is Arc:
            extra = _add(moves, event, extra, inverse_time)  # type: ignore[arg-type]
    for text in after:
        yield moves.sample(Action(text, last.line), first_line)  # type: ignore[union-attr]
        moves = _Moves(step)
    yield moves.sample(None, first_line)


def _may_act(signature: str | None) -> bool:
    """Whether a block may hold an action or a feed mode: its signature (the letters of a plain
    block's words, G words with their numbers) names one; None (not a plain block) may."""
    return signature is None or any(c in signature for c in "MTSHDP") or "G4" in signature or "G9" in signature


def _add(moves: _Moves, event: Line | Arc, extra: tuple[float, ...], inverse_time: bool) -> tuple[float, ...]:
    """Add a move; return the extra axes' positions after it."""
    ctx = event.context
    (ox, oy, oz), u = ctx.offset, ctx.unit_mm
    (x0, y0, z0), (x1, y1, z1) = event.start, event.end
    moves.ends.append(((x0 + ox) * u, (y0 + oy) * u, (z0 + oz) * u, (x1 + ox) * u, (y1 + oy) * u, (z1 + oz) * u))
    end_extra = (tuple(event.extra) + NO_EXTRA)[: len(EXTRA_AXES)] if event.extra else extra
    moves.extra.append((extra, end_extra))
    rapid = type(event) is Line and event.rapid  # type: ignore[union-attr]
    moves.rapid.append(rapid)
    line = event.block.line
    moves.lines.append(line)
    if type(event) is Arc:
        i, j, _ = PLANE_AXES[ctx.plane]
        cx, cy, cz = event.center
        centre = ((cx + ox) * u, (cy + oy) * u, (cz + oz) * u)
        moves.arcs.append((len(moves.ends) - 1, ctx.plane, centre[i], centre[j], event.turn))
    if not rapid:
        if inverse_time:
            moves.inverse_time += 1.0 / event.feed if event.feed > 0 else math.inf
        else:
            feed = event.feed * u
            if not moves.feeds or not math.isclose(moves.feeds[-1][0], feed, rel_tol=1e-9, abs_tol=1e-9):
                moves.feeds.append((feed, line))
    return end_extra


def _inverse_time(block: Block, now: bool) -> bool:
    """G93 / G94 / G95 as the block leaves them (the ISO family's modal group 5)."""
    for item in block.items:
        if type(item) is Word and item.letter in "Gg" and item.value in (93.0, 94.0, 95.0):
            now = item.value == 93.0
    return now


def read_sections(stream: BinaryIO, file: str, dialect: str, offsets: WorkOffsets | None, step: float) -> Iterator[Section]:
    """A program's sections as ncpp's parser and interpreter read its text afresh."""
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    name, blocks = parse_program(stream, file, dialect)
    interpret, _ = dialect_tools(name)
    quiet = Warnings(stream=_Discard())
    events = interpret(blocks, file=file, warnings=quiet, offsets=offsets or AT_MACHINE_ZERO)
    return sections(events, step)


class _Discard:
    def write(self, text: str) -> int:
        return len(text)


@dataclass(frozen=True)
class Bound:
    """How far a written path may lie from the programmed one (mm)."""

    distance: float

    @property
    def step(self) -> float:
        return self.distance / 4


def verify(original: BinaryIO, written: BinaryIO, *, file: str, dialect: str | None, offsets: WorkOffsets | None,
           bound: Bound) -> int:  # fmt: skip
    """Compare the written program with the original, section by section; raise NcppError
    at the original's line where they part.  Returns the number of sections compared."""
    if dialect is None:
        from ncpp.program.dialects import SNIFF_BYTES, detect

        dialect = detect(original.read(SNIFF_BYTES), file)
        original.seek(0)
    mine = read_sections(original, file, dialect, offsets, bound.step)
    theirs = read_sections(written, file, dialect, offsets, bound.step)
    count, line = 0, 1
    while True:
        a = next(mine, None)
        try:
            b = next(theirs, None)
        except NcppError as err:
            text = _line_text(written, err.where.line)
            raise NcppError(f"verification: ncpp cannot read back the program it wrote: {err.message}, "
                            f"at its line {err.where.line} {text!r}", Location(file, a.first_line if a else line, 1)) from None
        if a is None and b is None:
            return count
        if a is None or b is None:
            raise NcppError("verification: the written program does not end its actions where the original does",
                            Location(file, a.first_line if a else line, 1))
        compare(a, b, bound, file)
        count, line = count + 1, a.action.line if a.action else a.first_line


def _line_text(stream: BinaryIO, number: int | None) -> str:
    """Line `number` of a program file, stripped, for a message (at most 120 characters)."""
    if number is None:
        return ""
    stream.seek(0)
    for n, raw in enumerate(stream, 1):
        if n == number:
            return raw.decode("latin-1").strip()[:120]
    return ""


def compare(original: Section, written: Section, bound: Bound, file: str) -> None:
    """Raise NcppError where the written section does not do what the original does."""
    a, b = original.action, written.action
    if (a is None) != (b is None) or (a is not None and a.text != b.text):  # type: ignore[union-attr]
        where = a.line if a is not None else original.first_line
        raise NcppError(f"verification: the written program does {_what(b)} where the original does {_what(a)}", Location(file, where, 1))
    within = bound.distance + bound.step / 2  # a point of either path lies within `step` / 2 of a sample
    width = max(original.points.shape[1], written.points.shape[1])
    _follows(written, original, within, width, file, "the written path leaves the original's", True)
    _follows(original, written, within, width, file, "the written path does not follow the original's", False)
    _same_feeds(original, written, file)


def _what(action: Action | None) -> str:
    return f"'{action.text}'" if action is not None else "nothing more"


def _follows(path: Section, along: Section, within: float, width: int, file: str, message: str, written: bool) -> None:
    """Raise where a sample of `path` lies further than `within` from every sample of `along`
    of its kind (rapid or feed).  A written path's fault is told at the original's nearest line."""
    if not len(path.points):
        return
    if not len(along.points):
        line = along.first_line if written else int(path.lines[0])
        raise NcppError(f"verification: {message}: it has no move here", Location(file, line, 1))
    apart = 4 * within  # a rapid's samples lie this far from a feed's along an extra coordinate
    tree = cKDTree(_coordinates(along, width, apart))
    distance, _ = tree.query(_coordinates(path, width, apart), distance_upper_bound=within)
    far = np.flatnonzero(np.isinf(distance))
    if not len(far):
        return
    k = int(far[0])
    point = _coordinates(path, width, 0.0)[k]
    gap, near = cKDTree(_coordinates(along, width, 0.0)).query(point)
    line = int(along.lines[near]) if written else int(path.lines[k])
    if gap <= within and written:
        message = "the written program makes a " + ("rapid move where the original cuts" if path.rapid[k] else "feed move where the original rapids")
    elif gap <= within:
        message = "the written program " + ("feeds where the original rapids" if path.rapid[k] else "rapids where the original cuts")
    else:
        message = f"{message} by more than {within:.4f} mm"
    raise NcppError(f"verification: {message}", Location(file, line, 1))


def _coordinates(section: Section, width: int, apart: float) -> np.ndarray:
    """A section's samples as `width` coordinates (extra axes zero where it has none), and,
    with `apart`, one more that keeps rapids' and feeds' samples that far apart."""
    points = section.points
    if points.shape[1] < width:
        points = np.hstack((points, np.zeros((len(points), width - points.shape[1]))))
    if apart:
        points = np.hstack((points, (section.rapid * apart)[:, None]))
    return points


def _same_feeds(original: Section, written: Section, file: str) -> None:
    mine, theirs = [f for f, _ in original.feeds], [f for f, _ in written.feeds]
    for k, (a, b) in enumerate(zip_longest(mine, theirs)):
        if a is None or b is None or not math.isclose(a, b, rel_tol=1e-6, abs_tol=1e-9):
            line = original.feeds[k][1] if k < len(original.feeds) else original.first_line
            raise NcppError(f"verification: the written program feeds at {_rate(b)} where the original feeds at {_rate(a)}",
                            Location(file, line, 1))
    a, b = original.inverse_time, written.inverse_time
    if not math.isclose(a, b, rel_tol=1e-4, abs_tol=1e-7):
        raise NcppError(f"verification: the written program's inverse-time moves take {b:.6g} min where the original's take {a:.6g} min",
                        Location(file, original.first_line, 1))


def _rate(value: float | None) -> str:
    return "nothing" if value is None else f"{value:g} mm/min"
