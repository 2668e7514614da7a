"""Tool-centre paths as LinuxCNC's rs274 prints them (under cutter compensation its
STRAIGHT_FEED and ARC_FEED calls are the tool centre's), and how far a machine with errors
known in closed form puts a rewritten program's tool centre from the original's path.
Nothing of ncpp's own interpreter or simulator is used."""

from __future__ import annotations

import functools
import math
import re
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tests import rs274

_CALL = re.compile(
    r"\b(STRAIGHT_FEED|STRAIGHT_TRAVERSE|ARC_FEED|RIGID_TAP|SET_G5X_OFFSET|SET_G92_OFFSET|SET_XY_ROTATION"
    r"|USE_LENGTH_UNITS"
    r"|USE_TOOL_LENGTH_OFFSET|SELECT_PLANE"
    r"|COMMENT)\((\"interpreter: cutter radius compensation (?:on|off)|[^)]*)"
)
# rs274's ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end_point, ...): the
# plane's first, second and normal axis, and the rotation counter-clockwise from first to second
_PLANES = {"CANON_PLANE_XY": (0, 1, 2), "CANON_PLANE_XZ": (2, 0, 1), "CANON_PLANE_YZ": (1, 2, 0)}


@dataclass(frozen=True)
class Move:
    """A feed move of the tool centre (an arc's centre and turn: rs274's ARC_FEED; a rigid tap's
    way down: RIGID_TAP, whose return retraces it), machine coordinates in mm as the program puts
    them: its work offsets, G92 and tool length offset added, where the machine's axes stand (under
    LinuxCNC's G10 L2 R the point plus G92 turned about Z before the rest is added: `_placed`)."""

    start: NDArray  # (3,)
    end: NDArray  # (3,)
    centre: NDArray | None = None  # (2,) an arc's, in its plane's first and second axis
    turn: int = 0  # +1 counter-clockwise, -1 clockwise
    comp: int = 0  # under cutter compensation, or the exit move after it: the number of its G41/G42 (from 1)
    axes: tuple[int, int, int] = (0, 1, 2)  # an arc's plane: its first, second and normal axis
    tool: NDArray = field(default_factory=lambda: np.zeros(3))  # the tool length offset in effect, mm

    def samples(self, count: int = 16) -> NDArray:
        """(count,3) points along the move, ends included (an arc whose end radius differs from its
        start's blends from one to the other, as LinuxCNC's motion does)."""
        t = np.linspace(0.0, 1.0, count)
        if self.centre is None:
            return self.start + t[:, None] * (self.end - self.start)
        a0, r0, sweep, r1 = self.polar()
        angle, radius = a0 + t * sweep, r0 + t * (r1 - r0)
        u, v, w = self.axes
        out = np.empty((count, 3))
        out[:, u] = self.centre[0] + radius * np.cos(angle)
        out[:, v] = self.centre[1] + radius * np.sin(angle)
        out[:, w] = self.start[w] + t * (self.end[w] - self.start[w])
        return out

    def polar(self) -> tuple[float, float, float, float]:
        """An arc's start angle and radius, signed sweep (rad) and end radius."""
        plane = list(self.axes[:2])
        s, e = self.start[plane] - self.centre, self.end[plane] - self.centre  # type: ignore[operator]
        a0, a1 = math.atan2(s[1], s[0]), math.atan2(e[1], e[0])
        span = (a1 - a0) % (2 * math.pi) if self.turn > 0 else (a0 - a1) % (2 * math.pi)
        span = (span if span > 1e-12 else 2 * math.pi) + 2 * math.pi * (abs(self.turn) - 1)
        return a0, float(np.hypot(*s)), math.copysign(span, self.turn), float(np.hypot(*e))


def feed_moves(
    program: Path, tool_table: Path | None = None, var_file: Path | None = None, home: Path | None = None
) -> list[Move]:
    """The program's feed moves of the tool centre, program coordinates, as rs274 prints them."""
    proc = rs274.run(program, var_file=var_file, tool_table=tool_table, digits=7, home=home,
                     cwd=program.parent, timeout=600)  # fmt: skip
    errors = rs274.messages(proc)
    assert not errors or errors[0].startswith("File ended with no percent sign"), proc.stderr
    moves: list[Move] = []
    at = np.zeros(3)
    # the offsets in mm (rs274 prints them in the units then)
    g5x, g92, tool, scale = np.zeros(3), np.zeros(3), np.zeros(3), 1.0
    turn = 0.0  # SET_XY_ROTATION's, degrees
    comp = leaving = sections = 0
    axes = (0, 1, 2)
    for name, args in _CALL.findall(proc.stdout):
        if name == "COMMENT":
            if args.startswith('"interpreter: cutter radius compensation'):
                if args.endswith("on"):
                    sections += 1
                comp, leaving = sections if args.endswith("on") else 0, comp if args.endswith("off") else 0
            continue
        if name == "SELECT_PLANE":
            axes = _PLANES[args.strip()]
            continue
        if name == "USE_LENGTH_UNITS":
            scale = 25.4 if "INCH" in args else 1.0
            continue
        v = [float(a) for a in args.replace(" ", ",").split(",") if a]
        if name == "SET_G5X_OFFSET":
            g5x = np.array(v[1:4]) * scale
            continue
        if name == "SET_G92_OFFSET":
            g92 = np.array(v[:3]) * scale
            continue
        if name == "USE_TOOL_LENGTH_OFFSET":
            tool = np.array(v[:3]) * scale
            continue
        if name == "SET_XY_ROTATION":
            turn = v[0]
            continue
        placed = functools.partial(_placed, g92=g92, turn=turn, after=g5x + tool)
        if name == "ARC_FEED":
            assert turn == 0.0 or axes == (0, 1, 2), "an arc out of the XY plane under G10 L2 R"
            end = np.empty(3)
            end[list(axes)] = v[0], v[1], v[5]
            end = placed(end * scale)
            centre = placed(np.array([v[2], v[3], 0.0]) * scale)[:2] if turn else (
                np.array(v[2:4]) * scale + (g5x + g92 + tool)[list(axes[:2])])  # fmt: skip
            moves.append(Move(at, end, centre, int(v[4]), comp or leaving, axes, tool))
        else:
            end = placed(np.array(v[:3]) * scale)
            if name == "STRAIGHT_FEED" or name == "RIGID_TAP":
                moves.append(Move(at, end, comp=comp or leaving, tool=tool))
            if name == "RIGID_TAP":  # (the control returns to where the tap started)
                end = at
        leaving = 0
        at = end
    return moves


def _placed(point: NDArray, g92: NDArray, turn: float, after: NDArray) -> NDArray:
    """Where the control puts a program point (mm): rs274ngc's canon adds G92, turns X Y by the
    rotation (degrees), then adds the work offset and the tool length (`after`)."""
    p = point + g92
    if turn:
        c, s = math.cos(math.radians(turn)), math.sin(math.radians(turn))
        p = np.array([c * p[0] - s * p[1], s * p[0] + c * p[1], p[2]])
    return p + after


def deviation(
    original: list[Move], rewritten: list[Move], machine: Callable[[NDArray], NDArray], count: int = 16
) -> NDArray:
    """(m,) for each rewritten move, the largest distance (mm) of its tool centre, run on `machine`
    (command points (n,3), machine mm -> where the tool goes), from the original's tool-centre path."""
    path = _Path(original)
    return np.array([path.distance(machine(move.samples(count))).max() for move in rewritten])


class _Path:
    """A tool-centre path's lines and arcs (helices) as arrays, for distances to many points at once."""

    def __init__(self, moves: list[Move]):
        lines = [m for m in moves if m.centre is None]
        arcs = [m for m in moves if m.centre is not None]
        self.a = np.array([m.start for m in lines]).reshape(-1, 3)
        self.ab = np.array([m.end for m in lines]).reshape(-1, 3) - self.a
        self.ends = np.array([p for m in arcs for p in (m.start, m.end)]).reshape(-1, 3)
        self.centre = np.array([m.centre for m in arcs]).reshape(-1, 2)
        self.axes = np.array([m.axes for m in arcs], dtype=np.intp).reshape(-1, 3)
        self.z0 = np.array([m.start[m.axes[2]] for m in arcs])
        self.rise = np.array([m.end[m.axes[2]] - m.start[m.axes[2]] for m in arcs])
        self.a0, self.r0, sweep, self.r1 = np.array([m.polar() for m in arcs]).reshape(-1, 4).T
        self.turn, self.span = np.sign(sweep), np.abs(sweep)

    def distance(self, p: NDArray) -> NDArray:
        """(n,) distance of points p (n,3) from the path (an arc's: within its sweep, from the point of
        the arc at the point's angle, its radius and height blended; else from its nearer end)."""
        best = np.full(len(p), np.inf)
        at = p[:, None, :]
        if len(self.a):
            t = np.clip(
                ((at - self.a) * self.ab).sum(-1) / np.maximum((self.ab**2).sum(-1), 1e-300), 0.0, 1.0
            )
            best = np.minimum(
                best, np.linalg.norm(at - (self.a + t[..., None] * self.ab), axis=-1).min(axis=1)
            )
        if len(self.centre):  # each point in each arc's plane axes (n,m,3)
            local = np.take_along_axis(
                np.broadcast_to(at, (len(p), len(self.axes), 3)), self.axes[None], axis=-1
            )
            rel = local[..., :2] - self.centre
            travelled = (self.turn * (np.arctan2(rel[..., 1], rel[..., 0]) - self.a0)) % (2 * math.pi)
            inside = travelled <= self.span  # (one turn at most: the test programs' arcs)
            part = travelled / self.span
            radial = np.abs(np.linalg.norm(rel, axis=-1) - (self.r0 + part * (self.r1 - self.r0)))
            height = local[..., 2] - (self.z0 + self.rise * part)
            best = np.minimum(best, np.where(inside, np.hypot(radial, height), np.inf).min(axis=1))
            best = np.minimum(best, np.linalg.norm(at - self.ends, axis=-1).min(axis=1))
        return best
