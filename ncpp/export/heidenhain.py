"""HEIDENHAIN nonlinear axis error compensation table (*.COM).

Checked against (see tests/export/test_tables.py for where each is used):
  * HEIDENHAIN Technical Manual MANUALplus 620, p. 716, "Entering
    compensation values" (https://www.easymanua.ls/heidenhain/manualplus-620/manual/506189?p=716):
    column AXISPOS holds the compensation points, "with respect to the
    machine datum"; the column named after the axis (its CfgAxes/axisList
    key) holds the compensation values; BACKLASH, if required, "the
    compensation values measured in the negative direction of traverse".
  * same manual p. 718: a *.CMA table assigns the *.COM tables, one column
    per compensated axis, "[axis in column from *.com] = F(axis in column
    from *.cma)", the active line marked * in column ACTIVE.
  * TNC 407/415/425 Technical Manual (01.98), PLC module 9095 errors
    (https://azmanual.top/manuals/797826/heidenhain-tnc-407-243-020-technical-manual.html?page=622):
    "Compensation value table (.COM) has more than 256 entries".
  * The HEIDENHAIN table file layout, as read and written by drunsinn/pyLSV2
    (pyLSV2/table_reader.py; sample tests/test_files/palletmag.tab): a line
    `BEGIN <NAME>.<SUFFIX> MM`, a header line whose column names fix the
    columns' start and width, values *left-aligned* at their column's start,
    a last line `[END]`.

NOT verified (no primary source found): the sign (we write the measured
error e = actual − nominal, as the manuals' worked example plots "error in
Z"; whether the control subtracts it was not checkable), whether BACKLASH
wants the full negative-direction error (written) or its difference from
the positive one, the NR column, the 256-point limit on controls newer than
the TNC 4xx, and how a control treats the notes we put after `[END]`
(HEIDENHAIN tables have no comment syntax; pyLSV2 stops reading at `[END]`).
"""

from __future__ import annotations

import re

import numpy as np

from ncpp.export.common import AxisError, interpolation_residual, uniform_grid

MAX_POINTS = 256
DECIMALS = 5  # 0.01 um
WIDTH = 14  # every column; wide enough for -99999.99999


def write_heidenhain_com(
    error: AxisError, *, spacing: float | None = None, name: str | None = None
) -> tuple[str, list[str]]:
    grid = uniform_grid(error.lo, error.hi, max_points=MAX_POINTS, spacing=spacing, what="HEIDENHAIN")
    x = grid.positions
    fwd, rev = error.forward(x), error.reverse(x)
    name = (name or f"{error.axis}_{error.name}.COM").upper()
    col = error.axis
    rows = [f"BEGIN {name} MM", _row(["NR", "AXISPOS", col, "BACKLASH"])]
    rows += [_row([str(i), _v(p), _v(f), _v(r)]) for i, (p, f, r) in enumerate(zip(x, fwd, rev))]
    rows.append("[END]")
    residual = max(
        interpolation_residual(error, x, error.forward), interpolation_residual(error, x, error.reverse)
    )
    notes = [
        f"ncpp export-table: {error.name} of axis {error.axis}, {len(x)} points every {grid.spacing:g} mm, "
        "AXISPOS from the machine datum",
        f"assign in the .CMA file: {name} in column {col}, that line marked * in ACTIVE",
        f"largest error between points: {residual * 1000:.3f} um",
        "unverified: sign of the values (measured error e written); check one point on the machine",
        *grid.notes,
    ]
    return "\n".join(rows + [f"* {n}" for n in notes]) + "\n", grid.notes


def _row(cells: list[str]) -> str:
    return "".join(f"{c:<{WIDTH}}" for c in cells).rstrip()


def _v(value: float) -> str:
    return f"{value:+.{DECIMALS}f}"


def read_heidenhain_com(text: str) -> tuple[list[str], np.ndarray]:
    """Column names and the numeric rows up to [END], each cell cut at the
    header's column positions as a HEIDENHAIN control (and pyLSV2) reads it."""
    lines = text.splitlines()
    columns = list(re.finditer(r"\S+", lines[1]))
    names = [c.group() for c in columns]
    starts = [c.start() for c in columns]
    bounds = list(zip(starts, starts[1:] + [None]))
    rows = []
    for line in lines[2:]:
        if line.strip() == "[END]":
            break
        rows.append([float(line[a:b]) for a, b in bounds])
    return names, np.asarray(rows)
