"""What every controller table is made from: an axis error sampled on a grid.

`axis_error(machine, "X")` evaluates the positioning error of X for travel in
+ and in − direction (the same curve twice when the table is not direction
dependent), in mm, actual minus nominal, on a grid that a writer asks for: its
component EXX plus the machine file's `[[effects]]` that are a positioning
error of X by its own position (`scale`, `cyclic`: static, as compensation
cancels them), either of them alone where the file gives only one.
`uniform_grid` picks that grid within a controller's limits and says in
`notes` what it had to change (more spacing, fewer points); every writer
copies the notes into its file as comments and the CLI prints them.

The component is the error motion measured at the axis's reference point
(see ncpp.machine.chain); Abbe offsets to a particular tool point are not
included — a controller's axis table cannot carry them either.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import NcppError
from ncpp.machine import Machine, Polynomial, Table
from ncpp.machine.effects import Effect
from ncpp.machine.trajectory import Trajectory

AXES = "XYZ"
# The effects that are an axis's positioning error by its own position alone (machine-file.md,
# `[[effects]]`): a positioning table carries them.  Backlash and reversal spikes depend on the
# travel's history, lateral play, straightness and squareness move other axes, an angular error
# moves the tool through an Abbe arm no axis table carries.
ALONG_AXIS = ("scale", "cyclic")


@dataclass(frozen=True)
class AxisError:
    """An error component of one axis, ready to be sampled (mm, actual − nominal)."""

    axis: str
    name: str  # ISO name, e.g. EXX or EYX, with the effects added to it ("EXX + scale")
    component: Table | Polynomial | None  # None: the effects alone
    lo: float  # range the table should cover, mm
    hi: float
    effects: tuple[Effect, ...] = ()  # of kinds ALONG_AXIS, on this axis

    @property
    def directional(self) -> bool:
        return self.component is not None and bool(self.component.directional)

    def forward(self, x: NDArray) -> NDArray:
        return self._error(x, 1.0)

    def reverse(self, x: NDArray) -> NDArray:
        return self._error(x, -1.0)

    def _error(self, x: NDArray, direction: float) -> NDArray:
        x = np.asarray(x, dtype=float)
        total = np.zeros_like(x)
        if self.component is not None:
            total = total + np.asarray(self.component(x, np.full_like(x, direction)), dtype=float)
        if self.effects and x.size:
            points = np.zeros((max(x.size, 2), 3))  # (a trajectory has two points at least)
            points[: x.size, AXES.index(self.axis)] = x.ravel()
            along = Trajectory(points, 1000.0)  # (static effects: the feed does not count)
            for effect in self.effects:
                total = total + effect.apply(along)[: x.size, AXES.index(self.axis)].reshape(x.shape)
        return total

    def mean(self, x: NDArray) -> NDArray:
        return 0.5 * (self.forward(x) + self.reverse(x))

    def own_positions(self) -> NDArray | None:
        """The table's own breakpoints inside the range (None for a polynomial)."""
        if not isinstance(self.component, Table):
            return None
        pos = np.asarray(self.component.positions)
        return pos[(pos >= self.lo - 1e-9) & (pos <= self.hi + 1e-9)]


def axis_error(machine: Machine, axis: str, name: str | None = None) -> AxisError:
    """The component `name` (default the positioning error E<axis><axis>) of `axis`."""
    axis = axis.upper()
    if axis not in AXES:
        raise NcppError(f"unknown axis {axis!r}: use X, Y or Z")
    positioning = f"E{axis}{axis}"
    name = name or positioning
    comp = machine.components.get(name)
    effects = tuple(e for e in machine.effects if e.kind in ALONG_AXIS and getattr(e, "axis", "") == axis)
    effects = effects if name == positioning else ()
    if comp is None and not effects:
        also = " nor a scale or cyclic effect" if name == positioning else ""
        raise NcppError(f"the machine file has no {name} component{also} for axis {axis}")
    lo, hi = machine.limits[axis]
    # the effects hold over the whole travel, where a table past its ends holds its end values
    whole_travel = bool(effects) and math.isfinite(lo) and math.isfinite(hi)
    if isinstance(comp, Table) and not whole_travel:
        # The table is a measurement; outside it the model only holds end values.
        lo = max(lo, comp.positions[0]) if math.isfinite(lo) else comp.positions[0]
        hi = min(hi, comp.positions[-1]) if math.isfinite(hi) else comp.positions[-1]
    elif isinstance(comp, Polynomial) and comp.limits is not None:
        lo = comp.limits[0] if not math.isfinite(lo) else lo
        hi = comp.limits[1] if not math.isfinite(hi) else hi
    if not (math.isfinite(lo) and math.isfinite(hi) and hi > lo):
        raise NcppError(
            f"{name}: give [limits] {axis} in the machine file; the travel to tabulate is unknown"
        )
    said = " + ".join(([name] if comp is not None else []) + [f"{e.kind} effect" for e in effects])
    return AxisError(axis, said, comp, float(lo), float(hi), effects)


@dataclass
class Grid:
    positions: NDArray
    spacing: float | None  # None: the table's own (non-uniform) breakpoints
    notes: list[str] = field(default_factory=list)


def reference_on_travel(error: AxisError, reference: float, notes: list[str]) -> float:
    """The reference position, moved onto the table's range with a note when it lies outside."""
    if error.lo <= reference <= error.hi:
        return reference
    clipped = min(max(reference, error.lo), error.hi)
    notes.append(f"reference position {reference:g} mm lies outside the table range; {clipped:g} mm used")
    return clipped


def uniform_grid(
    lo: float,
    hi: float,
    *,
    max_points: int,
    spacing: float | None = None,
    quantum: float = 0.001,
    what: str = "table",
) -> Grid:
    """Equidistant points from `lo` covering [lo, hi] with at most `max_points`.

    `spacing` (mm) is the user's wish; without it the finest spacing the
    controller allows is used.  Spacing is rounded up to `quantum` so that the
    positions print exactly; the last point may lie beyond `hi` (a table must
    cover the travel; the model holds its end value there)."""
    notes: list[str] = []
    span = hi - lo
    finest = span / (max_points - 1)
    if spacing is None:
        step = finest
    else:
        if spacing <= 0:
            raise NcppError("--spacing must be positive")
        step = spacing
        if spacing < finest:
            notes.append(
                f"{what}: spacing {spacing:g} mm needs {math.ceil(span / spacing) + 1} points, "
                f"more than the {max_points} allowed; spacing widened"
            )
            step = finest
    step = math.ceil(step / quantum - 1e-9) * quantum
    n = int(math.ceil(span / step - 1e-9)) + 1
    while n > max_points:  # rounding the step up can only help, but be sure
        step += quantum
        n = int(math.ceil(span / step - 1e-9)) + 1
    positions = lo + step * np.arange(n)
    if spacing is not None and not math.isclose(step, spacing, rel_tol=1e-9) and not notes:
        notes.append(f"{what}: spacing {spacing:g} mm rounded to {step:g} mm")
    return Grid(positions, step, notes)


def interpolation_residual(error: AxisError, positions: NDArray, values_of) -> float:
    """Worst |model − linear interpolation of the table| over the range, mm:
    what a controller that interpolates linearly misses between its points."""
    fine = np.linspace(positions[0], positions[-1], max(2001, 8 * len(positions)))
    return float(np.max(np.abs(values_of(fine) - np.interp(fine, positions, values_of(positions)))))


def quantize(values: NDArray, step: float) -> NDArray:
    """Round to the controller's resolution (`step` mm)."""
    return np.round(np.asarray(values) / step) * step


def comment_block(lines: list[str], prefix: str) -> str:
    return "".join(f"{prefix}{line}".rstrip() + "\n" for line in lines)
