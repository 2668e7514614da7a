"""The box a program's moves sweep, per work coordinate system and per tool.

Feed and rapid moves both count (a rapid crashes as well as a cut); an arc counts
by its true extent (the quadrant points it passes, not only its end points).  A
move counts by where it goes: its start is the previous move's end, and where
the tool stands before the first move is not known.
Boxes are kept in program coordinates (mm) and, where the zero the control holds
is known, in machine axis positions (mm): the program plus the work offset, G92
and the tool length in effect, as `Context.to_machine` says.  A zero is known where ncpp is told it
or where the program sets it itself (G10 L2 with X Y Z, Fanuc's G10 L20: `Context.zero_set`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field

import numpy as np

from ncpp.motion.segments import PLANE_AXES, Arc, Context, Event, Line

AXES = "XYZ"


@dataclass
class Box:
    """The extent of some moves: lowest and highest X, Y, Z (mm), and the lines they come from."""

    lo: np.ndarray = field(default_factory=lambda: np.full(3, math.inf))
    hi: np.ndarray = field(default_factory=lambda: np.full(3, -math.inf))
    first_line: int = 0
    last_line: int = 0
    moves: int = 0

    def add(self, points: np.ndarray, line: int) -> None:
        self.lo = np.minimum(self.lo, points.min(axis=0))
        self.hi = np.maximum(self.hi, points.max(axis=0))
        self.first_line = self.first_line or line
        self.last_line = line
        self.moves += 1

    @property
    def empty(self) -> bool:
        return self.moves == 0

    def as_dict(self) -> dict[str, list[float]]:
        return {a: [round(float(self.lo[i]), 6), round(float(self.hi[i]), 6)] for i, a in enumerate(AXES)}


@dataclass
class Extent:
    """One group's boxes: in program mm, and in machine mm over its moves whose zero is known."""

    name: str
    program: Box = field(default_factory=Box)
    machine: Box = field(default_factory=Box)
    unknown_zero: int = 0  # moves whose zero the control holds is not known
    zero_from_program: bool = False  # some of its moves run where the program set the zero itself (G10)


def move_points(move: Line | Arc) -> np.ndarray:
    """The points that bound where a move goes, program units: its end point and, of an arc,
    the quadrant points its sweep passes (the normal axis of a helix moves linearly).  Its
    start is where the move before it ended (or, for the first, a point nobody knows)."""
    ends = np.array([move.end], dtype=float)
    if type(move) is not Arc:
        return ends
    i, j, _ = PLANE_AXES[move.context.plane]
    radius = move.radius()
    start = math.atan2(move.start[j] - move.center[j], move.start[i] - move.center[i])
    sweep = move.sweep()
    low, high = sorted((start, start + sweep))
    quadrants = np.arange(math.ceil(low / (math.pi / 2)), math.floor(high / (math.pi / 2)) + 1) * (
        math.pi / 2
    )
    points = np.repeat(ends[:1], len(quadrants), axis=0)
    points[:, i] = move.center[i] + radius * np.cos(quadrants)
    points[:, j] = move.center[j] + radius * np.sin(quadrants)
    return np.vstack([ends, points])


def extents(
    events: Iterable[Event], zero_known: Callable[[Context], bool], system_name: Callable[[Context], str]
) -> tuple[Extent, dict[str, Extent], dict[str, Extent]]:
    """The whole program's extent, and per work coordinate system (named by `system_name`)
    and per tool ("" none); machine boxes only of moves whose zero is known: where the program set
    it (G10), as the interpreter says (`Context.zero_set`), elsewhere as `zero_known` says."""
    whole = Extent("all moves")
    systems: dict[str, Extent] = {}
    tools: dict[str, Extent] = {}
    for move in events:
        if type(move) is not Line and type(move) is not Arc:
            continue
        context, line = move.context, move.block.line
        program = move_points(move)
        name = system_name(context)
        groups = (
            whole,
            systems.setdefault(name, Extent(name)),
            tools.setdefault(context.tool_id, Extent(context.tool_id)),
        )
        known = zero_known(context) if context.zero_set is None else context.zero_set
        machine = (program + np.array(context.offset)) * context.unit_mm if known else None
        groups[1].zero_from_program |= context.zero_set is True
        for group in groups:
            group.program.add(program * context.unit_mm, line)
            if machine is None:
                group.unknown_zero += 1
            else:
                group.machine.add(machine, line)
    return whole, systems, tools


@dataclass(frozen=True)
class AxisFit:
    """How a box's span of one axis sits in the machine's travel: mm beyond each end (0: within)."""

    travel: tuple[float, float]
    below_mm: float
    above_mm: float

    @property
    def fits(self) -> bool:
        return self.below_mm == 0.0 and self.above_mm == 0.0

    def as_dict(self) -> dict:
        return {"travel": list(self.travel), "fits": self.fits, "below_mm": round(self.below_mm, 6),
                "above_mm": round(self.above_mm, 6)}  # fmt: skip


def fit_in_travel(
    box: Box, limits: Mapping[str, tuple[float, float]], slack_mm: float = 1e-6
) -> dict[str, AxisFit]:
    """Per axis the machine file gives travel for: by how much the box leaves it at each end."""
    out = {}
    for i, axis in enumerate(AXES):
        if axis not in limits:
            continue
        lo, hi = limits[axis]
        below, above = lo - float(box.lo[i]), float(box.hi[i]) - hi
        out[axis] = AxisFit((lo, hi), below if below > slack_mm else 0.0, above if above > slack_mm else 0.0)
    return out
