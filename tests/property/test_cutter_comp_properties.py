"""Cutter compensation against LinuxCNC's rs274 on random programs (hypothesis).

Random lines, arcs, rapids and Z moves mixed with G40-G42.1, unit, mode, system,
offset, cycle and tool words, run by rs274 and by ncpp's interpreter with the same
tool table: both accept, and the moves outside compensation agree (`without_comp`),
or both refuse, with the same message.  rs274's gouging refusals are the one
difference allowed: they need the tool centre's path, which the interpreter does not make.

Random contours under G41.1/G42.1 that rs274 runs: the tool centre's path ncpp makes of them
(`on_centre`, what `ncpp motion`, `ncpp simulate` and the verifier follow) is rs274's, call for call.
"""

from __future__ import annotations

import io
from dataclasses import replace

import pytest
from hypothesis import given
from hypothesis import strategies as st

from ncpp.errors import Warnings
from ncpp.motion import interpret
from ncpp.motion.canon import canon_call, read_canon
from ncpp.motion.centre_path import on_centre
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.tools import ToolTable
from ncpp.program.parser import parse_stream
from tests import rs274 as oracle
from tests.conftest import RS274
from tests.motion.test_oracle import (
    oracle_settings,
    ours,
    refused_alike,
    rs274_error,
    run_rs274,
    same_calls,
    tool_table,
    without_comp,
)

coordinate = st.integers(-40_000, 40_000).map(lambda n: f"{n / 1000:g}")
line = st.builds(lambda g, x, y: f"G{g} X{x} Y{y}", st.sampled_from([0, 1, 1]), coordinate, coordinate)
arc = st.builds(
    lambda g, x, y, r: f"G{g} X{x} Y{y} R{r / 1000:g}",
    st.sampled_from([2, 3]),
    coordinate,
    coordinate,
    st.integers(30_000, 60_000),
)
plunge = st.integers(-3_000, 3_000).map(lambda n: f"G1 Z{n / 1000:g}")
codes = st.sampled_from([
    "G41.1 D0", "G41.1 D2", "G41.1 D10", "G42.1 D2", "G42.1 D6", "G41 D1", "G42", "G40", "G40",
    "G20", "G21", "G91", "G90", "G55", "G54", "G64", "M6 T1", "G43 H1", "G92 X0", "G28", "G53 G0 X0",
    "G81 X1 Y1 Z-1 R1", "G80", "G18", "G17", "G4 P0.1", "M3 S100",
])  # fmt: skip
programs = st.lists(st.one_of(line, line, arc, plunge, codes), min_size=3, max_size=25).map(
    lambda body: "G21 G90 G17 G94 G64\nG0 X0 Y0 Z5\nG1 Z-1 F100\n" + "\n".join(body) + "\nG40\nG0 Z5\nM2\n"
)


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
@oracle_settings
@given(programs)
def test_cutter_compensation_agrees_with_rs274(tmp_path, text):
    path = tmp_path / "comp.ngc"
    path.write_text(text)
    calls, messages = run_rs274(path)
    refused = rs274_error(messages)
    if refused is not None and "gouging" in refused[0]:
        return
    # rs274's stand-alone machine is in inches: its tool table's D too
    offsets = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=ToolTable.from_file(tool_table(), unit_mm=25.4))
    off_path: list[bool] = []
    mine, error, warned = ours(path, off_path, offsets)
    if "outside the motion interpreter's scope" in warned:
        return  # (an arc in G18 with R, ...: compared by the corpus oracle, not here)
    if refused_alike(refused, error):
        return
    theirs, kept = without_comp(read_canon(calls), mine, off_path)
    assert len(theirs) == len(kept) and same_calls(theirs, kept), (theirs, kept)


# the contours: entered from X-50 Y-50 with a radius of 1, 3 or 5 mm on either side; lines, arcs and Z
# moves (which rs274 holds with the move before an inside corner); left by G40 and a line
contour = st.lists(st.one_of(line.filter(lambda m: m.startswith("G1")), arc, plunge), min_size=3, max_size=12)
contours = st.builds(
    lambda side, first, body: (
        "G21 G90 G17 G94 G64\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG0 X-50 Y-50\n"
        + f"{side}\n{first}\n"
        + "\n".join(body)
        + "\nG40\nG1 X-50 Y-50\nG0 Z5\nM2\n"
    ),
    st.sampled_from(["G41.1 D2", "G42.1 D2", "G41.1 D6", "G42.1 D10"]),
    line.filter(lambda m: m.startswith("G1")),
    contour,
)


@pytest.mark.skipif(not RS274.exists(), reason="rs274 oracle not available")
@oracle_settings
@given(contours)
def test_the_tool_centre_path_is_rs274s(tmp_path, text):
    path = tmp_path / "contour.ngc"
    path.write_text(text)
    done = oracle.run(path, digits=7, home=tmp_path, timeout=120)
    if oracle.messages(done):  # (a gouge, an entry too short, a tool too big for an arc: rs274's refusals)
        return
    theirs = read_canon(done.stdout)
    with path.open("rb") as stream:
        events = list(
            interpret(
                parse_stream(stream, str(path)), file=str(path), warnings=Warnings(stream=io.StringIO())
            )
        )
    mine = [call for call in map(canon_call, on_centre(events)) if call is not None]
    assert [c.name for c in mine] == [c.name for c in theirs], (mine, theirs)
    for a, b in zip(mine, theirs):
        assert max(abs(x - y) for x, y in zip(a.args, b.args)) < 1e-5, (a, b)
