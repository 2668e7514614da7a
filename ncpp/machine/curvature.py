"""How far a machine's error can bow away from a straight line between two points.

`subdivide_lines` samples the error along each line to see whether it bows from the
straight interpolation of its end errors by more than the tolerance allows.  Where the
error is smooth, the bow of a segment of length L is at most L²/8 · max‖E''‖ along it
(E'' the second derivative along the segment), and on a machine whose components are all
tables with smooth interpolation, that derivative is bounded by the tables' own.  In the
first-order model (eqs. 28–30 of M. Rahman, *Modeling and measurement of multi-axis machine
tools to improve positioning accuracy in a software way*, University of Oulu, 2004), axis K
adds δ_K(P_K) + ε_K(P_K) × L_K(P) (squareness adds terms linear in P), so along a unit
direction u

    d²/ds² [δ_K + ε_K × L_K] = u_K² (δ_K'' + ε_K'' × L_K) + 2 u_K ε_K' × dL_K/ds,

and with |u_K| ≤ 1, ‖dL_K/ds‖ ≤ 1:  ‖E''‖ ≤ Σ_K Σ|δ_K''| + Σ|ε_K''| · max‖L_K‖ + 2 Σ|ε_K'|.
The maxima are taken over the table intervals the segment spans; its Abbe arm L_K is
affine along it, so the larger of its ends' bounds it.  The exact chain differs from the
first-order model by terms smaller by the angles (at most MAX_ANGLE here): MARGIN covers
them.  A line whose bound already keeps it whole needs no samples: the samples, which
cannot find more bow than there is, would keep it whole too.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ncpp.machine.chain import AXES, Chain, abbe_offset, norm3
from ncpp.machine.components import COMPONENTS, StackedTables, Table

MARGIN = 1.25  # over the first-order bound: the exact chain's terms of second order in the angles
MAX_ANGLE = 1e-3  # rad: the angles' sum at most, for MARGIN to hold
MAX_INTERVALS = 256  # per axis: a table of the maxima over every run of intervals is kept


class BowBound:
    """Bounds of ‖E''‖ along segments of a machine whose errors are smooth tables (`of`)."""

    def __init__(self, machine, axes: dict[str, _AxisBound]):
        self.chain = Chain(machine.chain)
        self.tool = np.asarray(machine.tool, dtype=float)
        self.references = {a: np.asarray(r, dtype=float) for a, r in machine.references.items()}
        self.axes = axes

    @classmethod
    def of(cls, machine) -> BowBound | None:
        """The bound, or None where the error may not be smooth: a component other than a
        table, a table interpolated linearly (kinks), an effect that depends on position,
        or angles too large for MARGIN."""
        if any(effect.static for effect in machine.effects):
            return None
        if any(
            not isinstance(c, Table) or (c.interpolation == "linear" and len(c.positions) > 2)
            for c in machine.components.values()
        ):
            return None
        axes: dict[str, _AxisBound] = {}
        angles = 0.0
        for axis, (stacked, rows, _) in machine._evaluators.items():
            if stacked is None:
                continue
            mine = [c for n, c in machine.components.items() if COMPONENTS[n].axis == axis]
            bound = _AxisBound.of(stacked, rows, mine)
            if bound is None:
                return None
            axes[axis] = bound
            angles += bound.angle
        return cls(machine, axes) if angles <= MAX_ANGLE else None

    def __call__(self, start: NDArray, end: NDArray, tools: NDArray | None = None) -> NDArray:
        """(n,) bounds of ‖E''‖ (1/mm) along the segments from `start` to `end` ((n,3) axis
        positions, mm) with the (n,3) tool length offsets `tools` (mm) in effect; inf for a
        segment that leaves a table's range (outside it the table holds its end value: a kink)."""
        tool = self.tool if tools is None else self.tool - tools
        total = np.zeros(len(start))
        for axis, bound in self.axes.items():
            k = AXES.index(axis)
            reference = self.references[axis]
            lever = np.maximum(
                norm3(abbe_offset(self.chain, axis, start, tool, reference)),
                norm3(abbe_offset(self.chain, axis, end, tool, reference)),
            )
            total += bound(np.minimum(start[:, k], end[:, k]), np.maximum(start[:, k], end[:, k]), lever)
        return MARGIN * total


class _AxisBound:
    """One axis's tables' derivatives, as maxima over every run of their intervals."""

    def __init__(
        self,
        inner: NDArray,
        low: float,
        high: float,
        delta2: NDArray,
        eps2: NDArray,
        eps1: NDArray,
        angle: float,
    ):
        self.inner, self.low, self.high = inner, low, high
        self.delta2, self.eps2, self.eps1 = (
            delta2,
            eps2,
            eps1,
        )  # (m, m): [i, j] the maximum over intervals i..j
        self.angle = angle  # rad: the largest |ε| of each of its three angles, summed

    @classmethod
    def of(cls, stacked: StackedTables, rows: list[int], tables: list[Table]) -> _AxisBound | None:
        """From the axis's `tables` stacked (`rows`: each one's row of δx δy δz εx εy εz)."""
        grid = stacked.grid
        if len(grid) - 1 > MAX_INTERVALS:
            return None
        h = np.diff(grid)
        c0, c1, c2, c3 = stacked.coefficients  # (curves, intervals), highest power first in (p − x_i)
        second = np.maximum(np.abs(2 * c1), np.abs(6 * c0 * h + 2 * c1))  # f'' is linear on an interval
        first = np.maximum(np.abs(c2), np.abs((3 * c0 * h + 2 * c1) * h + c2))
        cubic = c0 != 0
        safe = np.where(cubic, c0, 1.0)
        vertex = -c1 / (3 * safe)  # where f' has its extreme, c2 − c1²/3c0, on a cubic piece
        inside = cubic & (vertex > 0) & (vertex < h)
        first = np.where(inside, np.maximum(first, np.abs(c2 - c1 * c1 / (3 * safe))), first)
        ends = ((c0 * h + c1) * h + c2) * h + c3
        delta2, eps2, eps1 = np.zeros(len(h)), np.zeros(len(h)), np.zeros(len(h))
        angle = 0.0
        for (plus, minus), row in zip(stacked.columns, rows):
            curves = [plus] if minus is None else [plus, minus]  # (the mean of the two: no more)
            if row < 3:
                delta2 += second[curves].max(axis=0)
            else:
                eps2 += second[curves].max(axis=0)
                eps1 += first[curves].max(axis=0)
                # the largest angle: at a breakpoint (smooth tables do not overshoot their values:
                # PCHIP keeps each interval monotone), each interval's start or end
                angle += float(max(np.abs(c3[curves]).max(), np.abs(ends[curves]).max()))
        low = max(
            t.positions[0] for t in tables
        )  # where every table has values: outside one, it holds its end (a kink)
        high = min(t.positions[-1] for t in tables)
        return cls(
            grid[1:-1].copy(), low, high, _run_maxima(delta2), _run_maxima(eps2), _run_maxima(eps1), angle
        )

    def __call__(self, low: NDArray, high: NDArray, lever: NDArray) -> NDArray:
        """(n,) the axis's bound for segments whose positions on it span [low, high], with Abbe arms up to `lever`."""
        i, j = self.inner.searchsorted(low, side="right"), self.inner.searchsorted(high, side="right")
        bound = self.delta2[i, j] + self.eps2[i, j] * lever + 2 * self.eps1[i, j]
        return np.where((low >= self.low) & (high <= self.high), bound, np.inf)


def _run_maxima(values: NDArray) -> NDArray:
    """(m, m): [i, j] the maximum of values[i..j] (j ≥ i)."""
    out = np.zeros((len(values), len(values)))
    for i in range(len(values)):
        out[i, i:] = np.maximum.accumulate(values[i:])
    return out


def ripple(machine) -> NDArray:
    """(3,) per axis X Y Z: the largest second derivative (1/mm) of the machine's `cyclic` effects
    along it, Σ um·(2π/period_mm)².  A screw-lead error repeats every few mm, shorter than the
    stretches a line's or an arc's samples are apart: a piece of length ℓ along axis k bows from its
    chord by at most ripple[k]·ℓ²/8 from them."""
    from ncpp.machine.effects import Cyclic

    out = np.zeros(3)
    for effect in machine.effects:
        if isinstance(effect, Cyclic):
            out[AXES.index(effect.axis)] += abs(effect.um) * 1e-3 * (2 * np.pi / effect.period_mm) ** 2
    return out


def ripple_bow(span: NDArray, ripple: NDArray) -> NDArray:
    """(n,) mm: how far pieces spanning `span` (n,3) mm of the axes bow at most from their chords
    by the errors that repeat along them (`ripple`, (3,) 1/mm)."""
    return span**2 @ ripple / 8
