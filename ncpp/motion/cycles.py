"""Drilling canned cycles as rs274ngc moves them (interp_cycles.cc).

G73 (chip-breaking peck), G81 (drill), G82 (drill, dwell), G83 (peck),
G85 (bore, feed out) and G89 (bore, dwell, feed out), in the G17, G18 or
G19 plane.  Coordinates here are those of the plane, as rs274ngc names them:
`aa` and `bb` in the plane, `cc` along its normal (the drilling axis).
The cycles that stop, reverse or orient the spindle (G74 G84 G86 G87 G88)
stay outside the interpreter's scope: they depend on the spindle's state.
"""

from __future__ import annotations

DRILLING = frozenset({73.0, 81.0, 82.0, 83.0, 85.0, 89.0})
DWELLING = frozenset({82.0, 89.0})  # P: a dwell time, sticky within the cycle
PECKING = frozenset({73.0, 83.0})  # Q: the peck depth, sticky within the cycle
# G73/G83: the rapid back into the hole stops this far above the last peck (rs274ngc's
# G83_RAPID_DELTA, in inch; 0.254 mm)
RAPID_DELTA_INCH = 0.010

Move = tuple[float, float, float, bool]  # (aa, bb, cc, rapid)


def hole(motion: float, aa: float, bb: float, r: float, clear: float, bottom: float, peck: float, rapid_delta: float) -> list[Move]:
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
    moves.append((aa, bb, clear, motion != 89.0))  # G89 feeds out
    return moves
