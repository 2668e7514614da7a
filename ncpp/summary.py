"""What a rewriting run did: one line for stderr, the same as JSON (`--report`).

`Summary` watches the events on both sides of the passes and the run's warnings:
the moves the passes may change (count, feed path length), those they leave as
programmed by why (`Line.fixed`), where the program passes through from a
construct ncpp cannot follow on, and the largest correction of a programmed
point (a block's last compensated end against its programmed end, machine mm).
"""

from __future__ import annotations

import json
import math
from collections.abc import Iterable, Iterator
from dataclasses import dataclass, field

from ncpp.errors import Location
from ncpp.motion.segments import (
    COMP,
    CYCLE,
    DRILLED,
    FLOW,
    HELD,
    HOLE,
    HOME,
    MACHINE,
    PATTERN,
    PLANE_AXES,
    TAP_OUT,
    UNPLACED,
    Arc,
    Event,
    Line,
    stores_a_cycle,
)

# Why moves are left as programmed, as the summary names it
REASONS = {
    CYCLE: "canned cycle",
    DRILLED: "drilling cycle (along the tool axis)",
    PATTERN: "hole pattern",
    FLOW: "loop or subroutine",
    COMP: "cutter compensation",
    HOME: "G28/G30 return",
    HELD: "before the program names G00-G03",
    MACHINE: "machine-coordinate move",
    UNPLACED: "move from a position ncpp is not told",
}
OUT_OF_SCOPE = "out of scope"
TRAVEL_END = "at a travel end"
# What the warnings after which the rest of the program passes through say (the interpreters' and
# `pipeline.warn_fixed`'s), and that of a line end left at a travel end (`apply_error_map`)
PASSED_ON = ("the program passes through uninterpreted", "the program passes through uncompensated")
STOPPED_AT_END = "stops at the end, uncompensated there"
WARNING_TEXTS = 1000  # warning texts kept with their first place (memory stays flat in program length)


@dataclass
class Summary:
    file: str = "<stdin>"
    moves: int = 0  # moves the passes compensate
    feed_mm: float = 0.0  # their feed (not rapid) path length
    largest_mm: float = 0.0  # the largest correction of a programmed point
    largest_line: int | None = None
    # reason -> the input lines of its moves, as runs [first, last] (memory by runs, not lines)
    left: dict[str, list[list[int]]] = field(default_factory=dict)
    left_moves: dict[str, int] = field(default_factory=dict)  # reason -> moves
    passed_on_from: int | None = None  # the line from which the program passes through (out of scope)
    # warning text -> (first place, times), for the first WARNING_TEXTS texts
    warned: dict[str, tuple[Location, int]] = field(default_factory=dict)
    warnings: int = 0
    lines_in: int = 0
    lines_out: int = 0

    def __post_init__(self) -> None:
        # id(block) -> its last move as programmed, until written
        self._programmed: dict[int, Line | Arc] = {}

    # -- the observers ----------------------------------------------------------------
    def heard(self, message: str, where: Location) -> None:
        """A warning of the run (`Warnings.listeners`)."""
        self.warnings += 1
        first, times = self.warned.get(message, (where, 0))
        if times or len(self.warned) < WARNING_TEXTS:
            self.warned[message] = (first, times + 1)
        if (
            self.passed_on_from is None
            and any(text in message for text in PASSED_ON)
            and where.line is not None
        ):
            self.passed_on_from = where.line
        elif STOPPED_AT_END in message and where.line is not None:
            self._leave(TRAVEL_END, where.line, count=False)

    def programmed(self, events: Iterable[Event]) -> Iterator[Event]:
        """The events as the passes take them."""
        programmed, dist = self._programmed, math.dist
        moves, feed = 0, 0.0
        try:
            for event in events:
                kind = type(event)
                if kind is Line:
                    if stores_a_cycle(event):  # type: ignore[arg-type]
                        pass  # (no move)
                    elif event.fixed and event.fixed != HOLE:  # type: ignore[union-attr]  # (HOLE: compensated)
                        self._leave(REASONS.get(event.fixed, event.fixed), event.block.line)  # type: ignore[union-attr]
                    else:
                        moves += 1
                        if not event.rapid:  # type: ignore[union-attr]
                            feed += dist(event.start, event.end) * event.context.unit_mm  # type: ignore[union-attr]
                        if event.tap != TAP_OUT:  # type: ignore[union-attr]  # (a tap's block ends at its bottom)
                            programmed[id(event.block)] = event  # type: ignore[assignment]
                elif kind is Arc:
                    if event.fixed:  # type: ignore[union-attr]
                        self._leave(REASONS.get(event.fixed, event.fixed), event.block.line)  # type: ignore[union-attr]
                    else:
                        moves += 1
                        feed += path_length(event)  # type: ignore[arg-type]
                        programmed[id(event.block)] = event  # type: ignore[assignment]
                yield event
        finally:  # (counted locally: an attribute per event costs a tenth of the pipeline's time)
            self.moves += moves
            self.feed_mm += feed

    def written(self, events: Iterable[Event]) -> Iterator[Event]:
        """The events as the passes hand them on: each block's last compensated move
        against its programmed one."""
        block = None
        last: Line | Arc | None = None
        for event in events:
            kind = type(event)
            if kind is Line or kind is Arc:
                if event.block is block:
                    kept = not event.fixed or event.fixed == HOLE  # type: ignore[union-attr]  # (not M140's retract)
                    if kept and not (kind is Line and event.tap == TAP_OUT):  # type: ignore[union-attr]  # (nor a tap's return)
                        last = event  # type: ignore[assignment]
                elif not event.fixed or event.fixed == HOLE:  # type: ignore[union-attr]
                    self._settle(block, last)
                    block, last = event.block, event  # type: ignore[assignment]
            yield event
        self._settle(block, last)

    def _settle(self, block, last: Line | Arc | None) -> None:
        programmed = self._programmed.pop(id(block), None) if last is not None else None
        if programmed is None:
            return
        context = last.context  # type: ignore[union-attr]
        if context is programmed.context:  # (mostly: the same offsets and units, so only the points differ)
            moved = math.dist(last.end, programmed.end) * context.unit_mm  # type: ignore[union-attr]
        else:
            moved = math.dist(context.to_machine(last.end), programmed.context.to_machine(programmed.end))  # type: ignore[union-attr]
        if moved > self.largest_mm:
            self.largest_mm, self.largest_line = moved, block.line

    def _leave(self, reason: str, line: int, count: bool = True) -> None:
        runs = self.left.setdefault(reason, [])
        if runs and line == runs[-1][1] + 1:
            runs[-1][1] = line
        elif not (runs and runs[-1][0] <= line <= runs[-1][1]):
            runs.append([line, line])
        if count:
            self.left_moves[reason] = self.left_moves.get(reason, 0) + 1

    # -- what it says -------------------------------------------------------------------
    def line(self, name: str | None = None) -> str:
        """The summary in one line, naming the program `name` (default: its file)."""
        parts = [
            f"compensated {self.moves} moves ({self.feed_mm:.1f} mm of feed path), "
            f"largest correction {1000 * self.largest_mm:.1f} µm"
            + (f" (line {self.largest_line})" if self.largest_line else "")
        ]
        left = [f"{self._left_count(reason, runs)} {_WHY.get(reason, reason)} ({_lines_text(runs)})"
                for reason, runs in self.left.items()]  # fmt: skip
        if self.passed_on_from is not None:
            lines = self.lines_in - self.passed_on_from + 1
            left.append(f"everything from line {self.passed_on_from} on ({lines} lines), out of scope")
        parts.append("left as programmed: " + (", ".join(left) if left else "nothing"))
        parts.append(f"{self.lines_in} lines in, {self.lines_out} out")
        if self.warnings:
            parts.append(f"{self.warnings} warnings")
        return f"ncpp: {name or self.file}: " + "; ".join(parts)

    def _left_count(self, reason: str, runs: list[list[int]]) -> str:
        """How many moves left for `reason` (lines, for a reason told by warnings)."""
        moves = self.left_moves.get(reason)
        return f"{moves} moves" if moves is not None else f"{_count(runs)} lines"

    def as_dict(self) -> dict:
        left = {
            reason: {"moves": self.left_moves.get(reason), "lines": runs}
            for reason, runs in self.left.items()
        }
        if self.passed_on_from is not None:
            left[OUT_OF_SCOPE] = {
                "moves": None,
                "lines": [[self.passed_on_from, max(self.lines_in, self.passed_on_from)]],
            }
        return {
            "file": self.file,
            "moves_compensated": self.moves,
            "feed_path_compensated_mm": round(self.feed_mm, 4),
            "largest_correction_um": round(1000 * self.largest_mm, 3),
            "largest_correction_line": self.largest_line,
            "left_as_programmed": left,
            "lines_in": self.lines_in,
            "lines_out": self.lines_out,
            "warnings": [
                {"message": message, "first_line": where.line, "times": times}
                for message, (where, times) in self.warned.items()
            ],
        }


_WHY = {
    "canned cycle": "of canned cycles",
    "loop or subroutine": "in loops or subroutines",
    "cutter compensation": "under cutter compensation",
    "G28/G30 return": "of G28/G30 returns",
    "before the program names G00-G03": "before the program names G00-G03",
    "machine-coordinate move": "in machine coordinates",
    "move from a position ncpp is not told": "from a position ncpp is not told",
    TRAVEL_END: "with an axis held at a travel end",
}


def path_length(move: Line | Arc) -> float:
    """mm along a move: a line's length, an arc's (with its helix)."""
    if type(move) is Line:
        return move.length() * move.context.unit_mm
    arc: Arc = move
    _, _, normal = PLANE_AXES[arc.context.plane]
    return math.hypot(arc.radius() * arc.sweep(), arc.end[normal] - arc.start[normal]) * arc.context.unit_mm


def _count(runs: list[list[int]]) -> int:
    return sum(last - first + 1 for first, last in runs)


def _lines_text(runs: list[list[int]], shown: int = 4) -> str:
    said = [f"{a}" if a == b else f"{a}-{b}" for a, b in runs]
    more = f" and {len(said) - shown} more" if len(said) > shown else ""
    return ("line " if len(said) == 1 and "-" not in said[0] else "lines ") + ", ".join(said[:shown]) + more


def write_report(path: str, summaries: list[Summary]) -> None:
    """`--report FILE.json`: one program's summary, or a list of several."""
    from ncpp.fileio import write_text_atomic

    data = summaries[0].as_dict() if len(summaries) == 1 else [s.as_dict() for s in summaries]
    write_text_atomic(path, json.dumps(data, indent=2, ensure_ascii=False) + "\n")
