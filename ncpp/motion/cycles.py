"""Canned cycles as rs274ngc moves them (interp_cycles.cc).

G73 (chip-breaking peck), G74/G84 (left/right-hand tapping), G81 (drill),
G82 (drill, dwell), G83 (peck), G85 (bore, feed out), G86 (bore, spindle
stop, rapid out), G87 (back bore) and G89 (bore, dwell, feed out),
in the G17, G18 or G19 plane.  Coordinates here are those of the plane, as
rs274ngc names them: `aa` and `bb` in the plane, `cc` along its normal (the
drilling axis).  G88 stays outside the interpreter's scope: the operator
retracts the spindle by hand, so where the tool is afterwards is unknown.
"""

from __future__ import annotations

CANNED = frozenset({73.0, 74.0, 81.0, 82.0, 83.0, 84.0, 85.0, 86.0, 87.0, 89.0})
DWELLING = frozenset({82.0, 86.0, 89.0})  # P: a dwell time, required (sticky within the cycle)
# the spindle direction (M3 1, M4 -1) each cycle needs (0: turning either way)
SPINDLE = {84.0: 1, 74.0: -1, 86.0: 0, 87.0: 0, 76.0: 0}  # (76: Fanuc's fine boring)
PECKING = frozenset({73.0, 83.0})  # Q: the peck depth, sticky within the cycle
# G73/G83: the rapid back into the hole stops this far above the last peck (rs274ngc's
# G83_RAPID_DELTA, in inch; 0.254 mm)
RAPID_DELTA_INCH = 0.010

Move = tuple[float, float, float, bool]  # (aa, bb, cc, rapid)


def approach(
    at: tuple[float, float, float], start_level: float, r: float, retract_to_r: bool
) -> tuple[list[Move], float, float]:
    """How a cycle reaches its holes from where the tool is (`at`, plane coordinates) when its
    series started at the normal-axis level `start_level`: (the move up to R first, if any,
    the level the tool crosses to the hole at, the level it retracts to).  It crosses not below
    R (G99) or the series' start level (G98), and G98 retracts to that start level even where
    an earlier, higher R left the tool above it; a series that started below R goes up to R
    first.  rs274ngc as LinuxCNC 2.9 runs it, found by probing it (test_cycles.py)."""
    if start_level < r:
        return [(at[0], at[1], r, True)], r, r
    clear = r if retract_to_r else start_level
    return [], at[2] if at[2] > r else clear, clear


def hole(
    motion: float,
    aa: float,
    bb: float,
    r: float,
    clear: float,
    bottom: float,
    peck: float,
    rapid_delta: float,
) -> list[Move]:
    """The moves of one hole, from above it at the R plane (`r`) back out to `clear`."""
    moves: list[Move] = []
    if motion in PECKING:
        depth = r - peck
        while depth > bottom:
            moves.append((aa, bb, depth, False))
            if motion == 83.0:  # out to the R plane to clear the chips
                moves.append((aa, bb, r, True))
            moves.append((aa, bb, depth + rapid_delta, True))
            depth = depth - peck
    moves.append((aa, bb, bottom, False))
    if motion == 85.0:
        moves.append((aa, bb, r, False))
    # taps and G89 feed out; Fanuc's fine boring G76 shifts off the wall at the bottom and back above
    # it, by the control's shift, and rapids out between (taken as straight out: its end is the same)
    moves.append((aa, bb, clear, motion not in (74.0, 84.0, 89.0)))
    return moves


def back_bore(
    aa: float, bb: float, off_a: float, off_b: float, r: float, clear: float, middle: float, bottom: float
) -> list[Move]:
    """G87: in beside the hole (`off_a`, `off_b`) with the spindle oriented, feed up to
    `middle` and back from the bottom, out the same way."""
    return [
        (off_a, off_b, r, True), (off_a, off_b, bottom, True), (aa, bb, bottom, True),
        (aa, bb, middle, False), (aa, bb, bottom, False),
        (off_a, off_b, bottom, True), (off_a, off_b, clear, True), (aa, bb, clear, True),
    ]  # fmt: skip


def fanuc_back_bore(
    at: tuple[float, float, float],
    aa: float,
    bb: float,
    off_a: float,
    off_b: float,
    r: float,
    top: float,
    initial: float,
) -> list[Move]:
    """Fanuc's G87 from `at` (plane coordinates): over the hole at the level the tool stands at, shifted
    by (`off_a`, `off_b`) with the spindle oriented, down to `r` below the part, back over the hole, the
    cut up to `top`, shifted again, up to the `initial` level and back over the hole (Fanuc Series
    15i-MA operator's manual, "Back boring cycle (G87)"; G98 only)."""
    shifted_a, shifted_b = aa + off_a, bb + off_b
    return [
        (aa, bb, at[2], True), (shifted_a, shifted_b, at[2], True), (shifted_a, shifted_b, r, True),
        (aa, bb, r, True), (aa, bb, top, False), (shifted_a, shifted_b, top, True),
        (shifted_a, shifted_b, initial, True), (aa, bb, initial, True),
    ]  # fmt: skip


def drilled(
    motion: float,
    at: tuple[float, float, float],
    start_level: float,
    aa: float,
    bb: float,
    r: float,
    bottom: float,
    peck: float,
    rapid_delta: float,
    retract_to_r: bool,
    back: tuple[float, float, float] | None = None,
) -> list[Move]:
    """The moves of a cycle block drilling one hole (no L repeats) from `at`; G87's `back`: its
    offset in the plane and the level it feeds up to (`back_bore`)."""
    moves, level, clear = approach(at, start_level, r, retract_to_r)
    moves.append((aa, bb, level, True))
    if level != r:
        moves.append((aa, bb, r, True))
    if back is not None:
        off_a, off_b, top = back
        return moves + back_bore(aa, bb, aa + off_a, bb + off_b, r, clear, top, bottom)
    return moves + hole(motion, aa, bb, r, clear, bottom, peck, rapid_delta)
