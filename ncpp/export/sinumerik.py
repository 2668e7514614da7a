"""SINUMERIK 840D compensation tables in archive (tape) format.

Checked against (see tests/export/test_tables.py for where each is used):
  * K3 "Compensations", Function Manual Extended Functions 03/2013,
    6FC5397-1BP40-3BA1, section 4.4.2 (measuring system error compensation):
    table parameters p. 240 (https://www.easymanua.ls/siemens/sinumerik-series/manual/275710?p=240)
    and the worked example p. 242
    (https://manual.onestart.ai/manuals/Siemens-SINUMERIK-Series-Function-Manual-5628364?page=242):
    `%_N_AX_EEC_INI`, `CHANDATA(1)`, `$AA_ENC_COMP[0,N,X1]=0.003` (mm),
    `$AA_ENC_COMP_STEP/_MIN/_MAX/_IS_MODULO[0,X1]`, `M17`; 0 ≤ N ≤
    MD38000 $MA_MM_ENC_COMP_MAX_POINTS − 1; the first and last values stay
    active beyond the table.
  * SINUMERIK 808D Function Manual 01/2017, p. 106
    (https://www.easymanua.ls/siemens/sinumerik-808d/manual/217421?p=106):
    MSEC alters the *actual value*, "A positive compensation value causes
    the corresponding machine axis to move in the negative direction" — so
    the value is the error itself, e = actual − nominal; and the value at the
    reference point should be zero (no jump on activation).
  * K3 4.4.3, table parameters p. 248-249
    (https://www.easymanua.ls/siemens/sinumerik-series/manual/275710?p=248,
    https://manual.onestart.ai/manuals/Siemens-SINUMERIK-Series-Function-Manual-5628364?page=249):
    `$AN_CEC[t,N]`, `_INPUT_AXIS` (base axis), `_OUTPUT_AXIS` (compensation
    axis), `_STEP`, `_MIN`, `_MAX`, `_DIRECTION` (0 both, 1 +, −1 −;
    "position-dependent backlash compensation can be implemented using two
    tables"), `_MULT_BY_TABLE`, `_IS_MODULO`; 0 ≤ N ≤ MD18342 − 1; general
    axis names AX1 ... in `(AXn)`; the 802D sl K3 example
    (https://www.easymanua.ls/siemens/sinumerik-802d-sl/manual/592298?p=222)
    shows `%_N_NC_CEC_INI`, `CHANDATA(1)`, `$AN_CEC_INPUT_AXIS[0]=(AX2)`.

NOT verified: the sign of a CEC value (we write −e, a value *added* to the
compensation axis; no sentence saying so was found); that the general name
AXn is accepted in `$AA_ENC_COMP` (the manual's example uses the machine
axis name X1; we write AX1..AX3 so that renamed machine axes still match);
the upper limits of MD38000 (5000 here) and MD18342 (2000 here) on 840D sl
(808D: 200 MSEC points; 828D: 8 CEC tables of 200 points).

Reversal: MSEC acts in both directions, so it gets the mean of e₊ and e₋;
two direction-dependent CEC tables (`_DIRECTION` = 1 / −1, base axis =
compensation axis) add −(e₊ − mean) and −(e₋ − mean).  `reference` shifts
the leadscrew table to 0 at the reference point.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ncpp.export.common import AxisError, interpolation_residual, reference_on_travel, uniform_grid

MAX_ENC_POINTS = 5000  # MD38000 upper limit (840D sl)
MAX_CEC_POINTS = 2000  # MD18342 per table, a usual upper limit
MACHINE_AXES = {"X": "AX1", "Y": "AX2", "Z": "AX3"}
DECIMALS = 4  # 0.1 um


def write_sinumerik(
    error: AxisError,
    transverse: Sequence[AxisError] = (),
    *,
    spacing: float | None = None,
    reference: float | None = None,
) -> tuple[str, list[str]]:
    """MSEC table for `error` (+ reversal CEC tables) and a CEC table per transverse component."""
    ax = MACHINE_AXES[error.axis]
    grid = uniform_grid(error.lo, error.hi, max_points=MAX_ENC_POINTS, spacing=spacing, what="SINUMERIK MSEC")
    x = grid.positions
    assert grid.spacing is not None  # a uniform grid has one
    mean = error.mean(x)
    placed: list[str] = []  # the reference's note, when it is moved onto the travel
    reference = None if reference is None else reference_on_travel(error, reference, placed)
    shift = 0.0 if reference is None else float(error.mean(np.array([reference]))[0])
    values = mean - shift
    n = len(x)
    lines = [
        f"; ncpp export-table: {error.name} of axis {error.axis} as measuring system error compensation",
        f"; needs MD38000 $MA_MM_ENC_COMP_MAX_POINTS[0,{ax}] >= {n} and MD32700 ENC_COMP_ENABLE[0] = 1",
        f"; largest error between points: {interpolation_residual(error, x, error.mean) * 1000:.3f} um",
    ]
    if reference is not None:
        lines.append(
            f"; shifted by {shift * 1000:+.1f} um so that the value at the reference {reference:g} mm is 0"
        )
    else:
        lines.append("; not shifted: Siemens asks for 0 at the reference point (give --reference)")
    lines += [f"; {note}" for note in placed + grid.notes]
    enc = ["%_N_AX_EEC_INI", "CHANDATA(1)", *lines]
    enc += [f"$AA_ENC_COMP[0,{i},{ax}]={_mm(v)}" for i, v in enumerate(values)]
    enc += [
        f"$AA_ENC_COMP_STEP[0,{ax}]={_mm(grid.spacing)}",
        f"$AA_ENC_COMP_MIN[0,{ax}]={_mm(x[0])}",
        f"$AA_ENC_COMP_MAX[0,{ax}]={_mm(x[-1])}",
        f"$AA_ENC_COMP_IS_MODULO[0,{ax}]=0",
        "M17",
    ]
    notes = placed + list(grid.notes)
    tables: list[tuple] = []  # (input axis, output axis, direction, component, correction(p), kind)
    if error.directional:
        for sign, curve in ((1, error.forward), (-1, error.reverse)):
            tables.append((ax, ax, sign, error, lambda p, c=curve: -(c(p) - error.mean(p)), "reversal"))
    for t in transverse:
        tables.append(
            (MACHINE_AXES[t.axis], MACHINE_AXES[t.name[1]], 0, t, lambda p, t=t: -t.mean(p), "straightness")
        )
    if not tables:
        return "\n".join(enc) + "\n", notes
    cec = [
        "%_N_NC_CEC_INI",
        "CHANDATA(1)",
        "; unverified: sign of the CEC values (-e written); check one point on the machine",
    ]
    for index, (inp, out, direction, comp, correction, kind) in enumerate(tables):
        g = uniform_grid(
            comp.lo, comp.hi, max_points=MAX_CEC_POINTS, spacing=spacing, what=f"SINUMERIK CEC {index}"
        )
        notes += [n_ for n_ in g.notes if n_ not in notes]
        p = g.positions
        assert g.spacing is not None  # a uniform grid has one
        cec.append(
            f"; table {index}: {kind} {comp.name}, correction -e on {out} as a function of {inp}"
            + (f", direction {direction:+d} only" if direction else "")
        )
        cec.append(
            f"; needs MD18342 $MN_MM_CEC_MAX_POINTS[{index}] >= {len(p)}, MD32710 $MA_CEC_ENABLE = 1 on {out}"
            f" and the table enabled (SD41300 $SN_CEC_TABLE_ENABLE[{index}] = 1, unverified)"
        )
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
