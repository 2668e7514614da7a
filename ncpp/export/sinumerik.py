"""SINUMERIK 840D compensation tables in archive (tape) format.

Following the K3 "Compensations" function manual (6FC5397-1BP40-3BA1,
section 4.4, interpolatory compensation):

* Leadscrew / measuring system error compensation `%_N_AX_EEC_INI`:
  `$AA_ENC_COMP[e,N,AXn]` values at `$AA_ENC_COMP_MIN + N·_STEP` up to
  `_MAX`, e = encoder 0.  MSEC modifies the *actual value*: "a positive
  compensation value causes the machine axis to move in the negative
  direction", so the value is the error itself, e = actual − nominal.
  Points 0 ≤ N < MD38000 $MA_MM_ENC_COMP_MAX_POINTS.
* Sag / cross compensation `%_N_NC_CEC_INI`: `$AN_CEC[t,N]`,
  `$AN_CEC_INPUT_AXIS[t]` (base axis), `$AN_CEC_OUTPUT_AXIS[t]`
  (compensation axis), `_STEP`, `_MIN`, `_MAX`, `_DIRECTION`.  CEC adds its
  value to the compensation axis, so the value is −e.  Points
  0 ≤ N < MD18342 $MN_MM_CEC_MAX_POINTS[t].
* Reversal: MSEC acts in both directions, so it gets the mean of e₊ and e₋;
  two direction-dependent CEC tables (`_DIRECTION` = 1 / −1, base axis =
  compensation axis, "position-dependent backlash compensation" in K3) add
  −(e₊ − mean) and −(e₋ − mean).

Axis names: machine axes AX1, AX2, AX3 for X, Y, Z.  The manual asks for a
zero value at the reference point (no jump on activation): `reference`
shifts the leadscrew table by its value there.
"""

from __future__ import annotations

import numpy as np

from ncpp.export.common import AxisError, interpolation_residual, uniform_grid

MAX_ENC_POINTS = 5000  # MD38000 upper limit (840D sl)
MAX_CEC_POINTS = 2000  # MD18342 per table, a usual upper limit
MACHINE_AXES = {"X": "AX1", "Y": "AX2", "Z": "AX3"}
DECIMALS = 4  # 0.1 um


def write_sinumerik(
    error: AxisError,
    transverse: list[AxisError] = (),
    *,
    spacing: float | None = None,
    reference: float | None = None,
) -> tuple[str, list[str]]:
    """MSEC table for `error` (+ reversal CEC tables) and a CEC table per transverse component."""
    ax = MACHINE_AXES[error.axis]
    grid = uniform_grid(error.lo, error.hi, max_points=MAX_ENC_POINTS, spacing=spacing, what="SINUMERIK MSEC")
    x = grid.positions
    mean = error.mean(x)
    shift = 0.0 if reference is None else float(error.mean(np.array([reference]))[0])
    values = mean - shift
    n = len(x)
    lines = [
        f"; ncpp export-table: {error.name} of axis {error.axis} as measuring system error compensation",
        f"; needs MD38000 $MA_MM_ENC_COMP_MAX_POINTS[0,{ax}] >= {n} and MD32700 ENC_COMP_ENABLE[0] = 1",
        f"; largest error between points: {interpolation_residual(error, x, error.mean) * 1000:.3f} um",
    ]
    if reference is not None:
        lines.append(f"; shifted by {shift * 1000:+.1f} um so that the value at the reference {reference:g} mm is 0")
    lines += [f"; {note}" for note in grid.notes]
    enc = ["%_N_AX_EEC_INI", "CHANDATA(1)", *lines]
    enc += [f"$AA_ENC_COMP[0,{i},{ax}]={_mm(v)}" for i, v in enumerate(values)]
    enc += [
        f"$AA_ENC_COMP_STEP[0,{ax}]={_mm(grid.spacing)}",
        f"$AA_ENC_COMP_MIN[0,{ax}]={_mm(x[0])}",
        f"$AA_ENC_COMP_MAX[0,{ax}]={_mm(x[-1])}",
        f"$AA_ENC_COMP_IS_MODULO[0,{ax}]=0",
        "M17",
    ]
    notes = list(grid.notes)
    tables: list[tuple] = []  # (input axis, output axis, direction, component, correction(p), kind)
    if error.directional:
        for sign, curve in ((1, error.forward), (-1, error.reverse)):
            tables.append((ax, ax, sign, error, lambda p, c=curve: -(c(p) - error.mean(p)), "reversal"))
    for t in transverse:
        tables.append((MACHINE_AXES[t.axis], MACHINE_AXES[t.name[1]], 0, t, lambda p, t=t: -t.mean(p), "straightness"))
    if not tables:
        return "\n".join(enc) + "\n", notes
    cec = ["%_N_NC_CEC_INI", "CHANDATA(1)"]
    for index, (inp, out, direction, comp, correction, kind) in enumerate(tables):
        g = uniform_grid(comp.lo, comp.hi, max_points=MAX_CEC_POINTS, spacing=spacing, what=f"SINUMERIK CEC {index}")
        notes += [n_ for n_ in g.notes if n_ not in notes]
        p = g.positions
        cec.append(
            f"; table {index}: {kind} {comp.name}, correction -e on {out} as a function of {inp}"
            + (f", direction {direction:+d} only" if direction else "")
        )
        cec.append(f"; needs MD18342 $MN_MM_CEC_MAX_POINTS[{index}] >= {len(p)}, MD32710 CEC_TABLE_ENABLE[{index}] = 1")
        cec += [f"; {note}" for note in g.notes]
        cec += [f"$AN_CEC[{index},{i}]={_mm(v)}" for i, v in enumerate(correction(p))]
        cec += [
            f"$AN_CEC_INPUT_AXIS[{index}]=({inp})",
            f"$AN_CEC_OUTPUT_AXIS[{index}]=({out})",
            f"$AN_CEC_STEP[{index}]={_mm(g.spacing)}",
            f"$AN_CEC_MIN[{index}]={_mm(p[0])}",
            f"$AN_CEC_MAX[{index}]={_mm(p[-1])}",
            f"$AN_CEC_DIRECTION[{index}]={direction}",
            f"$AN_CEC_MULT_BY_TABLE[{index}]=0",
            f"$AN_CEC_IS_MODULO[{index}]=0",
        ]
    cec.append("M17")
    return "\n".join(enc + cec) + "\n", notes


def _mm(value: float) -> str:
    text = f"{value:.{DECIMALS}f}".rstrip("0")
    text = text + "0" if text.endswith(".") else text
    return "0.0" if text in ("-0.0", "0.0") else text


def read_sinumerik(text: str) -> dict[str, dict]:
    """System variables of our archive: name -> {index tuple: value} (for the tests)."""
    out: dict[str, dict] = {}
    for line in text.splitlines():
        if line.startswith("$") and "=" in line:
            name, _, value = line.partition("=")
            var, _, idx = name.partition("[")
            key = tuple(idx.rstrip("]").split(","))
            value = value.strip()
            out.setdefault(var, {})[key] = value.strip("()") if value.startswith("(") else float(value)
    return out

