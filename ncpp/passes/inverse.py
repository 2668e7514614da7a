"""The inverse error map: the command C whose actual position C + E(C) is P."""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from ncpp.passes.context import ErrorMap, deviation

# The fixed-point iteration C <- P - E(C) gains a factor |dE/dP| (~1e-4) per step:
# one step leaves the command off by ~|E|·|dE/dP|, nanometres on most machines, two
# by ~1e-4 of that.  `iterations_for` picks the count per map; this is the count
# when the travel is unknown (measured maps), safe for any realistic machine.
ITERATIONS = 2
MAX_ITERATIONS = 4
RESIDUAL_SAMPLES = 4096  # points over the travel where the residual is estimated
RESIDUAL_SAFETY = 2.0  # the sampled worst residual times this must fit the budget


def command_for(
    model: ErrorMap,
    wanted: NDArray,
    direction: NDArray | None = None,
    tool_offset: NDArray | None = None,
    iterations: int = ITERATIONS,
) -> NDArray:
    """(n,3) commands, mm, that put the tool at the (n,3) wanted positions,
    approached with the (n,3) travel signs `direction` (None: unknown), with the
    (n,3) tool length offsets `tool_offset` in effect (None: none)."""
    wanted = np.asarray(wanted, dtype=float)
    if len(wanted) == 0:
        return wanted.copy()
    command = wanted - deviation(model, wanted, direction, tool_offset)
    for _ in range(iterations - 1):
        command = wanted - deviation(model, command, direction, tool_offset)
    return command


def iterations_for(model: ErrorMap, limits: dict[str, tuple[float, float]], budget: float) -> int:
    """The fewest steps of `command_for` whose residual |C + E(C) - P| stays within
    `budget` mm over the axes' travel `limits` (mm), estimated on random points
    reached from random directions (a safety factor over the worst one sampled).

    Each step costs one evaluation of the map at every point compensation makes,
    which is most of compensation's numeric work: a step that only moves the command
    by picometres, far below the output's last digit, is not taken."""
    travel = [limits.get(axis, (-math.inf, math.inf)) for axis in "XYZ"]
    if not all(math.isfinite(lo) and math.isfinite(hi) for lo, hi in travel):
        return ITERATIONS  # nowhere to look: the count that suffices for any realistic map
    rng = np.random.default_rng(0)
    lo, hi = np.array(travel).T
    wanted = lo + (hi - lo) * rng.random((RESIDUAL_SAMPLES, 3))
    direction = rng.choice([-1.0, 1.0], size=wanted.shape)
    error = deviation(model, wanted, direction, None)
    for steps in range(1, MAX_ITERATIONS + 1):
        command = wanted - error  # `command_for` after `steps` steps
        error = deviation(model, command, direction, None)  # its residual's, and the next step's
        if RESIDUAL_SAFETY * np.abs(command + error - wanted).max() <= budget:
            return steps
    return MAX_ITERATIONS
