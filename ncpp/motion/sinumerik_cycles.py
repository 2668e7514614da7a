"""Sinumerik drilling cycles: the levels along the tool axis a cycle runs through where it is called.

840D Programming Guide Cycles, "Drilling cycles" (levels in program coordinates; RTP the
retraction plane, RFP the reference plane, SDIS the safety clearance above it, no sign; the
final depth DP absolute or DPR below RFP, no sign, which counts when given):

* CYCLE81(RTP, RFP, SDIS, DP, DPR), "Drilling, centering": G0 to RFP+SDIS, G1 to the depth
  at the programmed feed, G0 to RTP.
* CYCLE82(..., DPR, DTB), "Drilling, counterboring": as CYCLE81, dwelling DTB s at the depth.
* CYCLE83(..., DPR, FDEP, FDPR, DAM, DTB, DTS, FRF, VARI), "Deep-hole drilling": G0 to
  RFP+SDIS, G1 to the first depth (FDEP absolute, or FDPR below RFP: it acts as DPR) at the
  programmed feed times FRF, the dwell DTB at each depth reached; each further stroke is the
  last one less the degression DAM while that is more than DAM, else DAM; G0 to RTP at the end.
  Chip breaking (VARI=0): after each infeed "retraction by 1 mm from the current drilling
  depth with G1 and the feedrate programmed in the calling program", then G1 to the next depth
  at that feed.  Chip removal (VARI=1) goes back to RFP+SDIS, dwells DTS and comes down at G0
  to the last depth less an anticipation distance the cycle works out internally: with more
  than one infeed it is out of scope, as are strokes that do not all have the same length
  (the manual shares out the last strokes of a degression its own way), a depth the strokes
  do not reach exactly, a safety clearance above DAM (with which the second stroke would
  differ as the first counts from RFP or from RFP+SDIS) and chip breaking in inches (the
  retract is given in mm).  One infeed (the first depth at DP) runs as CYCLE82 with the feed
  factor, in either mode.

The later versions' further parameters (CYCLE83: AXN, MDEP, VRT, DTD, DIS1; all: GMODE, DMODE,
AMODE) change what the others mean: given, they are out of scope, as is an FRF outside (0, 1]
(the feed factor the manual defines; 0, or left out, is not one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ncpp.motion.modal import OutOfScope

# Drilling cycles followed, and how many parameters each reads
PARAMETERS = {"CYCLE81": 5, "CYCLE82": 6, "CYCLE83": 12}
CHIP_BREAK = 1.0  # mm the chip-breaking retract goes back up (CYCLE83, VARI=0)
MAX_INFEEDS = 10_000  # infeeds of one hole: beyond, the parameters are a mistake, not a hole


@dataclass(frozen=True)
class Step:
    """One move of a cycle: to `level` along the tool axis at G0 (`feed` 0) or at G1 with the
    programmed feed times `feed`, then a dwell of `dwell` s."""

    level: float
    feed: float = 0.0
    dwell: float = 0.0


@dataclass(frozen=True)
class Drilling:
    """A drilling cycle's moves along the tool axis (program coordinates)."""

    name: str
    steps: tuple[Step, ...]


class CycleError(ValueError):
    """A cycle's parameters the control refuses (the message says which)."""


def drilling(name: str, values: list[float | None], inch: bool = False) -> Drilling:
    """The cycle `name` with its evaluated parameters (None: left out), in a program in inches
    or not."""
    rtp, rfp, sdis, dp, dpr = values[:5]
    if rtp is None or rfp is None or (dp is None and dpr is None):
        raise CycleError(f"{name}: RTP, RFP and DP or DPR are needed")
    # a parameter left out is 0 to the cycle, which cannot tell it from a 0 written: DPR counts
    # when it is not 0 ("DP and DPR both given: the depth is derived from DPR"), else DP
    depth = rfp - abs(dpr) if dpr else (dp or 0.0)
    clearance = rfp + abs(sdis or 0.0)
    if not depth < clearance:  # (the cycle drills down from above the plane)
        raise CycleError(f"{name}: the depth {depth:g} is not below the reference plane and safety clearance "
                         f"{clearance:g}")  # fmt: skip
    if name != "CYCLE83":
        dwell = (values[5] or 0.0) if name == "CYCLE82" else 0.0
        return Drilling(name, (Step(clearance), Step(depth, 1.0, dwell), Step(rtp)))
    return Drilling(name, (Step(clearance), *_deep_hole(values, rfp, depth, inch), Step(rtp)))


def _deep_hole(values: list[float | None], rfp: float, depth: float, inch: bool) -> list[Step]:
    """CYCLE83's infeeds (and chip-breaking retracts) from RFP+SDIS down to `depth`."""
    sdis = values[2]
    fdep, fdpr, dam, dtb, _dts, frf, vari = values[5:12]
    if not fdep and not fdpr:
        raise OutOfScope("CYCLE83 without a first drilling depth FDEP or FDPR")
    first = rfp - abs(fdpr) if fdpr else (fdep or 0.0)  # (as DPR and DP: `drilling`)
    if frf is None or not 0 < frf <= 1:
        raise OutOfScope(f"CYCLE83 with the feed factor FRF {'left out' if frf is None else f'{frf:g}'} "
                         "(the manual's range is 0.001 to 1)")  # fmt: skip
    if vari not in (None, 0.0, 1.0):
        raise OutOfScope(f"CYCLE83 with VARI={vari:g} (0: chip breaking, 1: chip removal)")
    if not depth <= first < rfp:
        raise OutOfScope(
            f"CYCLE83 with the first drilling depth {first:g} outside the hole ({rfp:g} to {depth:g})"
        )
    levels = _infeeds(rfp, first, depth, abs(dam or 0.0))
    if len(levels) > 1 and abs(sdis or 0.0) > abs(dam or 0.0):
        raise OutOfScope("CYCLE83 with the safety clearance SDIS above the degression DAM (the second stroke "
                         "would depend on whether the first counts from RFP or from RFP+SDIS)")  # fmt: skip
    if len(levels) > 1 and vari == 1.0:
        raise OutOfScope("CYCLE83 with chip removal (VARI=1) in more than one infeed: the control comes back "
                         "down to an anticipation distance it works out itself")  # fmt: skip
    if len(levels) > 1 and inch:
        raise OutOfScope("CYCLE83 with chip breaking in more than one infeed in inches (the manual gives "
                         "its retract in mm)")  # fmt: skip
    dwell = dtb or 0.0
    steps = [Step(levels[0], frf, dwell)]
    for level in levels[1:]:
        steps += [Step(steps[-1].level + CHIP_BREAK, 1.0), Step(level, 1.0, dwell)]
    return steps


def _infeeds(rfp: float, first: float, depth: float, dam: float) -> list[float]:
    """The depths the strokes reach, the last the final depth: out of scope unless every stroke
    is as long as the first (the degression rule gives that when DAM is the first stroke)."""
    stroke = rfp - first
    if math.isclose(first, depth, abs_tol=1e-9):
        return [depth]
    if not math.isclose(dam, stroke, rel_tol=1e-9):
        raise OutOfScope(f"CYCLE83 with strokes of different lengths (first {stroke:g}, degression {dam:g}): "
                         "how the cycle shares out its last strokes is not followed")  # fmt: skip
    count = (first - depth) / stroke
    if not math.isclose(count, round(count), abs_tol=1e-9) or round(count) >= MAX_INFEEDS:
        raise OutOfScope(f"CYCLE83 whose strokes of {stroke:g} do not reach the depth {depth:g} exactly")
    return [first - stroke * n for n in range(round(count))] + [depth]


__all__ = ["CHIP_BREAK", "PARAMETERS", "CycleError", "Drilling", "Step", "drilling"]
