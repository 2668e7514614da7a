"""A closed-form accuracy measurement that does not use ncpp's interpreter or model.

LinuxCNC's rs274 (7 decimals) runs the original program and ncpp's output; each
commanded point of the output is mapped through a machine whose error the test
writes down by hand (a pure positioning error, a squareness, a reversal of the
sign it chooses); the measure is how far the mapped path gets from the path the
original program commands.  Programs here run at work offset 0 (rs274's default
parameter file), in G17, so rs274's coordinates are machine coordinates.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path
from typing import Callable

import numpy as np
import pytest

from tests.conftest import RS274

_CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\(([^)]*)\)")
# (n,3) commanded points, (3,) direction each axis travels in (+1, -1) -> (n,3) actual points, mm
Machine = Callable[[np.ndarray, np.ndarray], np.ndarray]
STEP_MM = 0.05  # how densely paths are sampled


def rs274_calls(path: Path) -> list[tuple[str, list[float]]]:
    """rs274's motion calls of a program (7 decimals); fails the test if rs274 refuses it."""
    if not RS274.exists():
        pytest.skip("rs274 oracle not available")
    env = {**os.environ, "RS274_DIGITS": "7"}
    proc = subprocess.run([str(RS274), str(path)], capture_output=True, text=True, env=env, timeout=120, stdin=subprocess.DEVNULL)
    if "executing" not in proc.stderr:
        pytest.skip(f"rs274 oracle did not run: {proc.stderr.strip()[:200]}")
    messages = [line for line in proc.stderr.splitlines() if line.strip() and line.strip() != "executing"]
    assert proc.returncode == 0 and not messages, f"rs274 refused {path.name}: {messages[:3]}"
    return [(name, [float(v) for v in args.split(",")]) for name, args in _CALL.findall(proc.stdout)]


def moves(path: Path, scale: float = 1.0) -> list[tuple[np.ndarray, np.ndarray]]:
    """The program's moves as (start, end) points in mm (rs274's numbers times `scale`: 25.4
    for an inch program), arcs (G17) as short chords; the first starts at (0, 0, 0)."""
    at = np.zeros(3)
    out = []
    for name, args in rs274_calls(path):
        if name == "ARC_FEED":
            end = np.array([args[0], args[1], args[5]]) * scale
            centre, turn = np.array(args[2:4]) * scale, int(args[4])
            a0 = np.arctan2(at[1] - centre[1], at[0] - centre[0])
            a1 = np.arctan2(end[1] - centre[1], end[0] - centre[0])
            sweep = (a1 - a0) % (2 * np.pi) if turn > 0 else -((a0 - a1) % (2 * np.pi))
            radius = np.hypot(*(at[:2] - centre))
            n = max(2, int(abs(sweep) * radius / STEP_MM) + 1)
            t = np.linspace(0.0, 1.0, n)
            pts = np.column_stack([centre[0] + radius * np.cos(a0 + t * sweep), centre[1] + radius * np.sin(a0 + t * sweep),
                                   at[2] + t * (end[2] - at[2])])  # fmt: skip
            out += list(zip(pts[:-1], pts[1:]))
        else:
            end = np.array(args[:3]) * scale
            out.append((at, end))
        at = end
    return out


def actual_moves(path: Path, machine: Machine, scale: float = 1.0) -> list[np.ndarray]:
    """Where the tool really goes on each of the program's moves, (k,3) points along it: the
    commands mapped through `machine` with the direction each axis travels in (a still axis
    holds its last one, +1 before it first moves).  An axis moving one way never goes back:
    where it reverses with lost motion it stands until its command catches up, where it runs
    ahead it jumps the new way at once."""
    held = np.ones(3)
    last = None
    out = []
    for start, end in moves(path, scale):
        moving = end != start
        held = np.where(moving, np.sign(end - start), held)
        n = max(2, int(np.linalg.norm(end - start) / STEP_MM) + 2)
        raw = machine(start + np.linspace(0.0, 1.0, n)[:, None] * (end - start), held)
        if last is not None:
            raw = np.vstack([last[None, :], raw])
            d = np.where(moving, held, 0.0)
            raw = np.where(moving, d * np.maximum.accumulate(d * raw, axis=0), raw)[1:]
        out.append(raw)
        last = raw[-1]
    return out


def _samples(segments: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    pts = []
    for a, b in segments:
        n = max(2, int(np.linalg.norm(b - a) / STEP_MM) + 2)
        pts.append(a + np.linspace(0.0, 1.0, n)[:, None] * (b - a))
    return np.vstack(pts)


def _distance(points: np.ndarray, segments: list[tuple[np.ndarray, np.ndarray]]) -> np.ndarray:
    """(n,) distance of each point to the nearest of the segments."""
    a = np.array([s[0] for s in segments])
    b = np.array([s[1] for s in segments])
    ab = b - a
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-30)
    best = np.full(len(points), np.inf)
    for k in range(0, len(points), 2000):
        p = points[k : k + 2000, None, :]
        t = np.clip(np.einsum("pij,ij->pi", p - a, ab) / length2, 0.0, 1.0)
        d = np.linalg.norm(p - (a + t[..., None] * ab), axis=2)
        best[k : k + 2000] = d.min(axis=1)
    return best


def worst_um(original: Path, output: Path, machine: Machine, skip: int = 0) -> float:
    """µm the tool gets from the original's commanded path at most, running `output` on
    `machine` (the first `skip` moves, the approach from rs274's start, left out)."""
    return worst_at(original, output, machine, skip)[0]


def holes_um(output: Path, original: Path, machine: Machine, scale: float = 1.0) -> np.ndarray:
    """µm each hole (the end of a feed move down Z) lands from the original's, running
    `output` on `machine`."""

    def bottoms(path: Path, segments) -> np.ndarray:
        feeds = [(name, args) for name, args in rs274_calls(path) if name != "ARC_FEED"]
        assert len(feeds) == len(segments)
        return np.array([b for (name, _), (a, b) in zip(feeds, segments) if name == "STRAIGHT_FEED" and b[2] < a[2] - 1e-9])

    got = bottoms(output, [(m[0], m[-1]) for m in actual_moves(output, machine, scale)])
    wanted = bottoms(original, moves(original, scale))
    assert got.shape == wanted.shape
    return np.linalg.norm(got - wanted, axis=1) * 1000


def worst_at(original: Path, output: Path, machine: Machine, skip: int = 0) -> tuple[float, np.ndarray]:
    """`worst_um`, and the point of the mapped path where it is."""
    points = np.vstack(actual_moves(output, machine)[skip:])
    points = _samples(list(zip(points[:-1], points[1:])))
    d = _distance(points, moves(original)[skip:])
    return float(d.max() * 1000), points[int(d.argmax())]
