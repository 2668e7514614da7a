"""HEIDENHAIN nonlinear axis error compensation table (*.COM).

Format after the HEIDENHAIN technical manuals (MANUALplus 620 / TNC 6x0,
"Nonlinear axis error compensation"; TNC 407/426: 256 entries per table at
most): a HEIDENHAIN table file `BEGIN <name>.COM MM`, a header line of
columns, one line per compensation point, `[END]`.  Columns: NR, AXISPOS
(compensation point, mm from the machine datum), the column named after the
compensated axis (compensation value, mm) and BACKLASH ("the compensation
values measured in the negative direction of traverse").  The table is
assigned to the axis in a *.CMA file (`X = F(X)`).

Values are the measured error e = actual − nominal, as the manuals'
examples enter the error curve.  Verify the sign on the machine with one
point before use: the control's sign convention was not checkable here.
HEIDENHAIN tables have no comment syntax; the notes follow `[END]`, which
ends the table for the control.
"""

from __future__ import annotations

import numpy as np

from ncpp.export.common import AxisError, interpolation_residual, uniform_grid

MAX_POINTS = 256
DECIMALS = 5  # 0.01 um


def write_heidenhain_com(error: AxisError, *, spacing: float | None = None, name: str | None = None) -> tuple[str, list[str]]:
    grid = uniform_grid(error.lo, error.hi, max_points=MAX_POINTS, spacing=spacing, what="HEIDENHAIN")
    x = grid.positions
    fwd, rev = error.forward(x), error.reverse(x)
    name = name or f"{error.axis}_{error.name}.COM"
    col = error.axis
    rows = [f"BEGIN {name} MM", f"{'NR':<6}{'AXISPOS':>14}{col:>14}{'BACKLASH':>14}"]
    rows += [f"{i:<6}{_v(p):>14}{_v(f):>14}{_v(r):>14}" for i, (p, f, r) in enumerate(zip(x, fwd, rev))]
    rows.append("[END]")
    residual = max(interpolation_residual(error, x, error.forward), interpolation_residual(error, x, error.reverse))
    notes = [
        f"ncpp export-table: {error.name} of axis {error.axis}, {len(x)} points every {grid.spacing:g} mm",
        f"assign in the .CMA file: column {col} = {name}",
        f"largest error between points: {residual * 1000:.3f} um",
        *grid.notes,
    ]
    return "\n".join(rows + [f"* {n}" for n in notes]) + "\n", grid.notes


def _v(value: float) -> str:
    return f"{value:+.{DECIMALS}f}"


def read_heidenhain_com(text: str) -> tuple[list[str], np.ndarray]:
    """Column names and the numeric rows up to [END] (for the tests)."""
    lines = text.splitlines()
    header = lines[1].split()
    rows = []
    for line in lines[2:]:
        if line.strip() == "[END]":
            break
        rows.append([float(v) for v in line.split()])
    return header, np.asarray(rows)
