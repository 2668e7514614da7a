"""Helpers for the compensation tests: place a program in a machine's travel and compensate it."""

from __future__ import annotations

import io
import os

import numpy as np

from ncpp.errors import Warnings
from ncpp.motion import interpret
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from ncpp.program.parser import parse_stream
from ncpp.simulate import SampledPath

QUIET = Warnings(stream=open(os.devnull, "w"))
MARGIN_MM = 1.0


def events_of(data: bytes, name: str = "<test>", offsets: WorkOffsets | None = None) -> list:
    return list(interpret(parse_stream(io.BytesIO(data), name), file=name, warnings=QUIET, offsets=offsets))


def placement(path: SampledPath, limits) -> np.ndarray | None:
    """Work offset (mm) centring the program's extent in the travel; None if it does not fit."""
    if len(path.points) == 0:
        return None
    lo_p, hi_p = path.points.min(axis=0), path.points.max(axis=0)
    lo_m = np.array([limits[a][0] for a in "XYZ"])
    hi_m = np.array([limits[a][1] for a in "XYZ"])
    if np.any(hi_p - lo_p > hi_m - lo_m - 2 * MARGIN_MM):
        return None
    return np.round((lo_m + hi_m) / 2 - (lo_p + hi_p) / 2, 3)


def compensate(
    data: bytes, model, offset, tolerance: float = 0.001, name: str = "<test>", warnings: Warnings = QUIET
) -> bytes:
    """`data` compensated for `model`, the program placed by `offset`: G54's zero, or WorkOffsets."""
    rotary = getattr(model, "rotary_xyz_are_axis_positions", False)
    source = ErrorSource(model, "model", "0" * 16, model.max_correction_mm, dict(model.limits), rotary)
    offsets = offset if isinstance(offset, WorkOffsets) else WorkOffsets.at(offset)
    out = io.BytesIO()
    process(
        io.BytesIO(data),
        out,
        file=name,
        source=source,
        tolerance=tolerance,
        warnings=warnings,
        offsets=offsets,
    )
    return out.getvalue()


def repeatable_machine(path):
    """A sample machine's repeatable geometric errors, exactly: no thermal or servo effects,
    its reversal tables replaced by their mean (benchmarks/accuracy.py says why)."""
    from ncpp.machine import load_machine
    from ncpp.machine.components import Table

    true = load_machine(path).replace(effects=())
    comps = {}
    for name, c in true.components.items():
        if isinstance(c, Table) and c.values_minus is not None:
            c = Table(
                c.positions, (np.asarray(c.values) + np.asarray(c.values_minus)) / 2, None, c.interpolation
            )
        comps[name] = c
    return true.replace(components=comps)


def program_lines(text: str) -> list[str]:
    """The output's lines but its header's placement lines (the comments after its first line,
    `ncpp.header`): tests that count lines count the program's."""
    from ncpp.pipeline import HEADER_TAG

    def placement(line: str) -> bool:
        said = line.lstrip("(; ").rstrip(")")
        return said.startswith("ncpp ") and not said.startswith(HEADER_TAG)

    return [line for line in text.splitlines() if not placement(line)]
