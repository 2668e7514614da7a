"""LinuxCNC screw compensation files ([JOINT_n] COMP_FILE, COMP_FILE_TYPE).

Format, as LinuxCNC reads it (src/emc/motion/usrmotintf.cc, usrmotLoadComp,
and the INI documentation of COMP_FILE_TYPE):

* one triplet `nominal  a  b` per line, nominals strictly increasing, at most
  256 triplets (EMCMOT_COMP_SIZE) per joint, machine units;
* COMP_FILE_TYPE = 0: `a`, `b` are where the axis *is* when commanded to the
  nominal while travelling forward / in reverse; LinuxCNC stores the trims
  nominal − a and nominal − b;
* COMP_FILE_TYPE = 1: `a`, `b` are those trims directly (forward, reverse);
* the trim, linearly interpolated between entries, is added to the motor
  position command (control.c: backlash_corr = fwd_trim + fwd_slope·dpos).

So with the model error e = actual − nominal, type 0 writes `x  x+e₊  x+e₋`
and type 1 writes `x  −e₊  −e₋`; either way LinuxCNC commands x − e and the
error cancels (to first order in the error's slope).

LinuxCNC stops reading at the first line that is not three numbers: a comment
*before* the data would silently disable compensation.  Our notes therefore
go after the data, where LinuxCNC no longer reads.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import Location, NcppError
from ncpp.export.common import AxisError, Grid, comment_block, interpolation_residual, uniform_grid
from ncpp.machine import Table

MAX_ENTRIES = 256  # EMCMOT_COMP_SIZE
DECIMALS = 6  # 1 nm in mm: far below any screw error
RESOLUTION = 10.0**-DECIMALS


def write_linuxcnc_comp(
    error: AxisError, comp_type: int = 0, spacing: float | None = None
) -> tuple[str, list[str]]:
    """The comp file text for `error` and the notes on what was resampled."""
    if comp_type not in (0, 1):
        raise NcppError(f"COMP_FILE_TYPE is 0 or 1, not {comp_type}")
    own = error.own_positions()
    if spacing is None and own is not None and 2 <= len(own) <= MAX_ENTRIES:
        grid = Grid(own, None)  # the measured points themselves: nothing resampled
    else:
        grid = uniform_grid(error.lo, error.hi, max_points=MAX_ENTRIES, spacing=spacing, what="LinuxCNC")
        if own is not None and spacing is None:
            grid.notes.append(
                f"{len(own)} table points exceed LinuxCNC's {MAX_ENTRIES}; resampled every {grid.spacing:g} mm"
            )
    x = grid.positions
    fwd, rev = error.forward(x), error.reverse(x)
    a, b = (x + fwd, x + rev) if comp_type == 0 else (-fwd, -rev)
    width = max(len(f"{v:.{DECIMALS}f}") for v in np.concatenate([x, a, b]))
    body = "".join(
        f"{n:{width}.{DECIMALS}f} {p:{width}.{DECIMALS}f} {q:{width}.{DECIMALS}f}\n"
        for n, p, q in zip(x, a, b)
    )
    residual = max(
        interpolation_residual(error, x, error.forward), interpolation_residual(error, x, error.reverse)
    )
    what = (
        "actual positions (forward, reverse)"
        if comp_type == 0
        else "trims added to the command (forward, reverse)"
    )
    notes = [
        f"ncpp export-table: {error.name} of axis {error.axis}, {len(x)} entries, {x[0]:g} .. {x[-1]:g} mm",
        f"COMP_FILE_TYPE = {comp_type}: columns are nominal and {what}, mm",
        f"largest error between entries (linear interpolation): {residual * 1000:.3f} um",
        *grid.notes,
        "LinuxCNC reads triplets up to the first other line, so these notes come last",
    ]
    return body + comment_block(notes, "# "), grid.notes


@dataclass(frozen=True)
class LinuxCncComp:
    """A comp file read back: nominals and the error it describes (mm, actual − nominal)."""

    nominal: NDArray
    forward: NDArray  # actual − nominal, forward travel
    reverse: NDArray
    comp_type: int
    lines: tuple[int, ...]  # 1-based file line of each entry
    resolution: float  # the finest decimal step written in the file, mm
    file: str = "<comp>"

    def correction(self, x, direction: int = 1) -> NDArray:
        """The trim LinuxCNC adds to the command at `x` (linear between entries, end values held)."""
        values = self.forward if direction > 0 else self.reverse
        return -np.interp(np.asarray(x, dtype=float), self.nominal, values)

    @property
    def table(self) -> Table:
        """The error as a machine-model table (reversal in the minus values)."""
        return Table(tuple(self.nominal), tuple(self.forward), tuple(self.reverse), "linear")


_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")


def read_linuxcnc_comp(path: str | Path, comp_type: int = 0) -> LinuxCncComp:
    """Read a comp file the way LinuxCNC does, but refuse what it would get wrong."""
    file = str(path)
    text = Path(path).read_text(encoding="utf-8", errors="replace")
    rows, lines, decimals = [], [], 0
    stopped_at = None
    for number, line in enumerate(text.splitlines(), start=1):
        fields = line.split()
        values = _triplet(fields)
        if values is None:
            if stopped_at is None:
                stopped_at = number
            continue
        if stopped_at is not None:
            raise NcppError(
                f"LinuxCNC stops reading at line {stopped_at}; this triplet and the ones after it are ignored by it",
                Location(file, number, 1),
            )
        rows.append(values)
        lines.append(number)
        decimals = max(decimals, *(len(f.partition(".")[2]) for f in fields[:3]))
    if not rows:
        raise NcppError(
            "no `nominal forward reverse` triplets before the first other line", Location(file, 1, 1)
        )
    if len(rows) > MAX_ENTRIES:
        raise NcppError(
            f"{len(rows)} triplets; LinuxCNC holds at most {MAX_ENTRIES}",
            Location(file, lines[MAX_ENTRIES], 1),
        )
    data = np.asarray(rows)
    nominal = data[:, 0]
    for i in np.flatnonzero(np.diff(nominal) <= 0):
        raise NcppError(
            "nominal positions must increase (LinuxCNC rejects this entry)", Location(file, lines[i + 1], 1)
        )
    if comp_type == 0:
        fwd, rev = data[:, 1] - nominal, data[:, 2] - nominal
    elif comp_type == 1:
        fwd, rev = -data[:, 1], -data[:, 2]
    else:
        raise NcppError(f"COMP_FILE_TYPE is 0 or 1, not {comp_type}")
    return LinuxCncComp(nominal, fwd, rev, comp_type, tuple(lines), 10.0**-decimals, file)


def _triplet(fields: list[str]) -> tuple[float, float, float] | None:
    # sscanf("%lf %lf %lf") needs three leading numbers; anything after them is ignored.
    if len(fields) < 3 or not all(_NUMBER.fullmatch(f) for f in fields[:3]):
        return None
    return float(fields[0]), float(fields[1]), float(fields[2])


@dataclass(frozen=True)
class Outlier:
    line: int
    nominal: float
    column: str  # "forward" or "reverse"
    error: float  # actual − nominal at this entry, mm
    expected: float  # from its neighbours, mm

    def __str__(self) -> str:
        return (
            f"{self.column} error {self.error * 1000:+.1f} um at {self.nominal:g} "
            f"where its neighbours give {self.expected * 1000:+.1f} um"
        )


def flag_outliers(comp: LinuxCncComp, k: float = 6.0) -> list[Outlier]:
    """Entries that disagree with the line through their neighbours by more
    than k robust standard deviations (1.4826·MAD, at least the file's
    resolution).  One at a time, worst first, each flagged entry left out of
    its neighbours' predictions — so one wild point does not also condemn
    the two next to it."""
    out = []
    for column, values in (("forward", comp.forward), ("reverse", comp.reverse)):
        good = np.ones(len(values), dtype=bool)
        while good.sum() >= 4:
            residual = _neighbour_residuals(comp.nominal, values, good)
            live = residual[good]
            mad = np.median(np.abs(live - np.median(live)))
            scale = max(1.4826 * mad, comp.resolution)
            worst = int(np.argmax(np.where(good, np.abs(residual), -1.0)))
            if abs(residual[worst]) <= k * scale:
                break
            good[worst] = False
            expected = values[worst] - residual[worst]
            out.append(
                Outlier(
                    comp.lines[worst],
                    float(comp.nominal[worst]),
                    column,
                    float(values[worst]),
                    float(expected),
                )
            )
    return sorted(out, key=lambda o: (o.line, o.column))


def _neighbour_residuals(x: NDArray, y: NDArray, good: NDArray) -> NDArray:
    """For each good point: y minus the straight line through its nearest good
    neighbours (both sides inside, the two nearest on one side at the ends)."""
    idx = np.flatnonzero(good)
    res = np.zeros(len(y))
    for j, i in enumerate(idx):
        if 0 < j < len(idx) - 1:
            a, b = idx[j - 1], idx[j + 1]
        elif j == 0:
            a, b = idx[1], idx[2]
        else:
            a, b = idx[-3], idx[-2]
        res[i] = y[i] - (y[a] + (y[b] - y[a]) * (x[i] - x[a]) / (x[b] - x[a]))
    return res
