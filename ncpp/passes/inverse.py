"""The inverse error map: the command C whose actual position C + E(C) is P."""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from ncpp.passes.context import ErrorMap, deviation

# E is tens of microns and varies by ~1e-4 per mm, so the fixed-point
# iteration C <- P - E(C) gains ~4 digits per step: after two steps the
# command is off by ~E·(dE/dP)² ≈ 1e-9 mm, far below the output's 1e-4.
ITERATIONS = 2


def command_for(
    model: ErrorMap, wanted: NDArray, direction: NDArray | None = None, tool_offset: NDArray | None = None, iterations: int = ITERATIONS
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

