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
applied), sampled every quarter of the bound: a point found within the bound
less half a step of a sample is within the bound of the path.  A violation is
an `NcppError` at the input line where it happens.
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

WIDTH = 3 + len(EXTRA_AXES)  # a sample's coordinates: X Y Z, then A B C U V W
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

    points: np.ndarray  # (n, WIDTH) machine mm (extra axes in their own unit)
    rapid: np.ndarray  # (n,) bool
    lines: np.ndarray  # (n,) source line of each sample
    feeds: list[tuple[float, int]]  # G94/G95 feed rates in order, each once per run, with its first line
    inverse_time: float  # minutes the G93 moves take
    action: Action | None
    first_line: int


@dataclass
class _Moves:
    """Moves collected for one section, sampled when it closes."""

    step: float
    starts: list = field(default_factory=list)
    ends: list = field(default_factory=list)
    rapid: list = field(default_factory=list)
    lines: list = field(default_factory=list)
    arcs: list = field(default_factory=list)  # per move: None or (plane, centre i, centre j, turn)
    feeds: list = field(default_factory=list)
    inverse_time: float = 0.0

    def sample(self, action: Action | None, first_line: int) -> Section:
        if not self.starts:
            empty = np.zeros((0, WIDTH))
            return Section(empty, np.zeros(0, bool), np.zeros(0, int), self.feeds, self.inverse_time, action, first_line)
        starts, ends = np.array(self.starts), np.array(self.ends)
        lengths = np.array([_length(s, e, arc) for s, e, arc in zip(self.starts, self.ends, self.arcs)])
        counts = np.maximum(1, np.ceil(lengths / self.step).astype(np.int64))
        move = np.repeat(np.arange(len(counts)), counts + 1)
        first = np.concatenate(([0], np.cumsum(counts + 1)[:-1]))
        t = (np.arange(len(move)) - first[move]) / counts[move]
        points = starts[move] + t[:, None] * (ends - starts)[move]
        for k, arc in enumerate(self.arcs):
            if arc is not None:
                rows = slice(first[k], first[k] + counts[k] + 1)
                _bend(points[rows], t[rows], starts[k], ends[k], arc)
        rapid = np.array(self.rapid)[move]
        lines = np.array(self.lines)[move]
        return Section(points, rapid, lines, self.feeds, self.inverse_time, action, first_line)


def _length(start: np.ndarray, end: np.ndarray, arc: tuple | None) -> float:
    chord = float(np.linalg.norm(end - start))
    if arc is None:
        return chord
    plane, ci, cj, turn = arc
    i, j, _ = PLANE_AXES[plane]
    radius = max(math.hypot(start[i] - ci, start[j] - cj), math.hypot(end[i] - ci, end[j] - cj))
    return abs(_sweep(start, end, arc)) * radius + chord


def _sweep(start: np.ndarray, end: np.ndarray, arc: tuple) -> float:
    """Signed angle an arc turns (rs274's ARC_FEED rotation: +1 counter-clockwise)."""
    plane, ci, cj, turn = arc
    i, j, _ = PLANE_AXES[plane]
    a0 = math.atan2(start[j] - cj, start[i] - ci)
    a1 = math.atan2(end[j] - cj, end[i] - ci)
    full = 2 * math.pi
    if turn > 0:
        d = (a1 - a0) % full
        return (d if d > 1e-12 else full) + full * (turn - 1)
    d = (a0 - a1) % full
    return -((d if d > 1e-12 else full) + full * (-turn - 1))


def _bend(points: np.ndarray, t: np.ndarray, start: np.ndarray, end: np.ndarray, arc: tuple) -> None:
    """Put an arc's samples (made along its chord) on the arc, in place; the radius changes
    linearly from start to end, as rs274 interpolates an arc whose radii differ."""
    plane, ci, cj, _ = arc
    i, j, _ = PLANE_AXES[plane]
    a0 = math.atan2(start[j] - cj, start[i] - ci)
    r0, r1 = math.hypot(start[i] - ci, start[j] - cj), math.hypot(end[i] - ci, end[j] - cj)
    angle = a0 + _sweep(start, end, arc) * t
    radius = r0 + (r1 - r0) * t
    points[:, i] = ci + radius * np.cos(angle)
    points[:, j] = cj + radius * np.sin(angle)


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
    position: np.ndarray | None = None
    extra = np.zeros(len(EXTRA_AXES))
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
            if not (kind is Pass and event.skipped):  # type: ignore[union-attr]
                before, after = actions_of(block)
                inverse_time = _inverse_time(block, inverse_time)
                for text in before:
                    yield moves.sample(Action(text, block.line), first_line)
                    moves, first_line = _Moves(step), block.line
        if kind is not Line and kind is not Arc:
            continue
        ctx = event.context  # type: ignore[union-attr]
        if event.extra:  # type: ignore[union-attr]
            extra = np.zeros(len(EXTRA_AXES))
            extra[: len(event.extra)] = event.extra  # type: ignore[union-attr]
        start = np.concatenate((ctx.to_machine(event.start), position[3:] if position is not None else extra))  # type: ignore[union-attr]
        end = np.concatenate((ctx.to_machine(event.end), extra))  # type: ignore[union-attr]
        arc = None
        if kind is Arc:
            i, j, _ = PLANE_AXES[ctx.plane]
            centre = ctx.to_machine(event.center)  # type: ignore[union-attr]
            arc = (ctx.plane, centre[i], centre[j], event.turn)  # type: ignore[union-attr]
        _add(moves, start, end, arc, event, inverse_time)  # type: ignore[arg-type]
        position = end
    for text in after:
        yield moves.sample(Action(text, last.line), first_line)  # type: ignore[union-attr]
        moves = _Moves(step)
    yield moves.sample(None, first_line)


def _add(moves: _Moves, start: np.ndarray, end: np.ndarray, arc: tuple | None, event: Line | Arc, inverse_time: bool) -> None:
    rapid = type(event) is Line and event.rapid  # type: ignore[union-attr]
    moves.starts.append(start)
    moves.ends.append(end)
    moves.rapid.append(rapid)
    moves.lines.append(event.block.line)
    moves.arcs.append(arc)
    if rapid:
        return
    if inverse_time:
        moves.inverse_time += 1.0 / event.feed if event.feed > 0 else math.inf
        return
    feed = event.feed * event.context.unit_mm
    if not moves.feeds or not math.isclose(moves.feeds[-1][0], feed, rel_tol=1e-9, abs_tol=1e-9):
        moves.feeds.append((feed, event.block.line))


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
    within = bound.distance - bound.step / 2
    _follows(written, original, within, file, "the written path leaves the original's", True)
    _follows(original, written, within, file, "the written path does not follow the original's", False)
    _same_kind(original, written, within, file)
    _same_feeds(original, written, file)


def _what(action: Action | None) -> str:
    return f"'{action.text}'" if action is not None else "nothing more"


def _follows(path: Section, along: Section, within: float, file: str, message: str, report_nearest: bool) -> None:
    """Raise where a sample of `path` lies further than `within` from every sample of `along`."""
    if not len(path.points):
        return
    if not len(along.points):
        line = along.first_line if report_nearest else int(path.lines[0])
        raise NcppError(f"verification: {message}: it has no move here", Location(file, line, 1))
    tree = cKDTree(along.points)
    distance, _ = tree.query(path.points, distance_upper_bound=within)
    far = np.flatnonzero(np.isinf(distance))
    if len(far):
        k = int(far[0])
        line = int(along.lines[tree.query(path.points[k])[1]]) if report_nearest else int(path.lines[k])
        raise NcppError(f"verification: {message} by more than {within:.4f} mm", Location(file, line, 1))


def _same_kind(original: Section, written: Section, within: float, file: str) -> None:
    """Feeds only where the original feeds, rapids only where it rapids."""
    for rapid, label in ((False, "a feed move where the original rapids"), (True, "a rapid move where the original cuts")):
        mine = written.points[written.rapid == rapid]
        if not len(mine):
            continue
        theirs = original.points[original.rapid == rapid]
        if not len(theirs):
            raise NcppError(f"verification: the written program makes {label}", Location(file, original.first_line, 1))
        distance, _ = cKDTree(theirs).query(mine, distance_upper_bound=within)
        far = np.flatnonzero(np.isinf(distance))
        if len(far):
            point = mine[int(far[0])]
            _, near = cKDTree(original.points).query(point)
            raise NcppError(f"verification: the written program makes {label}", Location(file, int(original.lines[near]), 1))


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
