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

* CYCLE84(..., DPR, DTB, SDAC, MPIT, PIT, POSS, SST, SST1), "Rigid tapping": G0 to RFP+SDIS,
  tapping to the depth at the speed SST, the dwell DTB, back to RFP+SDIS at the speed SST1 (0:
  SST), G0 to RTP; the feed along the tool axis is the speed times the thread pitch PIT (the
  pitch as a thread size MPIT is out of scope, as is a speed of 0).
* CYCLE840(..., DPR, DTB, SDR, SDAC, ENC, MPIT, PIT), "Tapping with compensating chuck": G0
  to RFP+SDIS, tapping to the depth, the dwell DTB, back to RFP+SDIS with the spindle
  reversed, G0 to RTP; without an encoder (ENC=1) and no pitch at the feed programmed before,
  else at the spindle speed programmed before times PIT (MPIT out of scope).
* CYCLE85(..., DPR, DTB, FFR, RFF), "Boring 1": G0 to RFP+SDIS, G1 to the depth at FFR, the
  dwell, G1 back to RFP+SDIS at RFF, G0 to RTP.
* CYCLE86(..., DPR, DTB, SDIR, RPA, RPO, RPAP, POSS), "Boring 2": G0 to RFP+SDIS, G1 to the
  depth at the feed programmed before, the dwell, an oriented spindle stop, G0 back to
  RFP+SDIS and to RTP; the lift-off RPA RPO RPAP away from the wall (a move in the plane the
  cycle makes from the hole) is out of scope unless all three are 0.
* CYCLE87(..., DPR, SDIR) and CYCLE88(..., DPR, DTB, SDIR), "Boring 3" and "Boring 4": G0 to
  RFP+SDIS, G1 to the depth at the feed programmed before, (CYCLE88: the dwell), the spindle
  stopped with M5 and the program with M0, then on NC start G0 to RTP.
* CYCLE89(..., DPR, DTB), "Boring 5": G0 to RFP+SDIS, G1 to the depth, the dwell, G1 back to
  RFP+SDIS at the same feed, G0 to RTP.

The later versions' further parameters (CYCLE83: AXN, MDEP, VRT, DTD, DIS1; CYCLE84: AXN, PTAB,
TECHNO, VARI, DAM, VRT; CYCLE840: AXN, PTAB, TECHNO; all: GMODE, DMODE, AMODE) change what the
others mean: given, they are out of scope, as is an FRF outside (0, 1] (the feed factor the
manual defines; 0, or left out, is not one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ncpp.motion.modal import OutOfScope

# Drilling cycles followed, and how many parameters each reads
PARAMETERS = {"CYCLE81": 5, "CYCLE82": 6, "CYCLE83": 12, "CYCLE84": 12, "CYCLE840": 11, "CYCLE85": 8,
              "CYCLE86": 11, "CYCLE87": 6, "CYCLE88": 7, "CYCLE89": 6}  # fmt: skip
CHIP_BREAK = 1.0  # mm the chip-breaking retract goes back up (CYCLE83, VARI=0)
MAX_INFEEDS = 10_000  # infeeds of one hole: beyond, the parameters are a mistake, not a hole


@dataclass(frozen=True)
class Step:
    """One move of a cycle: to `level` along the tool axis at G0 (`feed` and `rate` 0), at G1
    with the programmed feed times `feed` or at `rate`, then a dwell of `dwell` s."""

    level: float
    feed: float = 0.0
    dwell: float = 0.0
    rate: float = 0.0  # a feed of the cycle's own (program units/min), in place of the programmed one


@dataclass(frozen=True)
class Drilling:
    """A drilling cycle's moves along the tool axis (program coordinates)."""

    name: str
    steps: tuple[Step, ...]


class CycleError(ValueError):
    """A cycle's parameters the control refuses (the message says which)."""


def drilling(name: str, values: list[float | None], inch: bool = False, spindle: float = 0.0) -> Drilling:
    """The cycle `name` with its evaluated parameters (None: left out), in a program in inches
    or not, the spindle speed programmed before it `spindle` (rev/min)."""
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
    if name in BORING or name in TAPPING:
        return Drilling(
            name, (Step(clearance), *_in_and_out(name, values, clearance, depth, spindle), Step(rtp))
        )
    if name != "CYCLE83":
        dwell = (values[5] or 0.0) if name == "CYCLE82" else 0.0
        return Drilling(name, (Step(clearance), Step(depth, 1.0, dwell), Step(rtp)))
    return Drilling(name, (Step(clearance), *_deep_hole(values, rfp, depth, inch), Step(rtp)))


# Boring cycles: (the index of the dwell DTB or None, how the tool comes out: "G0", "G1" at the
# feed it went in at, or "RFF" at its own parameter)
BORING = {"CYCLE85": (5, "RFF"), "CYCLE86": (5, "G0"), "CYCLE87": (None, "G0"), "CYCLE88": (5, "G0"),
          "CYCLE89": (5, "G1")}  # fmt: skip
TAPPING = frozenset(("CYCLE84", "CYCLE840"))


def _in_and_out(
    name: str, values: list[float | None], clearance: float, depth: float, spindle: float
) -> list[Step]:
    """The steps between RFP+SDIS and back (or straight to RTP) of a boring or tapping cycle."""
    if name in TAPPING:
        return _tapping(name, values, clearance, depth, spindle)
    dwell_at, out = BORING[name]
    dwell = (values[dwell_at] or 0.0) if dwell_at is not None else 0.0
    if name == "CYCLE86" and any(values[7:10]):
        raise OutOfScope(
            "CYCLE86 with a lift-off RPA, RPO or RPAP (the cycle's move in the plane away from the wall)"
        )
    if name == "CYCLE85":
        ffr, rff = values[6], values[7]
        if not ffr or not rff or ffr < 0 or rff < 0:
            raise CycleError("CYCLE85: the feeds FFR and RFF are needed, above 0")
        return [Step(depth, rate=ffr, dwell=dwell), Step(clearance, rate=rff)]
    down = Step(depth, 1.0, dwell)
    if name in ("CYCLE87", "CYCLE88"):
        return [down]  # (M5 and M0 at the depth; on NC start G0 to RTP)
    return [down, Step(clearance, 1.0 if out == "G1" else 0.0)]


def _tapping(
    name: str, values: list[float | None], clearance: float, depth: float, spindle: float
) -> list[Step]:
    """CYCLE84's and CYCLE840's tapping in and back out to RFP+SDIS (the module docstring)."""
    dtb = values[5] or 0.0
    mpit, pit = (values[7], values[8]) if name == "CYCLE84" else (values[9], values[10])
    if mpit:
        raise OutOfScope(f"{name} with the thread pitch as a thread size MPIT")
    if name == "CYCLE840" and values[8] == 1.0 and not pit:  # without encoder: the programmed feed
        return [Step(depth, 1.0, dtb), Step(clearance, 1.0)]
    if name == "CYCLE840" and values[8] not in (None, 0.0, 1.0):
        raise OutOfScope(f"CYCLE840 with ENC={values[8]:g} (0: with encoder, 1: without)")
    if not pit:
        raise OutOfScope(f"{name} without a thread pitch PIT")
    speed_in = (values[10] or 0.0) if name == "CYCLE84" else spindle
    speed_out = ((values[11] or 0.0) or speed_in) if name == "CYCLE84" else spindle
    if not speed_in > 0 or not speed_out > 0:
        raise OutOfScope(f"{name} without a spindle speed ({'SST' if name == 'CYCLE84' else 'S before it'})")
    return [Step(depth, rate=speed_in * abs(pit), dwell=dtb), Step(clearance, rate=speed_out * abs(pit))]


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
