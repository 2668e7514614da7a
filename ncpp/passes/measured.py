"""Error maps taken straight from one measurement (M. Rahman, *Modeling and measurement
of multi-axis machine tools to improve positioning accuracy in a software way*,
University of Oulu, 2004, sections 7.2–7.3).

`ncpp compensate --from FILE` uses these instead of a full machine model:

* a ball-bar file gives a radial map in its plane: a point at angle θ about
  the ball-bar centre is off by ΔR(θ) along the radius (the mean of the CW
  and CCW traces, after removing the set-up centre offset by the
  least-squares circle, so the correction is the machine's and not the
  fixture's);
* a laser position or comparator file gives the positioning (and
  transverse) deviation along its axis, from the ISO 230-2 mean
  bidirectional deviation per target, interpolated linearly and held
  constant beyond the measured range.

Both were measured with one tool; they hold whatever tool length offset the
program applies (they know no Abbe arm to lengthen).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from ncpp.errors import NcppError
from ncpp.instruments.files import PLANES, Measurement, read_measurement

AXIS_INDEX = {"X": 0, "Y": 1, "Z": 2}


@dataclass(frozen=True, eq=False)
class RadialMap:
    """ΔR(θ) about a centre in a plane; deviation is radial, in that plane."""

    centre: NDArray  # (3,) mm, command coordinates
    axes: tuple[int, int]  # plane's first and second axis index
    angle: NDArray  # (n,) rad, sorted, in [0, 2π)
    delta_r: NDArray  # (n,) mm

    def deviation(
        self, P: NDArray, direction: NDArray | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        P = np.atleast_2d(np.asarray(P, dtype=float))
        i, j = self.axes
        u, v = P[:, i] - self.centre[i], P[:, j] - self.centre[j]
        theta = np.arctan2(v, u) % (2 * np.pi)
        dr = np.interp(theta, self.angle, self.delta_r, period=2 * np.pi)
        r = np.hypot(u, v)
        safe = np.where(r > 0, r, 1.0)
        out = np.zeros_like(P)
        out[:, i] = np.where(r > 0, dr * u / safe, 0.0)
        out[:, j] = np.where(r > 0, dr * v / safe, 0.0)
        return out


@dataclass(frozen=True, eq=False)
class AxisMap:
    """Deviation vectors as functions of one axis position."""

    axis: int
    position: NDArray  # (n,) mm, ascending
    deviation_mm: NDArray  # (n,3) mm

    def deviation(
        self, P: NDArray, direction: NDArray | None = None, tool_offset: NDArray | None = None
    ) -> NDArray:
        P = np.atleast_2d(np.asarray(P, dtype=float))
        x = P[:, self.axis]
        return np.column_stack([np.interp(x, self.position, self.deviation_mm[:, k]) for k in range(3)])


def radial_map(m: Measurement) -> RadialMap:
    from ncpp.instruments.iso230_4 import _angles_about, centred, circular_test, lsc_centre

    test = circular_test(m)
    if m.center_mm is None:
        raise NcppError("a ball-bar file needs center_mm to compensate from it", m.at())
    centre_um = lsc_centre(test.traces, test.radius_mm)
    grid = np.radians(np.arange(0.0, 360.0, 0.5))
    curves = []
    for trace in test.traces:
        theta = _angles_about(trace, centre_um, test.radius_mm) % (2 * np.pi)
        order = np.argsort(theta)
        dr = centred(trace, centre_um, test.radius_mm)[order]
        curves.append(np.interp(grid, theta[order], dr, period=2 * np.pi))
    first, second = (AXIS_INDEX[a] for a in PLANES[m.plane])
    return RadialMap(
        np.asarray(m.center_mm, dtype=float), (first, second), grid, np.mean(curves, axis=0) / 1000.0
    )


def axis_map(m: Measurement) -> AxisMap:
    from ncpp.instruments.iso230_2 import evaluate_measurement

    name = m.axis
    if name not in AXIS_INDEX:
        what = f"a {m.instrument} file needs '# axis: X' (or Y or Z) to compensate from it"
        raise NcppError(what, m.at("axis"))
    axis = AXIS_INDEX[name]
    linear_column = "linear_um" if m.instrument == "comparator" else None
    linear = evaluate_measurement(m, column=linear_column)
    deviation = np.zeros((len(linear.targets), 3))
    deviation[:, axis] = np.nan_to_num(linear.mean) / 1000.0
    if m.instrument == "comparator":
        transverse = evaluate_measurement(m, column="transverse_um")
        across = (m.text("transverse") or "").upper()
        if across not in AXIS_INDEX:
            what = "a comparator file needs '# transverse: X' (or Y or Z) to compensate from it"
            raise NcppError(what, m.at("transverse"))
        deviation[:, AXIS_INDEX[across]] = np.nan_to_num(transverse.mean) / 1000.0
    order = np.argsort(linear.targets)
    return AxisMap(axis, np.asarray(linear.targets, dtype=float)[order], deviation[order])


def map_from_file(path: str) -> RadialMap | AxisMap:
    m = read_measurement(path)
    if m.instrument == "ballbar":
        return radial_map(m)
    if m.instrument == "comparator" or (m.instrument == "laser" and (m.quantity or "position") == "position"):
        return axis_map(m)
    raise NcppError(
        f"cannot compensate from a {m.instrument} {m.quantity or ''} file: use a ball-bar, comparator or laser position file",
        m.at(),
    )
