"""Klartext drilling cycles: the moves the control makes in the tool axis when one is called,
and the holes of a `PATTERN DEF` it calls them at (`pattern_holes`).

A `CYCL DEF` only defines a cycle; `M99` at the end of a block (after its move) or `CYCL CALL`
runs it where the tool stands.  Its Q parameters are the Q assignments of the `CYCL DEF`
block.  Heidenhain TNC 640 / iTNC 530 "Cycle programming" manual, "Fixed cycles: drilling",
each cycle's "Cycle run" (levels along the tool axis; Q200 set-up clearance, Q201 depth and
Q204 2nd set-up clearance count from the workpiece surface Q203):

* 200 DRILLING: FMAX to Q203+Q200; drill by Q202 at Q206; back at FMAX to the set-up
  clearance, and at FMAX down to the set-up clearance above the depth reached; again until
  the depth Q201; at FMAX to the set-up clearance, then to the 2nd set-up clearance if it is
  higher.
* 201 REAMING: FMAX to Q203+Q200; ream to Q201 at Q206; back to the set-up clearance at
  Q208 (0: at Q206); FMAX to the 2nd set-up clearance.
* 203 UNIVERSAL DRILLING: as 200, the plunge decreased after each infeed by the decrement
  Q212 down to the minimum Q205; with chip breaking (Q213 breaks) the tool goes back by Q256
  after an infeed, and out to the set-up clearance after every Q213 breaks; out of the hole at
  the retraction feed Q208 (0: at Q206), the chip breaks' short retracts too (the manual names
  no other feed for them), in again at FMAX to the set-up clearance above the depth reached.
* 240 CENTERING: FMAX to Q203+Q200; centre to the depth Q201 (Q343=0) at Q206; FMAX to the
  set-up clearance, then to the 2nd set-up clearance.
* 207 RIGID TAPPING: FMAX to Q203+Q200; tap to Q201 in one move, the spindle reversed back to
  the set-up clearance, both at the feed the spindle speed and the thread pitch Q239 make
  (the TOOL CALL's S times |Q239|, the manual names no other for the retract); FMAX to the 2nd
  set-up clearance.  Without a spindle speed the feed is not known: out of scope.
* 205 UNIVERSAL PECKING, in one infeed (the plunging depth Q202 0 or the depth or more, no chip
  breaking Q257 within it, no deepened starting point Q379): FMAX to Q203+Q200; drill to Q201
  at Q206; out to the set-up clearance at the retraction feed Q208 (0: at Q206); FMAX to the 2nd
  set-up clearance.  More infeeds come back down to the advanced stop distances Q258/Q259,
  which the control varies between the first and the last infeed itself: out of scope.

Dwells (Q210, Q211) move nothing.  The manual's depth sign gives the direction: a depth of
0 runs no cycle; a positive depth (the control refuses it unless a machine parameter allows
it), a depth measured on the tool's diameter (Q395=1, Q343=1: they need the tool's point
angle) and the other cycles (202 with its spindle orientation, 204, 206, 208, 209, pockets,
contours) are outside ncpp's scope (`OutOfScope`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ncpp.motion.modal import MAX_HOLES, OutOfScope

# The cycles followed and the Q parameters each needs (the others default to 0)
REQUIRED = {
    "200": ("q200", "q201", "q206", "q202", "q203", "q204"),
    "201": ("q200", "q201", "q206", "q203", "q204"),
    "203": ("q200", "q201", "q206", "q202", "q203", "q204"),
    "240": ("q200", "q201", "q206", "q203", "q204"),
    "207": ("q200", "q201", "q239", "q203", "q204"),
    "205": ("q200", "q201", "q206", "q202", "q203", "q204"),
}
OPTIONAL = {
    "200": ("q210", "q211", "q395"),
    "201": ("q211", "q208"),
    "203": ("q210", "q212", "q213", "q205", "q211", "q208", "q256", "q395"),
    "240": ("q343", "q344", "q211"),
    "207": ("q336",),
    "205": ("q212", "q205", "q258", "q259", "q257", "q256", "q211", "q379", "q253", "q208", "q395"),
}
# Cycles a CYCL DEF makes active at once, which leave the called cycle as it is: dwell (9),
# tolerance (32), preset (247), and the datum cycles (out of scope themselves)
DEFINITION_ACTIVE = frozenset(("7", "8", "9", "10", "11", "19", "26", "32", "247"))
RETRACT_FEED = "q208"  # the retraction feed: a number, 0 (at Q206), or MAX (rapid: infinite here)
MAX_INFEEDS = 10_000  # infeeds of one hole: beyond, the parameters are a mistake, not a hole


@dataclass(frozen=True)
class Drilling:
    """A defined drilling cycle: its number and Q parameters (name -> value, program units)."""

    number: str
    q: dict[str, float]
    line: int | None = None  # the CYCL DEF's line

    def __getitem__(self, name: str) -> float:
        return self.q.get(name, 0.0)


@dataclass(frozen=True)
class Step:
    """One move of a cycle run: to `level` in the tool axis, at rapid or at `feed`."""

    level: float
    rapid: bool
    feed: float = 0.0


def cycle_number(text: str) -> str:
    """`200` -> '200', `9.0` -> '9' (the old form numbers a cycle's lines)."""
    return text.split(".")[0].lstrip("0") or "0"


def parameters_needed(number: str) -> tuple[str, ...]:
    return REQUIRED[number] + OPTIONAL[number]


def steps(cycle: Drilling, spindle: float = 0.0) -> list[Step]:
    """The moves of one run of `cycle`, from the level the tool stands at, the spindle turning at
    `spindle` (rev/min; see the module docstring)."""
    depth = cycle["q201"]
    if depth == 0:
        return []  # (the manual: with DEPTH = 0 the control does not run the cycle)
    if depth > 0:
        raise OutOfScope(f"CYCL DEF {cycle.number} with a positive depth Q201 (away from the surface)")
    if cycle["q200"] < 0:
        raise OutOfScope(f"CYCL DEF {cycle.number} with a negative set-up clearance Q200")
    if cycle["q395"] or cycle["q343"]:
        raise OutOfScope(f"CYCL DEF {cycle.number} with the depth on the tool's diameter (Q395 or Q343 = 1)")
    surface = cycle["q203"]
    clearance = surface + cycle["q200"]
    bottom = surface + depth
    plunge, out = cycle["q206"], cycle[RETRACT_FEED] or cycle["q206"]

    def retract(level: float, rapid: bool = False) -> Step:
        """A move out at the retraction feed Q208, or at rapid (the cycle's own, or Q208= MAX)."""
        return Step(level, True) if rapid or math.isinf(out) else Step(level, False, out)

    if cycle.number == "207":
        if not spindle > 0 or not cycle["q239"]:
            raise OutOfScope("CYCL DEF 207 without a spindle speed (TOOL CALL S) or a thread pitch Q239: "
                             "its feed is not known")  # fmt: skip
        tapping = spindle * abs(cycle["q239"])
        run = [Step(clearance, True), Step(bottom, False, tapping), Step(clearance, False, tapping)]
        return run + _second(cycle, clearance)
    if cycle.number == "205":
        if cycle["q379"]:
            raise OutOfScope("CYCL DEF 205 with a deepened starting point Q379")
        if len(_infeeds(cycle, depth)) > 1 or 0 < cycle["q257"] < -depth:
            raise OutOfScope("CYCL DEF 205 in more than one infeed or with chip breaking Q257 (the control "
                             "comes back down to advanced stop distances it works out itself)")  # fmt: skip
        run = [Step(clearance, True), Step(bottom, False, plunge), retract(clearance)]
        return run + _second(cycle, clearance)
    if cycle.number in ("201", "240"):
        rapid_out = cycle.number == "240"
        run = [Step(clearance, True), Step(bottom, False, plunge)]
        return run + [retract(clearance, rapid_out)] + _second(cycle, clearance)
    run = [Step(clearance, True)]
    breaks = int(cycle["q213"]) if cycle.number == "203" else 0
    reached, broken, infeed = clearance, 0, 0
    for cut in _infeeds(cycle, depth):
        if infeed:
            if breaks and broken < breaks:
                broken += 1
                run.append(retract(reached + cycle["q256"]))
            else:
                broken = 0
                run += [retract(clearance, cycle.number == "200"), Step(reached + cycle["q200"], True)]
        reached = surface - cut
        run.append(Step(reached, False, plunge))
        infeed += 1
    return run + [retract(clearance, cycle.number == "200")] + _second(cycle, clearance)


def _infeeds(cycle: Drilling, depth: float) -> list[float]:
    """The depths below the surface each infeed ends at (positive), the last the full depth."""
    total, plunge = -depth, cycle["q202"]
    if plunge <= 0 or plunge >= total:
        return [total]  # (the manual: to depth in one move when the plunge is the depth or more)
    decrement = cycle["q212"] if cycle.number == "203" else 0.0
    least = cycle["q205"] if cycle.number == "203" else 0.0
    cuts: list[float] = []
    reached = 0.0
    while reached < total:
        if len(cuts) >= MAX_INFEEDS:
            raise OutOfScope(f"CYCL DEF {cycle.number} with more than {MAX_INFEEDS} infeeds")
        reached = min(total, reached + plunge)
        cuts.append(reached)
        plunge = max(plunge - decrement, least)
        if plunge <= 0:
            raise OutOfScope(f"CYCL DEF {cycle.number} whose decrement Q212 leaves no plunge (no Q205)")
    return cuts


def _second(cycle: Drilling, clearance: float) -> list[Step]:
    """FMAX to the 2nd set-up clearance, where it is above the set-up clearance."""
    second = cycle["q203"] + cycle["q204"]
    return [Step(second, True)] if second > clearance else []


# -- hole patterns (PATTERN DEF) -------------------------------------------------------------------
# Each shape's words (TNC 640 cycle programming manual, "Pattern definition PATTERN DEF"): those
# it needs, then those it may leave out (0).  POS: a position; ROW: start X Y, spacing D, count
# NUM, rotation ROT about the start; PAT/FRAME: start X Y, spacings DX DY, counts NUMX NUMY,
# rotation ROT, distortions ROTX ROTY; CIRC: centre X Y, diameter D, starting angle START,
# count NUM; PITCHCIRC: as CIRC with the stepping angle STEP.  Z, in every shape, is the
# workpiece surface, added to the cycle's Q203.
SHAPES = {
    "POS": (("X", "Y"), ("Z",)),
    "ROW": (("X", "Y", "D", "NUM"), ("ROT", "Z")),
    "PAT": (("X", "Y", "DX", "DY", "NUMX", "NUMY"), ("ROT", "ROTX", "ROTY", "Z")),
    "FRAME": (("X", "Y", "DX", "DY", "NUMX", "NUMY"), ("ROT", "ROTX", "ROTY", "Z")),
    "CIRC": (("X", "Y", "D", "NUM"), ("START", "Z")),
    "PITCHCIRC": (("X", "Y", "D", "STEP", "NUM"), ("START", "Z")),
}
Hole = tuple[float, float, float]  # X, Y and the workpiece surface the pattern gives it


def pattern_holes(name: str, words: dict[str, float]) -> list[Hole]:
    """The holes of one PATTERN DEF shape, in the order they are defined (a grid's row by row:
    see `ncpp.motion.heidenhain` for what follows from the order the manual leaves open)."""
    needed, optional = SHAPES[name]
    missing = [w for w in needed if w not in words]
    unknown = [w for w in words if w not in needed + optional]
    if missing or unknown:
        raise OutOfScope(f"PATTERN DEF {name} {'with ' + unknown[0] if unknown else 'without ' + missing[0]}")
    w = {k: words.get(k, 0.0) for k in needed + optional}
    surface = w["Z"]
    if name == "POS":
        return [(w["X"], w["Y"], surface)]
    grid_of = name in ("PAT", "FRAME")
    columns, rows = (_count(name, w["NUMX"]), _count(name, w["NUMY"])) if grid_of else (0, 0)
    count = _count(name, columns * rows if grid_of else w["NUM"])
    if name in ("CIRC", "PITCHCIRC"):
        step = w["STEP"] if name == "PITCHCIRC" else 360.0 / count
        radius = w["D"] / 2.0
        angles = np.radians(w["START"] + step * np.arange(count))
        xs, ys = w["X"] + radius * np.cos(angles), w["Y"] + radius * np.sin(angles)
        return [(float(x), float(y), surface) for x, y in zip(xs, ys)]
    if name == "ROW":
        grid = np.stack([w["D"] * np.arange(count), np.zeros(count)], axis=1)
    else:
        if w["ROTX"] or w["ROTY"]:
            raise OutOfScope(f"PATTERN DEF {name} with a distortion ROTX or ROTY")
        i, j = np.meshgrid(np.arange(columns), np.arange(rows))
        keep = (
            np.ones_like(i, bool)
            if name == "PAT"
            else (i == 0) | (i == columns - 1) | (j == 0) | (j == rows - 1)
        )
        grid = np.stack([w["DX"] * i[keep], w["DY"] * j[keep]], axis=1)
    turn = math.radians(w["ROT"])
    rotation = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    points = grid @ rotation.T + (w["X"], w["Y"])
    return [(float(x), float(y), surface) for x, y in points]


def _count(name: str, value: float) -> int:
    if not 1 <= value <= MAX_HOLES or value != int(value):
        raise OutOfScope(f"PATTERN DEF {name} with {value:g} holes")
    return int(value)


__all__ = ["DEFINITION_ACTIVE", "SHAPES", "Drilling", "Hole", "Step", "cycle_number", "parameters_needed",
           "pattern_holes", "steps"]  # fmt: skip
