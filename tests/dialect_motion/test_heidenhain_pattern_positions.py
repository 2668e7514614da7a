"""Klartext `PATTERN DEF` of single positions `POS1`-`POS9` called by `CYCL CALL PAT FMAX`: each
hole's X and Y written corrected, as a `CYCL CALL POS`'s are.

TNC 640 cycle programming manual, "Pattern definition PATTERN DEF", "Defining individual
machining positions": each POS gives a hole's X Y (and the surface Z) in the working plane; "Calling
a cycle with CYCL CALL PAT": the control goes to each hole in turn, FMAX or the given feed, and runs
the cycle there.  ncpp writes the PATTERN DEF again before the call, each POS's X Y corrected at the
height the tool is positioned at (as for M99 and CYCL CALL POS), and the program's own after it.

The judge is not ncpp: the written positions are read off the text here, and a machine file read
by `tests.compensation.closed_machine` (4x4 transforms written out by hand) says where the tool
lands for them; the written program is read back by the verifier as `process` writes it."""

from __future__ import annotations

import io
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from ncpp.motion.segments import DRILLED, PATTERN
from ncpp.summary import REASONS
from tests.compensation.closed_machine import ClosedMachine
from tests.conftest import ROOT, SHARED
from tests.dialect_motion.test_heidenhain_cycles import CYCLE_200, compensate, moves, program
from tests.writeback.test_compensated_holes import MACHINE, REVERSAL

# Scales on X Y Z and squareness of X-Y (C0Y) and X-Z (B0Z): a hole's X Y depend on its height
SCALES = MACHINE
HOLES = [(250.0, 180.0), (-120.0, 300.0), (310.0, -40.0), (25.0, -7.5)]
POSITIONS = "PATTERN DEF ~\n" + " ~\n".join(
    f"   POS{k} (X{x:+g} Y{y:+g} Z+0)" for k, (x, y) in enumerate(HOLES, 1)
)
# Cycle 200 (Q203=0, Q204=11) called from Z21: the first hole is reached at Z21, the others at the
# 2nd set-up clearance Q203 + Q204, where the cycle before leaves the tool
HEIGHTS = [21.0, 11.0, 11.0, 11.0]
AFTER = ["L  Z+21 FMAX", "L  X+0 Y+100 F500"]
_SHAPE = re.compile(r"POS\d+ \(X([-+.\d]+) Y([-+.\d]+) Z[-+.\d]+\)")


def written_positions(text: str) -> list[np.ndarray]:
    """The X Y of each PATTERN DEF's POS words in `text`, a list per PATTERN DEF, in order."""
    blocks = re.split(r"PATTERN DEF", text)[1:]
    return [np.array([[float(x), float(y)] for x, y in _SHAPE.findall(b.split("CYCL")[0])]) for b in blocks]


def landed_um(machine: ClosedMachine, positions: np.ndarray, heights: list[float]) -> np.ndarray:
    """µm the tool lands in X Y from each programmed hole, commanded to `positions` at `heights`."""
    commanded = np.column_stack([positions, heights])
    return np.linalg.norm(machine.tip(commanded)[:, :2] - np.array(HOLES), axis=1) * 1000


def test_each_position_lands_on_its_hole_at_the_height_the_tool_is_positioned_at(tmp_path: Path):
    """Uncompensated the holes land 1.9-18.9 µm off; written corrected, under 0.1 µm (the 4th decimal)."""
    machine_path = tmp_path / "scales.toml"
    machine_path.write_text(SCALES)
    machine = ClosedMachine.read(machine_path)
    text = program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX M13"], AFTER)
    written, stats = compensate(text, SCALES)
    before, corrected, again = written_positions(written)
    assert np.array_equal(before, np.array(HOLES)) and np.array_equal(again, before)  # the program's own
    uncompensated, compensated = landed_um(machine, before, HEIGHTS), landed_um(machine, corrected, HEIGHTS)
    assert uncompensated.min() > 1.0 and uncompensated.max() > 15.0
    assert compensated.max() < 0.1
    print("µm before", uncompensated.round(2), "after", compensated.round(3))
    assert REASONS[PATTERN] not in stats.summary.left
    call = written.index("CYCL CALL PAT FMAX M13")  # (between the corrected PATTERN DEF and the program's)
    assert (
        written.rindex("PATTERN DEF", 0, call) > written.index("PATTERN DEF")
        and "PATTERN DEF" in written[call:]
    )
    # read back: the cycle runs where the written PATTERN DEF puts each hole, its moves along Z as programmed
    drilled = [m for m in moves(written) if m.fixed == DRILLED and not m.rapid]
    assert [m.end[:2] for m in drilled] == [tuple(p) for p in corrected.tolist()]
    assert [m.end[2] for m in drilled] == [-6.0] * len(HOLES)


@pytest.mark.parametrize("machine", [SCALES, REVERSAL], ids=["scales", "reversals"])
def test_a_second_call_of_the_same_pattern_gets_its_own_corrections(machine):
    """The pattern called again by another cycle from Z30 (its 2nd set-up clearance 20): each call
    gets its PATTERN DEF corrected where it runs (with SCALES' squareness B0Z, X moves with the
    height), and the program's is back after each.  With reversal errors too, the verifier reads it back."""
    again = ["CYCL DEF 200 DRILLING ~\n  Q200=+2 ~\n  Q201=-10 ~\n  Q206=+50 ~\n  Q202=+10 ~\n  Q210=+0 ~\n"
             "  Q203=+0 ~\n  Q204=+20 ~\n  Q211=+0", "L  Z+30 FMAX", "CYCL CALL PAT FMAX"]  # fmt: skip
    text = program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX M13", *again], AFTER)
    written, stats = compensate(text, machine)
    patterns = written_positions(written)
    assert len(patterns) == 5 and all(np.array_equal(patterns[k], np.array(HOLES)) for k in (0, 2, 4))
    assert np.abs(patterns[1] - patterns[0]).max() > 0.001 and np.abs(patterns[3] - patterns[0]).max() < 0.02
    assert (machine is REVERSAL) or not np.array_equal(patterns[3], patterns[1])
    assert REASONS[PATTERN] not in stats.summary.left


@pytest.mark.parametrize(
    ("pattern", "call"),
    [
        ("POS1 (X+250 Y+180 Z+0) ~\n   POS2 (X+Q7 Y+300 Z+0)", "CYCL CALL PAT FMAX"),  # a Q parameter
        ("POS1 (X+250 Y+180 Z+0) ~\n   ROW1 (X+10 Y+5 D+8 NUM4 ROT+0 Z+0)", "CYCL CALL PAT FMAX"),
        ("CIRC1 (X+50 Y+20 D40 START+30 NUM6 Z+0)", "CYCL CALL PAT FMAX"),
        ("POS1 (X+250 Y+180 Z+0) ~\n   POS2 (X-120 Y+300 Z+0)", "CYCL CALL PAT F500"),  # a feed between holes
    ],
)
def test_other_patterns_are_drilled_where_the_pattern_puts_them(pattern, call):
    text = program(CYCLE_200, ["Q7 = -120", f"PATTERN DEF ~\n   {pattern}", call], AFTER)
    written, stats = compensate(text, SCALES)
    assert written.count("PATTERN DEF") == 1 and pattern in written
    assert list(stats.summary.left) == [REASONS[PATTERN]]
    assert [m.end[:2] for m in moves(written) if m.fixed == PATTERN] == [
        m.end[:2] for m in moves(text) if m.fixed == PATTERN
    ]


def test_a_feed_call_after_a_corrected_one_runs_the_programs_positions():
    """The PATTERN DEF written after the corrected call puts the program's holes back for a call
    left as programmed (here at F500)."""
    text = program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX", "CYCL CALL PAT F500"], AFTER)
    written, stats = compensate(text, SCALES)
    assert REASONS[PATTERN] in stats.summary.left
    fed = [m.end[:2] for m in moves(written) if m.fixed == PATTERN and m.end[2] == -6.0]
    assert fed == HOLES


def test_a_pattern_stays_as_programmed_when_it_is_not_called():
    written, _ = compensate(program(CYCLE_200, [POSITIONS], AFTER), SCALES)
    assert written.count("PATTERN DEF") == 1


def test_the_holes_read_back_where_moves_reports_them():
    """`moves` of the input: the move to each hole in the plane is compensated (not fixed), the
    cycle's along Z is DRILLED, and the PATTERN DEF's call leaves X Y known after it."""
    found = moves(program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX"], AFTER), io.StringIO())
    plane = [m for m in found if m.end[:2] in HOLES and m.start[:2] != m.end[:2] and m.start[2] > 0]
    assert [m.end[:2] for m in plane] == HOLES and not any(m.fixed for m in plane)
    assert not found[-1].fixed


WIDE = SHARED / "machines" / "wide.toml"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_the_command_line_writes_the_corrected_pattern_and_warns_once_for_the_call(tmp_path: Path):
    """On the shared wide machine, verified as written: one warning for the call's drilling moves
    along Z, none for a hole pattern."""
    source, out = tmp_path / "positions.h", tmp_path / "out.h"
    source.write_text(program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX M13"], AFTER))
    proc = subprocess.run([sys.executable, "-m", "ncpp", "compensate", "--machine", str(WIDE), str(source),
                           "-o", str(out)], capture_output=True, cwd=ROOT)  # fmt: skip
    said = proc.stderr.decode()
    assert proc.returncode == 0, said
    assert said.count("warning: drilling cycle:") == 1 and "hole pattern" not in said
    patterns = written_positions(out.read_text())
    assert len(patterns) == 3 and not np.array_equal(patterns[1], patterns[0])


@pytest.mark.parametrize("skipped", ["PATTERN DEF", "CYCL CALL PAT"])
def test_a_skippable_pattern_or_call_stays_as_programmed(skipped: str):
    """Block skip `/`: the PATTERN DEFs written around the call would run whatever the operator sets."""
    text = program(CYCLE_200, [POSITIONS, "CYCL CALL PAT FMAX"], AFTER)
    text = re.sub(rf"^(\d+  {skipped})", r"/ \1", text, flags=re.MULTILINE)
    assert "/ " in text
    written, stats = compensate(text, SCALES)
    assert written.count("PATTERN DEF") == 1 and REASONS[PATTERN] in stats.summary.left
