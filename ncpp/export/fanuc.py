"""FANUC stored pitch error compensation (parameters 3620–3624) and backlash (1851).

Checked against (see tests/export/test_tables.py for where each is used):
  * FANUC Series 0i-PB parameter manual B-63980EN/01, p. 100
    (http://cncmanuals.com/fanuc/217/series-0i-pb-parameter-manual/page/108):
    "The compensation value is output at the compensation position No.
    corresponding to each section between the coordinates"; the example's
    values are small signed integers, an *increment* per section, whose
    running sum is the "pitch error compensation amount (absolute value)".
  * FANUC technical report A-77810E (16i/18i bidirectional pitch error
    compensation) lists 3620 reference point number, 3621 / 3622 most
    distant point on the − / + side, 3623 magnification, 3624 interval,
    3605#0 bidirectional, 3626 / 3627 for the − direction.

So point number n stands for a *section*: the interval that ends at
x_ref + (n − 3620)·3624.  3620 is the section that ends at the reference
position; 3621 the first section of the table (no point is spent below the
table start), 3622 the last.  With C(x) = −(e(x) − e(x_ref)) the wanted
correction in detection units, section k gets v_k = round(C_k/M) −
round(C_{k−1}/M): rounding the running sum, not each step, keeps the error
from drifting along the axis.  M (3623) is the smallest magnification that
brings every |v_k| within 7.

NOT verified (no primary source found; from memory): the ±7 range of a
value, 0..1023 point numbers, that a value is the correction to *add*
(−Δe, not the error), the tape syntax `N<param>A<axis>P<value>` and
`N<10000+point>P<value>`, and backlash parameter 1851 in detection units.

Reversal: the pitch table corrects travel in the + direction (reference
return in +); 1851 takes the mean extra error of − travel, e₋ − e₊
(positive = lost motion).  Position-dependent reversal (bidirectional pitch
compensation, 3605#0, 3626, 3627) is not written; its spread is reported.
"""

from __future__ import annotations

import math
import re

import numpy as np

from ncpp.errors import NcppError
from ncpp.export.common import AxisError, reference_on_travel

MAX_POINTS = 1024  # point numbers 0..1023, shared by all axes (0i); 30i allows more
MAX_STEP = 7
MAX_MAGNIFICATION = 100


def write_fanuc_pitch(
    error: AxisError,
    *,
    spacing: float | None = None,
    reference: float = 0.0,
    detection_unit: float = 0.001,
    reference_number: int | None = None,
    axis_number: int | None = None,
    max_points: int = MAX_POINTS,
) -> tuple[str, list[str]]:
    """Parameter listing (text with `(...)` comments) and the notes on what was changed.

    `reference_number` is 3620; by default the lowest that keeps every
    section number >= 0."""
    notes: list[str] = []
    lo, hi = error.lo, error.hi
    reference = reference_on_travel(error, reference, notes)
    du = detection_unit
    span = hi - lo
    # The sections from the reference outwards, each end rounded up, take up to span/interval + 2
    # point numbers: so many, and no more, fit max_points (0 .. max_points - 1).
    finest = span / (max_points - 2)
    interval = spacing if spacing is not None else max(finest, span / 64)  # 64 sections is a usual allocation
    if interval < finest:
        notes.append(f"FANUC: interval {interval:g} mm needs more than {max_points} points; widened")
        interval = finest
    interval = math.ceil(interval / du - 1e-9) * du  # an integer number of detection units
    k_lo = -int(math.ceil((reference - lo) / interval - 1e-9))
    k_hi = int(math.ceil((hi - reference) / interval - 1e-9))
    k = np.arange(k_lo, k_hi + 1)  # section k ends at x_k; k_lo is only the start of the first one
    x = reference + k * interval
    fwd = error.forward(x)
    wanted = -(fwd - error.forward(np.array([reference]))[0]) / du  # detection units, 0 at the reference
    magnification, steps = _fit_magnification(wanted)
    if np.any(np.abs(steps) > MAX_STEP):
        notes.append(
            f"FANUC: increments up to {np.max(np.abs(steps))} x{magnification} exceed +-{MAX_STEP}; "
            "clipped (use a smaller --spacing)"
        )
        steps = np.clip(steps, -MAX_STEP, MAX_STEP)
    steps = steps[1:]  # one value per section, sections k_lo+1 .. k_hi
    achieved = np.concatenate([[0], np.cumsum(steps)]) * magnification
    achieved -= achieved[k == 0][0]
    residual = float(np.max(np.abs(achieved - wanted))) * du
    reversal = (error.reverse(x) - fwd) / du
    backlash = int(round(float(np.mean(reversal))))
    ref_number = max(0, -k_lo - 1) if reference_number is None else reference_number
    first, last = ref_number + k_lo + 1, ref_number + k_hi
    if first < 0 or last >= max_points:
        raise NcppError(f"point numbers {first}..{last} exceed 0..{max_points - 1}")
    a = axis_number if axis_number is not None else "XYZ".index(error.axis) + 1
    params = [
        (3620, ref_number, f"number of the section ending at the reference position, {reference:g} mm"),
        (3621, first, f"most negative section, {x[0]:g} .. {x[1]:g} mm"),
        (3622, last, f"most positive section, {x[-2]:g} .. {x[-1]:g} mm"),
        (3623, magnification, "magnification of the values"),
        (3624, round(interval / du), f"interval between points in detection units = {interval:g} mm"),
        (1851, backlash, "backlash in detection units = mean of e- minus e+"),
    ]
    lines = [
        f"NCPP EXPORT-TABLE {error.name} OF AXIS {error.axis} AS FANUC PITCH ERROR COMPENSATION",
        f"parameter tape format: N<parameter> A<axis {a}> P<value>; pitch data N<10000 + point> P<value>",
        f"detection unit {du * 1000:g} um; a point's value is the increment, times 3623,",
        "output while the axis travels through its section",
        f"largest residual after rounding: {residual * 1000:.2f} um at the points",
        f"reversal varies {np.min(reversal) * du * 1000:.1f} .. {np.max(reversal) * du * 1000:.1f} um along the axis;"
        " only its mean goes to 1851",
        "check 3624 against the fastest feed: FANUC needs interval >= max feed / 7500",
        "unverified: value range +-7, sign = correction to add, tape syntax; check one point on the machine",
        *notes,
    ]
    out = ["%"] + [f"({_safe(line)})" for line in lines]
    out += [f"N{number}A{a}P{value} ({_safe(what)})" for number, value, what in params]
    out += [f"N{10000 + first + i}P{int(v)} ({x[i]:.3f} .. {x[i + 1]:.3f} MM)" for i, v in enumerate(steps)]
    return "\n".join(out + ["%"]) + "\n", notes


def _safe(text: str) -> str:
    """FANUC comments end at the first ')': keep them out."""
    return text.replace("(", "").replace(")", "").upper()


def _fit_magnification(wanted: np.ndarray) -> tuple[int, np.ndarray]:
    """Smallest magnification M whose rounded increments stay within ±7."""
    for m in range(1, MAX_MAGNIFICATION + 1):
        steps = np.diff(np.round(wanted / m), prepend=np.round(wanted[0] / m)).astype(int)
        if np.max(np.abs(steps)) <= MAX_STEP:
            return m, steps
    m = MAX_MAGNIFICATION
    return m, np.diff(np.round(wanted / m), prepend=np.round(wanted[0] / m)).astype(int)


def read_fanuc_pitch(text: str) -> tuple[dict[int, int], dict[int, int]]:
    """(parameters, pitch values by point number) from a parameter tape."""
    params: dict[int, int] = {}
    points: dict[int, int] = {}
    for line in text.splitlines():
        m = re.match(r"N(\d+)(?:A\d+)?P([-+]?\d+)", line)
        if m:
            number, value = int(m.group(1)), int(m.group(2))
            (points if number >= 10000 else params)[number % 10000 if number >= 10000 else number] = value
    return params, points
