"""`Trajectory`: a time-ordered sampled command path, the input of simulations.

Positions are command axis positions (n,3) mm, fed at `feed_mm_min`; time
in s is given or follows from path length and feed.  Constructors sample a
circle (ball bar, circular test) and a straight line (laser runs); `then`
joins paths end to end in time.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np
from numpy.typing import ArrayLike, NDArray

PLANES = {"XY": (0, 1, 2), "YZ": (1, 2, 0), "ZX": (2, 0, 1)}  # first, second, normal axis index
# A step this small is floating-point noise (a position converted between frames and units),
# not motion: it must not reverse an axis (a reversal error is µm) in the simulation.
NOISE_MM = 1e-9


@dataclass(frozen=True, eq=False)
class Trajectory:
    positions: NDArray  # (n,3) mm
    feed_mm_min: float
    t: NDArray | None = None  # (n,) s, non-decreasing

    def __post_init__(self) -> None:
        pos = np.array(self.positions, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 3 or len(pos) < 2:
            raise ValueError("a trajectory needs positions of shape (n, 3), n >= 2")
        if not self.feed_mm_min > 0:
            raise ValueError("feed_mm_min must be positive")
        pos.setflags(write=False)
        object.__setattr__(self, "positions", pos)
        if self.t is not None:
            t = np.array(self.t, dtype=float)
            if t.shape != (len(pos),) or np.any(np.diff(t) < 0):
                raise ValueError("t must be one non-decreasing time per position")
            t.setflags(write=False)
            object.__setattr__(self, "t", t)

    def __len__(self) -> int:
        return len(self.positions)

    # ---------------------------------------------------------- constructors
    @classmethod
    def line(cls, start: ArrayLike, end: ArrayLike, feed_mm_min: float, step_mm: float = 1.0) -> Trajectory:
        """Straight move from start to end, sampled about every step_mm."""
        a, b = np.asarray(start, dtype=float), np.asarray(end, dtype=float)
        n = max(2, int(np.ceil(np.linalg.norm(b - a) / step_mm)) + 1)
        s = np.linspace(0.0, 1.0, n)[:, None]
        return cls(a + s * (b - a), feed_mm_min)

    @classmethod
    def circle(
        cls,
        plane: str,
        centre: ArrayLike,
        radius: float,
        direction: str = "CCW",
        feed_mm_min: float = 1000.0,
        start_deg: float = 0.0,
        sweep_deg: float = 360.0,
        overshoot_deg: float = 0.0,
        step_deg: float = 0.25,
    ) -> Trajectory:
        """Circle in plane XY | YZ | ZX about `centre` (command coordinates).

        Angles follow the ball-bar file: from the plane's first axis towards
        its second (XY: +X→+Y, YZ: +Y→+Z, ZX: +Z→+X).  CCW runs with
        increasing angle from start_deg through sweep_deg; overshoot_deg adds
        arc before the start and after the end (feed-in/feed-out)."""
        if plane not in PLANES:
            raise ValueError(f"plane must be one of {', '.join(PLANES)}, not {plane!r}")
        sign = {"CCW": 1.0, "CW": -1.0}.get(direction.upper())
        if sign is None:
            raise ValueError(f"direction must be CW or CCW, not {direction!r}")
        if not radius > 0:
            raise ValueError("radius must be positive")
        total = sweep_deg + 2 * overshoot_deg
        n = max(3, int(np.ceil(total / step_deg)) + 1)
        ang = np.deg2rad(start_deg + sign * np.linspace(-overshoot_deg, sweep_deg + overshoot_deg, n))
        first, second, _ = PLANES[plane]
        pos = np.tile(np.asarray(centre, dtype=float), (n, 1))
        pos[:, first] += radius * np.cos(ang)
        pos[:, second] += radius * np.sin(ang)
        return cls(pos, feed_mm_min)

    def then(self, other: Trajectory) -> Trajectory:
        """This path followed by another (time continues; the feed of the
        first is kept as the nominal feed, each part's own timing is kept)."""
        t2 = other.time - other.time[0] + self.time[-1]
        if np.allclose(self.positions[-1], other.positions[0]):
            pos, t = np.vstack([self.positions, other.positions[1:]]), np.concatenate([self.time, t2[1:]])
        else:
            gap = np.linalg.norm(other.positions[0] - self.positions[-1]) / (other.feed_mm_min / 60.0)
            pos, t = np.vstack([self.positions, other.positions]), np.concatenate([self.time, t2 + gap])
        return Trajectory(pos, self.feed_mm_min, t)

    # ------------------------------------------------------------ kinematics
    @cached_property
    def arc_length(self) -> NDArray:
        """Cumulative path length (n,) mm."""
        steps = np.linalg.norm(np.diff(self.positions, axis=0), axis=1)
        return np.concatenate([[0.0], np.cumsum(steps)])

    @cached_property
    def time(self) -> NDArray:
        """Time (n,) s: given, or path length over feed."""
        if self.t is not None:
            return self.t
        return self.arc_length / (self.feed_mm_min / 60.0)

    @cached_property
    def velocity(self) -> NDArray:
        """Axis velocities (n,3) mm/s: mean of the segments on either side."""
        dp = np.diff(self.positions, axis=0)
        dt = np.diff(self.time)[:, None]
        seg = np.divide(dp, dt, out=np.zeros_like(dp), where=dt > 0)
        v = np.empty_like(self.positions)
        v[0], v[-1] = seg[0], seg[-1]
        v[1:-1] = 0.5 * (seg[:-1] + seg[1:])
        return v

    def directions(self) -> NDArray:
        """Direction of travel per axis (n,3) in {−1, 0, +1}: the sign of the
        last motion that axis made (held through stops); a sample gets the
        direction it was approached in, the first sample that of the first move."""
        delta = np.diff(self.positions, axis=0)
        step = np.sign(np.where(np.abs(delta) > NOISE_MM, delta, 0.0))
        out = np.zeros_like(self.positions)
        for i in range(3):
            s = step[:, i]
            moving = np.flatnonzero(s)
            if len(moving) == 0:
                continue
            # index of the last non-zero step at or before each step
            idx = np.maximum.accumulate(np.where(s != 0, np.arange(len(s)), -1))
            held = np.where(idx >= 0, s[np.maximum(idx, 0)], s[moving[0]])
            out[1:, i] = held
            out[0, i] = s[moving[0]]
        return out

    def reversals(self, axis: int) -> NDArray:
        """Sample indices where `axis` (0, 1, 2) starts moving the other way:
        the turning point (last sample of the old direction)."""
        d = self.directions()[:, axis]
        return np.flatnonzero(d[1:] * d[:-1] < 0)
