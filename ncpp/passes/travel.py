"""The direction each axis really travels in, as the machine will see it.

With direction-dependent (reversal) error tables the error of a command
depends on the sign of the axis's last motion.  The machine takes that sign
from the commands it is given, compensation included: µm moves that the
compensation adds on a nominally still axis count, a move smaller than the
output resolution is no move at all, and an axis that stands keeps the
direction of its last motion.  These helpers predict that, vectorised over a
chunk of segments, and carry the held direction from chunk to chunk.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from ncpp.passes.context import PassContext


@dataclass
class Travel:
    """What the machine has done so far: held direction per axis (0 until it
    has moved) and the last command, machine mm (None before the first)."""

    held: NDArray = field(default_factory=lambda: np.zeros(3))
    last: NDArray | None = None

    def copy(self) -> Travel:
        return Travel(self.held.copy(), None if self.last is None else self.last.copy())


def grid(ctx: PassContext, scales: NDArray) -> NDArray:
    """(n,) output resolution per segment in its program units."""
    return np.where(scales == 1.0, ctx.resolution, ctx.resolution_inch)


def quantize(points: NDArray, step: NDArray) -> NDArray:
    """Program points (n,3) or (n,m,3) on the output grid `step` (n,): what the
    written program will say, so that directions predicted from them are exact."""
    s = step.reshape((-1,) + (1,) * (points.ndim - 1))
    return np.round(points / s) * s


def steps(motion: NDArray, threshold: NDArray) -> NDArray:
    """(n,3) signs of motions (machine mm) larger than `threshold` (n,) mm, else 0."""
    return np.where(np.abs(motion) > threshold[:, None], np.sign(motion), 0.0)


def hold(step: NDArray, held: NDArray) -> NDArray:
    """Directions (n,3): each row's step where it moves, else the last nonzero
    step before it (`held` from before the first row)."""
    n = len(step)
    if n == 0:
        return step
    rows = np.arange(n)[:, None]
    last = np.maximum.accumulate(np.where(step != 0, rows, -1), axis=0)
    filled = np.take_along_axis(step, np.maximum(last, 0), axis=0)
    return np.where(last >= 0, filled, held[None, :])
