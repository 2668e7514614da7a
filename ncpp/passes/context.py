"""What every pass is given: the error map, tolerances and where to report."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Warnings


class ErrorMap(Protocol):
    """Anything that says where the tool really goes: a `Machine`, or a map
    built straight from one measurement (`ncpp.passes.measured`).  A map may also
    have a `bow_bound` (`ncpp.machine.curvature.BowBound`, or None): with one,
    subdivide_lines leaves unsampled the lines it keeps whole; and a `ripple`
    (`Machine.ripple`): with one, lines and arcs are cut as short as its repeating errors need."""

    def deviation(
        self, P: NDArray, direction: NDArray | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        """(n,3) actual minus nominal tool point, mm, for (n,3) axis positions in mm
        reached with travel signs `direction` (n,3) (None: unknown, mean of both),
        with the (n,3) tool length offsets `tool_offset` in effect, mm (None: none)."""
        ...


def deviation(model: ErrorMap, P: NDArray, direction: NDArray | None, tool_offset: NDArray | None) -> NDArray:
    """The map's deviation, told the tool length offsets when there are any (a map
    that knows no tools, such as a test's, is asked without them)."""
    if tool_offset is None:
        return model.deviation(P, direction)
    return model.deviation(P, direction, tool_offset)


class Corrections:
    """The largest correction compensation has made so far in a run (mm, machine coordinates,
    command minus wanted point): a running maximum, which the verifier's bound follows."""

    def __init__(self) -> None:
        self.largest = 0.0

    def note(self, mm: float) -> None:
        if mm > self.largest:  # (NaN is not: a point that is not a number is refused where it is found)
            self.largest = mm


@dataclass(frozen=True)
class PassContext:
    model: ErrorMap
    tolerance: float = 0.001  # mm: allowed deviation of the compensated path
    arc_radius_tolerance: float = 0.0005  # mm: start/end radius agreement of emitted arcs
    max_correction: float = 0.5  # mm: larger corrections are refused
    rotary_xyz_are_axis_positions: bool = False  # moves that turn A, B or C may be compensated (`rotary.py`)
    kinematics_m_codes: tuple[
        int, ...
    ] = ()  # M codes that switch the control's kinematics: refused (`rotary.py`)
    limits: dict[str, tuple[float, float]] = field(default_factory=dict)  # machine axis travel, mm
    directional: bool = False  # the model has reversal (direction-dependent) errors
    resolution: float = 1e-4  # mm: the output grid of mm programs (every writer writes at least 4 decimals)
    resolution_inch: float = 1e-5  # inch: the same for inch programs (5 decimals)
    min_line_check: float = 1.0  # mm: shorter lines are never subdivided (their error is linear to < 0.01 µm)
    iterations: int = (
        2  # fixed-point steps of the inverse map (`inverse.iterations_for` picks the fewest that suffice)
    )
    warnings: Warnings = field(default_factory=Warnings)
    file: str = "<stdin>"
    # the largest correction made so far, noted by `geometry.compensate`
    corrections: Corrections = field(default_factory=Corrections, compare=False)

    def limit_arrays(self) -> tuple[NDArray, NDArray]:
        lo = np.array([self.limits.get(a, (-np.inf, np.inf))[0] for a in "XYZ"])
        hi = np.array([self.limits.get(a, (-np.inf, np.inf))[1] for a in "XYZ"])
        return lo, hi


def is_directional(model: ErrorMap, limits: dict[str, tuple[float, float]] | None = None) -> bool:
    """Whether the map's errors depend on the direction of travel (probed at a few points)."""
    lo = np.array([max((limits or {}).get(a, (-500.0, 500.0))[0], -500.0) for a in "XYZ"])
    hi = np.array([min((limits or {}).get(a, (-500.0, 500.0))[1], 500.0) for a in "XYZ"])
    P = lo + (hi - lo) * np.random.default_rng(0).random((16, 3))
    try:
        plus = model.deviation(P, np.ones_like(P))
        minus = model.deviation(P, -np.ones_like(P))
    except TypeError:
        return False
    return bool(np.abs(plus - minus).max() > 1e-7)
