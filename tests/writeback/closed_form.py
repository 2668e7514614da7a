"""The closed-form judge of the --expand tests of Klartext and Sinumerik: the test's own reading of
where each block of the written program ends (`end_points`), mapped through the machine whose errors
are linear in position (`AFFINE`, `machine`) and measured against the points the test computes
(`landed`)."""

from __future__ import annotations

import re
from collections.abc import Callable

import numpy as np

from tests.compensation.test_dialect_cutter_comp import machine
from tests.writeback.conftest import misses

# the corners of a square 40 x 40 at the program zero, each run of the tests' loops draws
SQUARE = [(0, 0), (40, 0), (40, 40), (0, 40), (0, 0)]


def squares(runs: int) -> list[tuple[float, float, float]]:
    """The corners of `runs` squares, the first at Z-1, each 1 mm deeper."""
    return [(x, y, -float(level)) for level in range(1, runs + 1) for x, y in SQUARE]


def end_points(text: str, word: re.Pattern[str], moves: Callable[[str], bool]) -> np.ndarray:
    """Where each block of a written program (absolute words) that `moves` ends, in order: `word`
    finds its (axis, number) pairs, X Y Z; what follows a `;` is a comment."""
    here = [0.0, 0.0, 0.0]
    ends = []
    for line in text.splitlines():
        code = line.split(";")[0]
        if not moves(code):
            continue
        for axis, value in word.findall(code):
            here["XYZ".index(axis)] = float(value)
        ends.append(list(here))
    return np.array(ends)


def landed(ends: np.ndarray, wanted: list[tuple[float, ...]]) -> np.ndarray:
    """For each programmed point, how far (mm) the nearest of the written program's end points
    `ends` lands from it on AFFINE's machine."""
    return misses(machine(ends), wanted)
