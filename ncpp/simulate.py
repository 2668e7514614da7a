"""The virtual machine: run a program's motion on a modelled machine.

Every segment is sampled finely (lines by length, arcs so that the chord
error stays below `CHORD_MM`), the samples become machine positions, the
machine model says where the tool really goes, and the contour error is the
distance from there to the nominal path.  The nominal path is the program
itself, or — for a compensated program — the original it was made from.
"""

from __future__ import annotations

import math
from collections.abc import Iterable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.motion.segments import PLANE_AXES, Arc, Event, Line

STEP_MM = 0.5  # sample spacing along lines and large arcs
CHORD_MM = 1e-5  # largest chord error of an arc's sampled polyline (0.01 µm)
# Samples of one path at most (~1 GB with their arrays): a move of 10^13 mm asked for 146 TiB
MAX_SAMPLES = 20_000_000


@dataclass(frozen=True)
class SampledPath:
    points: NDArray  # (n,3) machine positions, mm
    feed: NDArray  # (n,) mm/min (0 for rapids)
    line: NDArray  # (n,) source line number
    rapid: NDArray  # (n,) bool
    circles: list  # full circles: (centre (3,), radius mm, plane, slice of points)
    tools: NDArray | None = None  # (n,3) tool length offsets in effect, mm (None: none)


def sample_events(events: Iterable[Event], step_mm: float = STEP_MM, file: str = "<stdin>") -> SampledPath:
    """Sampled machine positions of a program's motion (placed on the machine by the
    work offsets the events were interpreted with: `Context.offset`); more than
    MAX_SAMPLES is an error naming the line (of `file`) where the path passes them."""
    pts: list[NDArray] = []
    feeds, lines, rapids, circles, tools = [], [], [], [], []
    count = 0
    for event in events:
        if type(event) is Line:
            p = _sample_line(event, step_mm, MAX_SAMPLES - count, file)
            rapid = event.rapid
        elif type(event) is Arc:
            p = _sample_arc(event, step_mm, MAX_SAMPLES - count, file)
            rapid = False
            if abs(event.sweep()) >= 2 * math.pi - 1e-9:
                s = event.context.unit_mm
                centre = np.array(event.context.to_machine(event.center))
                circles.append(
                    (centre, event.radius() * s, event.context.plane, slice(count, count + len(p)))
                )
        else:
            continue
        pts.append(p)
        n = len(p)
        feeds.append(np.full(n, 0.0 if rapid else event.feed * event.context.unit_mm))
        lines.append(np.full(n, event.block.line))
        rapids.append(np.full(n, rapid))
        tools.append((event.context.tool_mm, n))
        count += n
    if not pts:
        empty = np.zeros((0, 3))
        return SampledPath(empty, np.zeros(0), np.zeros(0, int), np.zeros(0, bool), [])
    return SampledPath(
        np.vstack(pts),
        np.concatenate(feeds),
        np.concatenate(lines),
        np.concatenate(rapids),
        circles,
        _tools(tools),
    )


def _tools(runs: list[tuple[tuple[float, float, float], int]]) -> NDArray | None:
    """(n,3) tool length offsets of the samples from (offset, count) per event; None if all zero."""
    if all(tool == (0.0, 0.0, 0.0) for tool, _ in runs):
        return None
    return np.repeat(np.array([tool for tool, _ in runs]), [n for _, n in runs], axis=0)


def _to_machine(event: Line | Arc, program: NDArray) -> NDArray:
    return (program + np.asarray(event.context.offset)) * event.context.unit_mm


def _samples(event: Line | Arc, spans: float, least: int, left: int, step_mm: float, file: str) -> int:
    """Samples for the event: `spans` (a length over a step) rounded up, at least `least`,
    when `left` remain of MAX_SAMPLES (a length may overflow to inf: compared first)."""
    if not spans < left:
        raise NcppError(f"the path needs more than {MAX_SAMPLES:,} samples at {step_mm:g} mm spacing (this move alone "
                        f"{spans:,.0f}): run part of the program, or a larger --step", Location(file, event.block.line))  # fmt: skip
    return max(least, math.ceil(spans))


def _sample_line(line: Line, step_mm: float, left: int = MAX_SAMPLES, file: str = "<stdin>") -> NDArray:
    a, b = np.asarray(line.start), np.asarray(line.end)
    length = float(np.linalg.norm(b - a)) * line.context.unit_mm
    n = _samples(line, length / step_mm, 1, left, step_mm, file)
    t = np.linspace(0.0, 1.0, n + 1)[:, None]
    p = a + t * (b - a)
    # the end exactly: a + 1·(b − a) can miss b by a unit in the last place, a
    # "motion" whose sign would set (and reverse) the direction of travel
    p[-1] = b
    return _to_machine(line, p)


def _sample_arc(arc: Arc, step_mm: float, left: int = MAX_SAMPLES, file: str = "<stdin>") -> NDArray:
    i, j, k = PLANE_AXES[arc.context.plane]
    s, e, c = np.asarray(arc.start), np.asarray(arc.end), np.asarray(arc.center)
    r0 = math.hypot(s[i] - c[i], s[j] - c[j])
    r1 = math.hypot(e[i] - c[i], e[j] - c[j])
    sweep = arc.sweep()
    radius_mm = max(r0, 1e-9) * arc.context.unit_mm
    step = min(step_mm, math.sqrt(8 * radius_mm * CHORD_MM))
    n = _samples(arc, abs(sweep) * radius_mm / step, 2, left, step_mm, file)
    t = np.linspace(0.0, 1.0, n + 1)
    a0 = math.atan2(s[j] - c[j], s[i] - c[i])
    angle = a0 + t * sweep
    r = r0 + t * (r1 - r0)
    p = np.empty((n + 1, 3))
    p[:, i] = c[i] + r * np.cos(angle)
    p[:, j] = c[j] + r * np.sin(angle)
    p[:, k] = s[k] + t * (e[k] - s[k])
    # the ends exactly: cos/sin round-off would be a 1e-15 mm "motion" whose sign sets the direction of travel
    p[0], p[-1] = s, e
    return _to_machine(arc, p)


def distance_to_path(points: NDArray, path: NDArray) -> NDArray:
    """Distance (n,) of each point to the polyline `path` (m,3).  The segments next to a point's
    nearest samples give a distance at least the true one; where the nearest samples lie elsewhere
    (a densely sampled arc beside a line sampled every half mm) it can be far too large, so the
    points are measured again against every segment (`_Segments`), the largest first, until no
    other can be larger than the largest so found: the maximum and where it is are exact."""
    from scipy.spatial import cKDTree

    if len(path) < 2:
        return np.linalg.norm(points - path[:1], axis=1) if len(path) else np.full(len(points), np.nan)
    tree = cKDTree(path)
    _, nearest = tree.query(points, k=min(4, len(path)))
    nearest = np.atleast_2d(nearest)
    best = np.full(len(points), np.inf)
    for col in range(nearest.shape[1]):
        for lo in (nearest[:, col] - 1, nearest[:, col]):
            lo = np.clip(lo, 0, len(path) - 2)
            best = np.minimum(best, _to_segments(points, path[lo], path[lo + 1]))
    segments, largest = _Segments(path), -np.inf
    order = np.argsort(-best, kind="stable")
    for at in range(0, len(order), 2048):
        block = order[at : at + 2048]
        if best[block[0]] <= largest:
            break
        best[block] = segments.distance(points[block], best[block])
        largest = max(largest, float(best[block].max()))
    return best


def _to_segments(points: NDArray, a: NDArray, b: NDArray) -> NDArray:
    """(n,) each point's distance to its segment from a to b ((n,3) each)."""
    ab = b - a
    t = np.clip(((points - a) * ab).sum(1) / np.maximum((ab * ab).sum(1), 1e-30), 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


class _Segments:
    """A polyline's segments looked up by their midpoints, in classes of like length: a segment of
    length L nearer to a point than d has its midpoint within d + L/2 of it (and a long segment
    does not widen the search among the short ones)."""

    CLASS = 4.0  # the segments of a class are this much longer at most than its shortest
    NEAR = 8  # segments per point looked at first, four times more where more are that near

    def __init__(self, path: NDArray):
        from scipy.spatial import cKDTree

        self.start, self.end = path[:-1], path[1:]
        lengths = np.linalg.norm(self.end - self.start, axis=1)
        shortest = max(float(lengths.max()) * 1e-9, 1e-12)
        rank = np.floor(np.log(np.maximum(lengths, shortest) / shortest) / np.log(self.CLASS)).astype(np.intp)
        self.classes = []
        for c in np.unique(rank).tolist():
            members = np.flatnonzero(rank == c)
            middle = (self.start[members] + self.end[members]) / 2
            self.classes.append((members, cKDTree(middle), float(lengths[members].max()) / 2))

    def distance(self, points: NDArray, bound: NDArray) -> NDArray:
        """(n,) each point's distance to the nearest segment; `bound` (n,): one known to be no smaller."""
        best = bound.copy()
        for members, tree, half in self.classes:
            rows, k = np.arange(len(points)), self.NEAR
            while rows.size:
                k = min(k, len(members))
                found, index = (a.reshape(len(rows), -1) for a in tree.query(points[rows], k=k))
                for col in range(k):
                    chosen = members[index[:, col]]
                    near = _to_segments(points[rows], self.start[chosen], self.end[chosen])
                    best[rows] = np.minimum(best[rows], near)
                rows = rows[found[:, -1] <= best[rows] + half] if k < len(members) else rows[:0]
                k *= 4
        return best


@dataclass(frozen=True)
class ContourReport:
    max_um: float
    rms_um: float
    worst_line: int  # source line (of the commanded program) where the error is largest
    worst_point: tuple[float, float, float]
    samples: int
    circles: list  # per full circle: dict(centre, radius, circularity_um, trace)
    # per feed sample, in path order: the contour error and the machine position
    error_um: NDArray = field(default_factory=lambda: np.zeros(0), repr=False)
    path_mm: NDArray = field(default_factory=lambda: np.zeros((0, 3)), repr=False)

    def as_dict(self) -> dict:
        return {
            "contour_error_max_um": self.max_um,
            "contour_error_rms_um": self.rms_um,
            "worst_line": self.worst_line,
            "worst_point_mm": list(self.worst_point),
            "samples": self.samples,
            "circles": [{k: v for k, v in c.items() if k != "trace"} for c in self.circles],
        }


def contour_error(
    machine, commanded: SampledPath, nominal: SampledPath, feed_effects: bool = True
) -> ContourReport:
    """Contour error of the commanded path run on `machine` against the nominal path (feed moves only)."""
    cut = ~commanded.rapid
    cmd = commanded.points[cut]
    if len(cmd) == 0:
        return ContourReport(0.0, 0.0, 0, (0.0, 0.0, 0.0), 0, [])
    # run the whole path (rapids too: they set the direction of approach), judge the cuts
    actual = _actual(machine, commanded, feed_effects)[cut]
    nominal_path = nominal.points[~nominal.rapid] if (~nominal.rapid).any() else nominal.points
    error = distance_to_path(actual, nominal_path) * 1000.0
    worst = int(np.argmax(error))
    circles = _circle_traces(machine, commanded, nominal, feed_effects)
    x, y, z = (float(v) for v in cmd[worst])
    return ContourReport(
        float(error.max()),
        float(np.sqrt(np.mean(error**2))),
        int(commanded.line[cut][worst]),
        (x, y, z),
        int(len(cmd)),
        circles,
        error,
        cmd,
    )


def _actual(machine, commanded: SampledPath, feed_effects: bool) -> NDArray:
    """Where the tool goes: geometry with the direction of travel along the path, plus effects."""
    cmd, feed = commanded.points, commanded.feed
    if len(cmd) < 2:
        return cmd + machine.deviation(cmd, None, commanded.tools)
    from ncpp.machine import Trajectory

    speed = float(np.median(feed[feed > 0])) if (feed > 0).any() else 1000.0
    machine = machine if feed_effects else machine.replace(effects=())
    return machine.simulate(Trajectory(cmd, speed), commanded.tools)


def _circle_traces(machine, commanded: SampledPath, nominal: SampledPath, feed_effects: bool) -> list:
    """For each full circle of the nominal program: the simulated ball-bar trace and circularity."""
    out = []
    for centre, radius, plane, _ in nominal.circles:
        i, j, _ = PLANE_AXES[plane]
        cut = ~commanded.rapid
        actual = _actual(machine, commanded, feed_effects)[cut]
        rel = actual - centre
        r = np.hypot(rel[:, i], rel[:, j])
        near = 0.05  # mm: the tool within this of the nominal circle is on it (errors are µm)
        on_circle = (np.abs(r - radius) < near) & (np.abs(rel[:, 3 - i - j]) < near)
        if on_circle.sum() < 8:
            continue
        angle = np.degrees(np.arctan2(rel[on_circle, j], rel[on_circle, i])) % 360.0
        dr = (r[on_circle] - radius) * 1000.0
        out.append(
            {
                "centre_mm": [float(v) for v in centre],
                "radius_mm": float(radius),
                "plane": {17: "XY", 18: "ZX", 19: "YZ"}[plane],
                "circularity_um": float(dr.max() - dr.min()),
                "trace": (angle, dr),
            }
        )
    return out
