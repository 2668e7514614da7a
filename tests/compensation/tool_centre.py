"""Tool-centre paths as LinuxCNC's rs274 prints them (under cutter compensation its
STRAIGHT_FEED and ARC_FEED calls are the tool centre's), and how far a machine with errors
known in closed form puts a rewritten program's tool centre from the original's path.
Nothing of ncpp's own interpreter or simulator is used."""

from __future__ import annotations

import math
import os
import re
import subprocess
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from tests.conftest import RS274

_CALL = re.compile(r"\b(STRAIGHT_FEED|STRAIGHT_TRAVERSE|ARC_FEED)\(([^)]*)\)")


@dataclass(frozen=True)
class Move:
    """A feed move of the tool centre in XY (an arc's centre and turn: rs274's ARC_FEED)."""

    start: NDArray  # (3,)
    end: NDArray  # (3,)
    centre: NDArray | None = None  # (2,) an arc's
    turn: int = 0  # +1 counter-clockwise, -1 clockwise

    def samples(self, count: int = 16) -> NDArray:
        """(count,3) points along the move, ends included."""
        t = np.linspace(0.0, 1.0, count)
        if self.centre is None:
            return self.start + t[:, None] * (self.end - self.start)
        a0, a1, radius = self._angles()
        sweep = (a1 - a0) % (2 * math.pi) if self.turn > 0 else -((a0 - a1) % (2 * math.pi))
        sweep = sweep if abs(sweep) > 1e-12 else 2 * math.pi * self.turn
        angle = a0 + t * sweep
        z = self.start[2] + t * (self.end[2] - self.start[2])
        return np.column_stack([self.centre[0] + radius * np.cos(angle), self.centre[1] + radius * np.sin(angle), z])

    def distance(self, p: NDArray) -> NDArray:
        """(n,) distance in XY of points p (n,3) from the move."""
        xy = p[:, :2]
        if self.centre is None:
            a, b = self.start[:2], self.end[:2]
            ab = b - a
            t = np.clip(((xy - a) @ ab) / max(ab @ ab, 1e-300), 0.0, 1.0)
            return np.linalg.norm(xy - (a + t[:, None] * ab), axis=1)
        a0, a1, radius = self._angles()
        rel = xy - self.centre
        angle = np.arctan2(rel[:, 1], rel[:, 0])
        # within the swept span: radial distance; else the nearer end
        start, span = (a0, (a1 - a0) % (2 * math.pi)) if self.turn > 0 else (a1, (a0 - a1) % (2 * math.pi))
        span = span if span > 1e-12 else 2 * math.pi
        inside = (angle - start) % (2 * math.pi) <= span
        radial = np.abs(np.linalg.norm(rel, axis=1) - radius)
        ends = np.minimum(np.linalg.norm(xy - self.start[:2], axis=1), np.linalg.norm(xy - self.end[:2], axis=1))
        return np.where(inside, radial, ends)

    def _angles(self) -> tuple[float, float, float]:
        s, e, c = self.start[:2] - self.centre, self.end[:2] - self.centre, self.centre  # type: ignore[operator]
        del c
        return math.atan2(s[1], s[0]), math.atan2(e[1], e[0]), float(np.hypot(*s))


def feed_moves(program: Path, tool_table: Path | None = None, var_file: Path | None = None,
               home: Path | None = None) -> list[Move]:
    """The program's feed moves of the tool centre, program coordinates, as rs274 prints them."""
    env = dict(os.environ, RS274_DIGITS="7")
    if tool_table is not None:
        env["RS274_TOOL_TABLE"] = str(tool_table)
    if var_file is not None:
        env["RS274_VAR_FILE"] = str(var_file)
    if home is not None:
        env["HOME"] = str(home)
    proc = subprocess.run([str(RS274), str(program)], capture_output=True, text=True, env=env, timeout=600,
                          cwd=program.parent, stdin=subprocess.DEVNULL)  # fmt: skip
    errors = [ln for ln in proc.stderr.splitlines() if ln.strip() and ln.strip() != "executing"]
    assert not errors or errors[0].startswith("File ended with no percent sign"), proc.stderr
    moves: list[Move] = []
    at = np.zeros(3)
    for name, args in _CALL.findall(proc.stdout):
        v = [float(a) for a in args.split(",")]
        if name == "ARC_FEED":
            end = np.array([v[0], v[1], v[5]])
            moves.append(Move(at, end, np.array([v[2], v[3]]), int(v[4])))
        else:
            end = np.array(v[:3])
            if name == "STRAIGHT_FEED":
                moves.append(Move(at, end))
        at = end
    return moves


def deviation(original: list[Move], rewritten: list[Move], machine: Callable[[NDArray], NDArray],
              count: int = 16) -> NDArray:
    """(m,) for each rewritten move, the largest distance in XY of its tool centre, run on `machine`
    (command points (n,3) -> where the tool goes), from the original's tool-centre path."""
    out = []
    for move in rewritten:
        reached = machine(move.samples(count))
        out.append(np.min([m.distance(reached) for m in original], axis=0).max())
    return np.array(out)
