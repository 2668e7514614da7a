"""APT hole-making cycles: `CYCLE/...` records and the holes their `GOTO`s drill.

Under a `CYCLE/` record each `GOTO` names a hole's top (the cycle point); the
cycle drills it down the tool axis (+Z here) and `CYCLE/OFF` ends the cycle.
The records are read in the keyword couplet form (ISO 4343:2000) that Creo
writes by default and NX writes:

* Creo: `CYCLE/DRILL|DEEP|BRKCHP|TAP|BORE, DEPTH,d [, STEP,s] , MMPM|IPM|MMPR|IPR,f,
  CLEAR,c [, RAPTO,r] [, RETURN,e]`: `d` below the point; the R plane `c` above it,
  `r` further towards it (Creo's "CL Output for Holemaking Cycles");
* NX: `CYCLE/DRILL[,DEEP|BRKCHP]|TAP|BORE, FEDTO,-d, [RAPTO,r | CLEAR,c,] RTRCTO,AUTO|v,
  MMPM,f`: the bottom at `-d` and the R plane at `r` (else `c`) from the point;
* SolidWorks CAM: `CYCLE/DRILL, FEDTO,d, MMPM,f, RAPTO,r, RTRCTO,v [, DWELL,t]` with the
  depth `d` above 0: the bottom `d` below the point, the R plane `r` and the retract level
  `v` above it (its files retract to the level the cycle started from: `v` is checked
  against it hole by hole).

A hole is drilled from the R plane to its bottom and left at the R plane (G99),
or, with `RTRCTO,AUTO` / `RETURN,0`, at the level the cycle started from (G98).
Positional (fixed format) records and couplets this module does not follow are
refused: a hole drilled to a guessed depth is scrap.
"""

from __future__ import annotations

from dataclasses import dataclass

from ncpp.cldata.reader import Record
from ncpp.errors import NcppError
from ncpp.motion.cycles import RAPID_DELTA_INCH, Move, hole
from ncpp.motion.segments import Point
from ncpp.program.blocks import Block

MM_PER_INCH = 25.4
LEVEL_TOL = 1e-6  # a retract level this close to the R plane is the R plane
# Cycle kinds and the ISO canned cycle that does each (RS274/NGC and FANUC: G81 drill,
# G82 drill with dwell, G83 peck, G73 chip-breaking peck, G84 tap, G85 bore feeding out,
# G89 bore with dwell); FACE is a drill with a dwell, REAM a bore
KINDS = {"DRILL": 81, "FACE": 81, "DEEP": 83, "BRKCHP": 73, "TAP": 84, "BORE": 85, "REAM": 85}
DWELLING = {81: 82, 85: 89}  # the cycle a DWELL at the bottom turns each into
FEEDS = {"MMPM": False, "IPM": False, "MMPR": True, "IPR": True}  # per revolution?
NUMBERS = {"DEPTH", "FEDTO", "CLEAR", "RAPTO", "RTRCTO", "RETURN", "STEP", "DWELL"} | set(FEEDS)


@dataclass(frozen=True, slots=True)
class Cycle:
    """A `CYCLE/` record's drilling: distances from the cycle point along +Z."""

    kind: str  # a KINDS key
    bottom: float  # below the point (negative)
    r_plane: float  # above the point (the rapid ends, the feed starts)
    feed: float | None  # per minute, per revolution when `per_rev`; None: the FEDRAT's
    per_rev: bool
    step: float  # peck depth (DEEP, BRKCHP); 0 otherwise
    dwell: float  # seconds at the bottom; 0: none
    to_start: bool  # retract to the level the cycle started from (G98), else to the R plane (G99)
    record: Record
    retract: float | None = None  # SolidWorks CAM's RTRCTO: the start level's height above each hole

    @property
    def code(self) -> int:
        """The ISO G code of the canned cycle."""
        code = KINDS[self.kind]
        return DWELLING.get(code, code) if self.dwell else code


def parse_cycle(rec: Record) -> Cycle | None:
    """The cycle of a `CYCLE/` record; None for `CYCLE/OFF`."""
    words = rec.words
    if words[:1] == ("OFF",):
        return None
    kind = words[0] if words else ""
    if (
        kind == "DRILL" and len(rec.args) > 1 and rec.args[1] in ("DEEP", "BRKCHP")
    ):  # NX: CYCLE/DRILL,DEEP,...
        kind = str(rec.args[1])
    if kind not in KINDS:
        raise NcppError(f"CYCLE/{kind or '?'}: ncpp posts the cycles {', '.join(KINDS)} and OFF", rec.where)
    values = _couplets(rec, rec.args[2:] if kind != words[0] else rec.args[1:])
    return Cycle(
        kind=kind,
        bottom=_bottom(rec, values),
        r_plane=_r_plane(rec, values),
        feed=next((_number(values, k) for k in FEEDS if k in values), None),
        per_rev=any(k in values for k in FEEDS if FEEDS[k]),
        step=_step(rec, kind, values),
        dwell=_dwell(rec, kind, values),
        to_start=_to_start(rec, values),
        record=rec,
        retract=_start_height(rec, values),
    )


def _couplets(rec: Record, args: tuple) -> dict[str, float | str]:
    """KEYWORD, value pairs; a keyword given twice with two values (a variable peck) is refused."""
    name = f"CYCLE/{rec.args[0]}"
    pairs = (*args, None) if len(args) % 2 else args
    values: dict[str, float | str] = {}
    for key, value in zip(pairs[::2], pairs[1::2], strict=True):
        if not isinstance(key, str):
            raise NcppError(f"{name}: a value {key:g} without its keyword: ncpp reads the keyword form "
                            "(DEPTH, d, MMPM, f, CLEAR, c, ...), not positional values",
                            rec.where)  # fmt: skip
        if key not in NUMBERS or not (isinstance(value, float) or (key, value) == ("RTRCTO", "AUTO")):
            shown = key if value is None else f"{key}, {value}"
            raise NcppError(f"{name}: {shown} is not followed by ncpp (it reads {', '.join(sorted(NUMBERS))} "
                            "with a number, and RTRCTO, AUTO)", rec.where)  # fmt: skip
        if values.get(key, value) != value:
            raise NcppError(f"{name}: {key} given twice ({values[key]}, {value}): "
                            "variable pecks are not posted",
                            rec.where)  # fmt: skip
        values[key] = value
    return values


def _number(values: dict[str, float | str], key: str) -> float | None:
    value = values.get(key)
    return value if isinstance(value, float) else None


def _bottom(rec: Record, values: dict[str, float | str]) -> float:
    depth, fedto = _number(values, "DEPTH"), _number(values, "FEDTO")
    if (depth is None) == (fedto is None):
        raise NcppError(f"CYCLE/{rec.args[0]}: expected the hole's depth as DEPTH, d or FEDTO, -d", rec.where)
    bottom = -depth if depth is not None else fedto
    assert bottom is not None
    if _solidworks(values):
        bottom = -bottom  # the depth below the point
    if not bottom < 0:
        raise NcppError(
            f"CYCLE/{rec.args[0]}: the hole's bottom is {bottom:g} from the cycle point, not below it",
            rec.where,
        )
    return bottom


def _r_plane(rec: Record, values: dict[str, float | str]) -> float:
    clear, rapto = _number(values, "CLEAR"), _number(values, "RAPTO")
    if "DEPTH" in values:  # Creo: RAPTO advances from the clearance towards the point
        return (clear or 0.0) - (rapto or 0.0)
    return rapto if rapto is not None else (clear or 0.0)


def _step(rec: Record, kind: str, values: dict[str, float | str]) -> float:
    step = _number(values, "STEP")
    if kind in ("DEEP", "BRKCHP"):
        if step is None or step <= 0:
            raise NcppError(
                f"CYCLE/{rec.args[0]}: a {kind} cycle needs its peck depth as STEP, s (above 0)", rec.where
            )
        return step
    if step is not None:
        raise NcppError(f"CYCLE/{rec.args[0]}: STEP in a {kind} cycle, which does not peck", rec.where)
    return 0.0


def _dwell(rec: Record, kind: str, values: dict[str, float | str]) -> float:
    dwell = _number(values, "DWELL")
    if dwell is None:
        return 0.0
    if KINDS[kind] not in DWELLING or dwell < 0:
        raise NcppError(f"CYCLE/{rec.args[0]}: a DWELL in a {kind} cycle is not posted", rec.where)
    return dwell


def _solidworks(values: dict[str, float | str]) -> bool:
    """SolidWorks CAM's form: FEDTO gives the hole's depth, above 0 (NX's FEDTO is below the point)."""
    fedto = _number(values, "FEDTO")
    return fedto is not None and fedto > 0


def _start_height(rec: Record, values: dict[str, float | str]) -> float | None:
    """SolidWorks CAM's RTRCTO, v other than the R plane: the start level's height above each hole."""
    level = _number(values, "RTRCTO")
    if level is None or not _solidworks(values) or abs(level - _r_plane(rec, values)) <= LEVEL_TOL:
        return None
    return level


def _to_start(rec: Record, values: dict[str, float | str]) -> bool:
    """G98 for RTRCTO, AUTO, Creo's RETURN, 0 and SolidWorks CAM's RTRCTO above the R plane (checked
    hole by hole against the start level); another retract level than the R plane is refused."""
    if values.get("RTRCTO") == "AUTO" or values.get("RETURN") == 0.0 or _start_height(rec, values):
        return True
    for key in ("RTRCTO", "RETURN"):
        level = _number(values, key)
        if level is not None and abs(level - _r_plane(rec, values)) > LEVEL_TOL:
            raise NcppError(f"CYCLE/{rec.args[0]}: {key}, {level:g} retracts elsewhere than the R plane "
                            f"({_r_plane(rec, values):g}) or the start level (AUTO): not posted",
                            rec.where)  # fmt: skip
    return False


@dataclass(frozen=True, slots=True)
class Hole:
    """One hole of a cycle, in program coordinates: what a generator writes as a canned cycle."""

    cycle: Cycle
    x: float
    y: float
    top: float  # the cycle point's Z (the hole's top)
    r: float  # the R plane's Z
    bottom: float  # the bottom's Z
    clear: float  # the Z the hole leaves the tool at (the R plane, or the start level)
    level: float  # the Z the tool crosses over to the hole at (rs274ngc: not below R, nor G98's start level)
    feed: float  # per minute
    series: bool  # it starts a series of the cycle (the canned cycle's words are all written)


@dataclass(slots=True, eq=True)
class HoleBlock(Block):
    """The block behind a hole's moves: the GOTO record, and the hole a generator writes for them."""

    hole: Hole | None = None


class Driller:
    """The holes of the `CYCLE/` under way and their moves, as rs274ngc moves a canned cycle
    (`ncpp.motion.interpreter` `_cycle`, G90, XY plane)."""

    def __init__(self, cycle: Cycle, start_z: float, inch: bool):
        self.cycle = cycle
        self.start_z = start_z  # the series' initial level (G98 retracts to it)
        self.last_r: float | None = None
        self.rapid_delta = RAPID_DELTA_INCH * (1.0 if inch else MM_PER_INCH)

    def hole(self, top: Point, pos: Point, feed: float, rpm: float | None) -> tuple[Hole, list[Move]]:
        """The hole at `top` drilled from `pos`: the Hole and its moves (x, y, z, rapid)."""
        cycle = self.cycle
        r, bottom = top[2] + cycle.r_plane, top[2] + cycle.bottom
        if not r > bottom:
            raise NcppError(
                f"CYCLE/{cycle.kind}: the R plane {r:g} is not above the hole's bottom {bottom:g}",
                cycle.record.where,
            )
        if cycle.retract is not None and abs(top[2] + cycle.retract - self.start_z) > LEVEL_TOL:
            raise NcppError(f"CYCLE/{cycle.kind}: RTRCTO, {cycle.retract:g} retracts to {top[2] + cycle.retract:g}, "
                            f"not to the level the cycle started from ({self.start_z:g}): not posted",
                            cycle.record.where)  # fmt: skip
        series = self.last_r is None or (cycle.to_start and r != self.last_r)
        if series and self.last_r is not None:  # G98 with another R: a new series from where the tool is
            self.start_z = pos[2]
        self.last_r = r
        moves: list[Move] = []
        level = self.start_z
        if level < r:
            moves.append((pos[0], pos[1], r, True))
            level = r
        else:
            level = max(pos[2], self.start_z if cycle.to_start else r)
        clear = level if cycle.to_start else r
        moves.append((top[0], top[1], level, True))
        if level != r:
            moves.append((top[0], top[1], r, True))
        moves += hole(float(cycle.code), top[0], top[1], r, clear, bottom, cycle.step, self.rapid_delta)
        return Hole(
            cycle, top[0], top[1], top[2], r, bottom, clear, level, self._feed(feed, rpm), series
        ), moves

    def _feed(self, feed: float, rpm: float | None) -> float:
        cycle = self.cycle
        if cycle.feed is None:
            if feed <= 0:
                raise NcppError(
                    f"CYCLE/{cycle.kind}: no feed rate (none in the record, no FEDRAT before)",
                    cycle.record.where,
                )
            return feed
        if not cycle.per_rev:
            return cycle.feed
        if not rpm:
            raise NcppError(f"CYCLE/{cycle.kind}: a feed per revolution and no spindle speed (SPINDL) before",
                            cycle.record.where)  # fmt: skip
        return cycle.feed * rpm


__all__ = ["Cycle", "Driller", "Hole", "HoleBlock", "KINDS", "parse_cycle"]
