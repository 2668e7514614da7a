"""A closed-form accuracy measurement that does not use ncpp's interpreter or model.

LinuxCNC's rs274 (7 decimals) runs the original program and ncpp's output; each
commanded point of the output is mapped through a machine whose error the test
writes down by hand (a pure positioning error, a squareness, a reversal of the
sign it chooses); the measure is how far the mapped path gets from the path the
original program commands.  Programs here run at work offset 0 (rs274's default
parameter file), in G17, so rs274's coordinates are machine coordinates.
"""

from __future__ import annotations

import re
from collections.abc import Callable
from pathlib import Path

import numpy as np

from tests import rs274

_CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED|USE_LENGTH_UNITS)\(([^)]*)\)")
# (n,3) commanded points, (3,) direction each axis travels in (+1, -1) -> (n,3) actual points, mm
Machine = Callable[[np.ndarray, np.ndarray], np.ndarray]
STEP_MM = 0.05  # how densely paths are sampled


def rs274_calls(path: Path) -> list[tuple[str, list[float]]]:
    """rs274's motion calls of a program (7 decimals), their lengths in mm (rs274 says them in
    the units in effect); fails the test if rs274 refuses it."""
    # (the stand-alone rs274 now and then dies of a bus error, whatever the program: run again)
    calls, unit = [], 1.0
    for name, args in _CALL.findall(rs274.canon(path, digits=7, retries=4)):
        if name == "USE_LENGTH_UNITS":
            unit = 25.4 if "INCHES" in args else 1.0
            continue
        values = [float(v) for v in args.split(",")]
        lengths = (0, 1, 2, 3, 5) if name == "ARC_FEED" else (0, 1, 2)
        calls.append((name, [v * unit if n in lengths else v for n, v in enumerate(values)]))
    return calls


def moves(path: Path) -> list[tuple[np.ndarray, np.ndarray]]:
    """The program's moves as (start, end) points in mm, arcs (G17) as short chords; the
    first starts at (0, 0, 0)."""
    return [(a, b) for a, b, _ in _moves(path)]


def _moves(path: Path) -> list[tuple[np.ndarray, np.ndarray, bool]]:
    """`moves`, each with whether it feeds (cuts) or is a rapid."""
    at = np.zeros(3)
    out = []
    for name, args in rs274_calls(path):
        if name == "ARC_FEED":
            end = np.array([args[0], args[1], args[5]])
            centre, turn = np.array(args[2:4]), int(args[4])
            a0 = np.arctan2(at[1] - centre[1], at[0] - centre[0])
            a1 = np.arctan2(end[1] - centre[1], end[0] - centre[0])
            sweep = (a1 - a0) % (2 * np.pi) if turn > 0 else -((a0 - a1) % (2 * np.pi))
            radius = np.hypot(*(at[:2] - centre))
            n = max(2, int(abs(sweep) * radius / STEP_MM) + 1)
            t = np.linspace(0.0, 1.0, n)
            pts = np.column_stack([centre[0] + radius * np.cos(a0 + t * sweep), centre[1] + radius * np.sin(a0 + t * sweep),
                                   at[2] + t * (end[2] - at[2])])  # fmt: skip
            out += [(a, b, True) for a, b in zip(pts[:-1], pts[1:])]
        else:
            end = np.array(args[:3])
            out.append((at, end, name == "STRAIGHT_FEED"))
        at = end
    return out


def actual_moves(path: Path, machine: Machine) -> list[np.ndarray]:
    """Where the tool really goes on each of the program's moves, (k,3) points along it: the
    commands mapped through `machine` with the direction each axis travels in (a still axis
    holds its last one, +1 before it first moves).  Where an axis's error travelling − is
    above its error travelling + (lost motion) the axis is a play: it stands on reversal until
    its command takes the play up (and stands whatever an µm command does inside it); where
    it is below (the axis runs ahead) it jumps the new way at once."""
    held = np.ones(3)
    at = None  # where the tool is
    out = []
    for start, end in moves(path):
        held = np.where(end != start, np.sign(end - start), held)
        n = max(2, int(np.linalg.norm(end - start) / STEP_MM) + 2)
        commands = start + np.linspace(0.0, 1.0, n)[:, None] * (end - start)
        plus, minus = machine(commands, np.ones(3)), machine(commands, -np.ones(3))
        actual = machine(commands, held)
        play = minus >= plus
        if at is not None and play.any():
            x = at.copy()
            for k in range(n):  # the play, sample by sample
                x = np.where(play[k], np.minimum(np.maximum(x, plus[k]), minus[k]), actual[k])
                actual[k] = x
        out.append(actual)
        at = actual[-1]
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


def worst_um(original: Path, output: Path, machine: Machine) -> float:
    """µm the tool gets from the original's cutting path (its feed moves) at most while it
    cuts, running `output` on `machine`."""
    return worst_at(original, output, machine)[0]


def holes_um(output: Path, original: Path, machine: Machine) -> np.ndarray:
    """µm each hole (the end of a feed move down Z) lands from the original's, running
    `output` on `machine`."""

    def bottoms(path: Path, segments) -> np.ndarray:
        feeds = [(name, args) for name, args in rs274_calls(path) if name != "ARC_FEED"]
        assert len(feeds) == len(segments)
        return np.array(
            [
                b
                for (name, _), (a, b) in zip(feeds, segments)
                if name == "STRAIGHT_FEED" and b[2] < a[2] - 1e-9
            ]
        )

    got = bottoms(output, [(m[0], m[-1]) for m in actual_moves(output, machine)])
    wanted = bottoms(original, moves(original))
    assert got.shape == wanted.shape
    return np.linalg.norm(got - wanted, axis=1) * 1000


def worst_at(original: Path, output: Path, machine: Machine) -> tuple[float, np.ndarray]:
    """`worst_um`, and the point of the mapped path where it is.  A feed move's path starts
    where the move before it left the tool (a reversal's jump is part of it)."""
    segments = []
    at = None
    for (_, _, feed), actual in zip(_moves(output), actual_moves(output, machine)):
        if feed:
            points = actual if at is None else np.vstack([at[None, :], actual])
            segments += list(zip(points[:-1], points[1:]))
        at = actual[-1]
    points = _samples(segments)
    d = _distance(points, [(a, b) for a, b, feed in _moves(original) if feed])
    return float(d.max() * 1000), points[int(d.argmax())]
