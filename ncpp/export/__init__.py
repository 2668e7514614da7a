"""Controller compensation tables (Rahman 2004, section 6.4.3): one module per controller.

Rahman 2004: M. Rahman, *Modeling and measurement of multi-axis machine tools to improve positioning
accuracy in a software way*, University of Oulu, 2004.

    from ncpp.export import axis_error, export_table
    text, notes = export_table(machine, "X", "linuxcnc", comp_type=0)

`notes` says what had to be resampled or clipped to meet the controller's
limits; the same sentences are in the file as comments.
"""

from __future__ import annotations

import math

import numpy as np

from ncpp.errors import NcppError
from ncpp.export.common import AxisError, axis_error
from ncpp.machine import Machine

FORMATS = ("linuxcnc", "fanuc", "sinumerik", "heidenhain")


def export_table(
    machine: Machine,
    axis: str,
    fmt: str,
    *,
    spacing: float | None = None,
    comp_type: int = 0,
    reference: float | None = None,
) -> tuple[str, list[str]]:
    """The table text for `axis` in controller format `fmt`, and the notes."""
    if spacing is not None and not 0 < spacing < math.inf:
        raise NcppError(f"--spacing must be a positive number of mm, not {spacing!r}")
    if reference is not None and not math.isfinite(reference):
        raise NcppError(f"--reference must be a finite number of mm, not {reference!r}")
    error = axis_error(machine, axis)
    if spacing is not None and spacing > error.hi - error.lo:  # a table needs two points on the travel
        raise NcppError(
            f"--spacing {spacing:g} mm is longer than the {axis} travel, {error.lo:g} to {error.hi:g} mm"
        )
    _check_size(machine, error)
    if fmt == "linuxcnc":
        from ncpp.export.linuxcnc import write_linuxcnc_comp

        return write_linuxcnc_comp(error, comp_type, spacing)
    if fmt == "fanuc":
        from ncpp.export.fanuc import write_fanuc_pitch

        return write_fanuc_pitch(error, spacing=spacing, reference=0.0 if reference is None else reference)
    if fmt == "sinumerik":
        from ncpp.export.sinumerik import write_sinumerik

        a = error.axis
        transverse = [
            axis_error(machine, a, f"E{j}{a}") for j in "XYZ" if j != a and f"E{j}{a}" in machine.components
        ]
        for t in transverse:
            _check_size(machine, t)
        return write_sinumerik(error, transverse, spacing=spacing, reference=reference)
    if fmt == "heidenhain":
        from ncpp.export.heidenhain import write_heidenhain_com

        return write_heidenhain_com(error, spacing=spacing)
    raise NcppError(f"unknown format {fmt!r}: use one of {', '.join(FORMATS)}")


def _check_size(machine: Machine, error: AxisError) -> None:
    """A controller applies a table's values as corrections: the machine file bounds
    those (max_correction_mm), as `ncpp compensate` does."""
    own = error.own_positions()
    x = (
        np.linspace(error.lo, error.hi, 2001)
        if own is None
        else np.union1d(np.linspace(error.lo, error.hi, 2001), own)
    )
    values = np.concatenate([error.forward(x), error.reverse(x)])
    worst = int(np.argmax(np.where(np.isfinite(values), np.abs(values), np.inf)))
    if not abs(values[worst]) <= machine.max_correction_mm:
        raise NcppError(
            f"{error.name} reaches {values[worst]:.4g} mm at {error.axis} = {x[worst % len(x)]:g} mm, more than the "
            f"machine file's max_correction_mm = {machine.max_correction_mm:g} mm that a table may correct"
        )


__all__ = ["FORMATS", "AxisError", "axis_error", "export_table"]
