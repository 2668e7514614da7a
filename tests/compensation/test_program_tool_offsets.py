"""Tool offsets a program sets itself, which the next G43 applies as if the tool table said them.

LinuxCNC (G-code manual, "G10 L1 Set Tool Table", "G10 L10 Set Tool Table", "G10 L11 Set Tool
Table"): `G10 L1 P<tool>` writes the given offsets into the tool table, L10 sets them so that the
current point, with the work offsets in effect, reads the given values, L11 as if G59.3 were in
effect; the offset in effect changes only at the next G43.  LinuxCNC's rs274 judges it, call by call.

Fanuc (Series 16i/18i-PA operator's manual B-63124EN/01, 15.3 "Tool compensation values ... entering
values from the program (G10)": `G10 L11 P_ R_`, R set in G90 and added in G91; the Fanuc-style
"G10: Programmable data input": L10 the H offsets' geometry, L11 their wear, L12 L13 the D offsets';
memory C keeps them apart, Series 0i Connection Manual B-63833EN-1/02, 10 "Tool compensation memory
C") and Haas ("G10 Set Offsets": L10 the length offset, L1 or L11 its wear, L12 L13 the diameter's):
G43 Hn applies geometry plus wear.
"""

from __future__ import annotations

import io
import re
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.tools import ToolTable
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program
from tests import rs274
from tests.compensation.conftest import events_of

# The stand-alone rs274 reads its tool table in inches: tool 1 50.8 mm, tool 2 114.3 mm, tool 3 25.4 mm
TABLE = "T1 P1 Z2.0 D0.25 ;end mill\nT2 P2 Z4.5 D0.2 ;drill\nT3 P3 Z1.0 ;probe\n"
# Each form of G10 L1/L10/L11, the offset in effect before and after the G43 that applies it
SET_BY_PROGRAM = """G21 G90
G10 L2 P1 X10 Y20 Z30
G10 L2 P9 X1 Y2 Z3
G54
T1 M6
G43 H1
G0 X1 Y2 Z5
G10 L1 P1 Z100
G1 Z4 F100
G43
G1 Z3
G10 L1 P2 X0.5 Z80 R3
G43.2 H2
G1 X5 Z2
G92 X0 Y0 Z0
G10 L10 P3 Z1
G10 L11 P2 X1 Z-1
T3 M6 G43
G1 X3 Z-2
G43 H2
G1 Y4
G49
G20
G10 L1 P1 Z4
G43 H1
G1 Z1
G49
G1 Z0.5
M2
"""


def _table(tmp_path: Path, text: str = TABLE) -> ToolTable:
    path = tmp_path / "tool.tbl"
    path.write_text(text)
    return ToolTable.from_file(path, 25.4)


def _told(tmp_path: Path, text: str = TABLE) -> WorkOffsets:
    return replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=_table(tmp_path, text))


_CALL = re.compile(r"(USE_LENGTH_UNITS|USE_TOOL_LENGTH_OFFSET|STRAIGHT_TRAVERSE|STRAIGHT_FEED)\(([^)]*)\)")


def _rs274_moves(calls: str) -> list[tuple[tuple[float, ...], tuple[float, ...]]]:
    """rs274's moves: (end point, the tool offset X Y Z in effect in mm)."""
    unit, tool, out = 1.0, (0.0, 0.0, 0.0), []
    for name, args in _CALL.findall(calls):
        values = [float(v) for v in re.split(r"[,\s]+", args.strip()) if v and v[0] in "-0123456789"]
        if name == "USE_LENGTH_UNITS":
            unit = 25.4 if "INCHES" in args else 1.0
        elif name == "USE_TOOL_LENGTH_OFFSET":
            tool = tuple(v * unit for v in values[:3])
        else:
            out.append((tuple(values[:3]), tool))
    return out


def _ncpp_moves(program: str, offsets: WorkOffsets) -> list[tuple[tuple[float, ...], tuple[float, ...]]]:
    lines = [e for e in events_of(program.encode(), offsets=offsets) if type(e).__name__ == "Line"]
    return [(e.end, e.context.tool_mm) for e in lines]


def test_g10_l1_l10_l11_set_the_offsets_rs274_applies_at_the_next_g43(tmp_path):
    var, program = tmp_path / "sim.var", tmp_path / "p.ngc"
    var.write_text("5220 1.0\n")
    program.write_text(SET_BY_PROGRAM)
    want = _rs274_moves(rs274.calls_from(var, program, TABLE))
    got = _ncpp_moves(SET_BY_PROGRAM, _told(tmp_path))
    assert (
        len(got) == len(want) == 8
    )  # (G49 before G20: rs274 keeps a tool offset's X through G20 unconverted)
    for (end, tool), (rs274_end, rs274_tool) in zip(got, want):
        assert end == pytest.approx(rs274_end, abs=1e-4)
        assert tool == pytest.approx(rs274_tool, abs=1e-3)
    lengths = [tool[2] for _, tool in got]
    assert lengths[0] == lengths[1] == pytest.approx(50.8)  # G10 L1 alone applies nothing
    assert lengths[2] == 100.0 and lengths[3] == pytest.approx(180.0)  # G43, then G43.2 H2 adds tool 2's 80
    assert lengths[6] == pytest.approx(101.6) and lengths[7] == 0.0  # G10 L1 in G20: 4 inches


@pytest.mark.parametrize(
    "line, message",
    [
        ("G10 L1 P0 Z1", "P value out of range with G10 L1"),
        ("G10 L10 P0 Z1", "P value out of range with G10 L10"),
        ("G10 L1 P7 Z1", "Requested tool 7 not found in the tool table"),
        ("G10 L11 P2", "G10 L1 without offsets has no effect"),  # (rs274 says L1 for each L)
    ],
)
def test_rs274_and_ncpp_refuse_the_same_g10(tmp_path, line, message):
    program = tmp_path / "p.ngc"
    program.write_text(f"G21\nG0 Z1\n{line}\nM2\n")
    table = tmp_path / "tools.tbl"
    table.write_text(TABLE)
    done = rs274.run(program, tool_table=table, timeout=60)
    if not rs274.ran(done):
        pytest.skip(f"rs274 oracle did not run: {done.stderr.strip()[:200]}")
    refused = rs274.error(done.stderr)
    assert refused is not None and refused[0] == message
    with pytest.raises(NcppError, match=rf"<test>:3:\d+: {message}$"):
        events_of(program.read_bytes(), offsets=_told(tmp_path))


@pytest.mark.parametrize(
    "program, reason",
    [
        ("G10 L10 P1 Z5\n", "G10 L10 after Z no move has put at a known position"),
        ("G0 X0 Y0\nG10 L11 P1 X1 Z5\n", "G10 L11 after Z no move has put at a known position"),
        ("G0 X0 Y0 Z5\nG10 L10 P1 A5\n", "G10 L10 of an axis other than X Y Z"),
        ("G0 X0 Y0 Z5\nG10 L2 P1 R30\nG10 L10 P1 Z5\n", "G10 L10 under a coordinate system rotation"),
        ("G0 X0 Y0 Z5\nG41.1 D2 G1 X10 F100\nG10 L10 P1 Z5\n", "G10 L10 under cutter compensation"),
        ("G0 X0 Y0 Z5\no1 repeat [2]\nG10 L10 P1 Z5\no1 endrepeat\n", "G92 or G10 L10/L11/L20 in a loop"),
        ("G0 X0 Y0 Z5\nT1 M6 G43\nG10 L10 P1 Z5\n", "G10 L10 after a tool change"),
    ],
)
def test_what_cannot_be_followed_ends_interpretation_naming_the_line(tmp_path, program, reason):
    said = io.StringIO()
    from ncpp.motion import interpret
    from ncpp.program.parser import parse_stream

    text = f"G21 G90\n{program}G1 X50 F100\nM2\n".encode()
    events = list(interpret(parse_stream(io.BytesIO(text), "t.ngc"), file="t.ngc",
                            warnings=Warnings(stream=said), offsets=_told(tmp_path)))  # fmt: skip
    line = next(n for n, text_line in enumerate(text.decode().splitlines(), 1) if "G10 L1" in text_line)
    assert said.getvalue().startswith(f"t.ngc:{line}:"), said.getvalue()
    assert reason in said.getvalue()
    assert not any(type(e).__name__ == "Line" and e.block.line > line for e in events)


def test_grbl_has_no_tool_table_to_set():
    from ncpp.motion.grbl import interpret

    said = io.StringIO()
    from ncpp.program.parser import parse_stream

    list(interpret(parse_stream(io.BytesIO(b"G21\nG10 L1 P1 Z5\nG0 X1\n"), "g.nc"), file="g.nc",
                   warnings=Warnings(stream=said)))  # fmt: skip
    assert "g.nc:2:1: warning: tool table change G10 L1/L10/L11 is outside" in said.getvalue()


def test_without_a_table_a_length_the_program_sets_is_known_and_others_are_warned(tmp_path):
    said = io.StringIO()
    from ncpp.motion import interpret
    from ncpp.program.parser import parse_stream

    text = b"G21 G90\nG10 L1 P4 Z75\nT4 M6 G43\nG0 Z10\nT5 M6 G43\nG0 Z10\nM2\n"
    events = list(interpret(parse_stream(io.BytesIO(text), "t.ngc"), file="t.ngc", warnings=Warnings(stream=said),
                            offsets=WorkOffsets.at((0.0, 0.0, 0.0))))  # fmt: skip
    lengths = [e.context.tool_mm[2] for e in events if type(e).__name__ == "Line"]
    assert lengths == [75.0, 0.0]
    assert said.getvalue().startswith(
        "t.ngc:5:7: warning: G43 applies a tool length from the control's tool table"
    )


def test_g10_l1_r_and_q_are_the_radius_and_orientation_g41_then_offsets_by(tmp_path):
    """rs274 offsets the path by G10 L1's R (10 - 1.5: STRAIGHT_FEED(8.5, 1.5, ...)); a lathe tool's
    orientation Q leaves the moves under G41 as programmed, as the table's Q does."""
    told = _told(tmp_path, "T1 P1 Z2 D0.25\n")
    program = b"G21 G90\nT1 M6\nG10 L1 P1 R1.5\nG0 X0 Y0 Z0\nG41 G1 X10 F100\nG1 Y10\nG40 G0 X20\n"
    lathe = b"G18\nG10 L1 P1 Q2\nG41 G1 X10 Z-5\nG1 X0\nG40 G0 X-10\nM2\n"
    lines = [e for e in events_of(program + lathe, offsets=told) if type(e).__name__ == "Line"]
    assert lines[2].centre_shift[0] == pytest.approx((0.0, 1.5, 0.0))  # off the path by R, to the left
    assert [e.fixed for e in lines[4:]] == ["cutter compensation"] * 3


# -- Fanuc and Haas: tool offset memory ------------------------------------------------------


def _dialect_moves(dialect: str, text: str, offsets: WorkOffsets, said: io.StringIO | None = None) -> list:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "f.nc", dialect)
    warnings = Warnings(stream=said or io.StringIO())
    events = interpret(blocks, file="f.nc", warnings=warnings, offsets=offsets)
    return [e for e in events if type(e).__name__ in ("Line", "Arc")]


G54 = (400.0, 350.0, 300.0)
# The H offset's geometry and wear, set and then added to, and a D offset's
FANUC = """O1000
G90 G10 L10 P1 R-150.
G10 L11 P1 R0.05
G91 G10 L11 P1 R-0.02
G91 G10 L10 P1 R0.5
G90 G10 L12 P1 R5.
G54 T1 M6
G00 G43 H1 Z50.
G00 X10. Y0.
G41 D1 G01 X20. F100.
G01 Y10.
G40 G00 X30.
M30
"""


def test_fanuc_g43_applies_geometry_plus_wear_as_g10_l10_l11_set_them(tmp_path):
    offsets = replace(WorkOffsets.at(G54), tools=_table(tmp_path, "T1 P1 Z4.0 D0.5\n"))
    moves = _dialect_moves("fanuc", FANUC, offsets)
    length = -150.0 + 0.5 + 0.05 - 0.02  # geometry set, then added to; wear set, then added to
    assert moves[0].context.tool_mm[2] == pytest.approx(length)
    assert moves[0].context.to_machine(moves[0].end)[2] == pytest.approx(300.0 + 50.0 + length)
    under_comp = [m for m in moves if m.centre_shift is not None]
    assert under_comp[0].centre_shift[1] == pytest.approx((0.0, 5.0, 0.0))  # G10 L12's radius


def test_fanuc_wear_alone_is_out_of_scope_and_haas_reads_it_as_wear(tmp_path):
    offsets = replace(WorkOffsets.at(G54), tools=_table(tmp_path, "T1 P1 Z4.0\n"))
    program = "O1000\nG90 G10 L11 P1 R0.05\nT1 M6\nG00 G43 H1 Z50.\nG00 X10.\nM30\n"
    said = io.StringIO()
    assert _dialect_moves("fanuc", program, offsets, said) == []
    assert said.getvalue().startswith(
        "f.nc:2:9: warning: G10 L11 of H offset 1, whose geometry the program has not set"
    )
    for wear in ("L11", "L1"):
        haas = _dialect_moves("haas", program.replace("L11", wear), offsets)
        assert haas[0].context.tool_mm[2] == pytest.approx(101.6 + 0.05)  # the table's length, its wear added


def test_fanuc_g10_l10_of_an_offset_the_table_lacks_and_in_inches(tmp_path):
    offsets = replace(WorkOffsets.at(G54), tools=_table(tmp_path, "T1 P1 Z4.0\n"))
    program = "O1000\nG20\nG90 G10 L10 P7 R-6.\nT1 M6\nG00 G43 H7 Z2.\nG00 X1.\nM30\n"
    moves = _dialect_moves("fanuc", program, offsets)
    assert moves[0].context.tool_mm[2] == pytest.approx(-6.0 * 25.4)
    said = io.StringIO()
    assert _dialect_moves("fanuc", program.replace("R-6.", "X1. R-6."), offsets, said) == []
    assert "G10 L10 with other words than P and R" in said.getvalue()


# -- compensated with the lengths the program sets -------------------------------------------------

Z_AXIS = Path(__file__).resolve().parents[1] / "machines" / "metrology" / "z_axis.toml"
# A tool setter's lengths at the program's top: tool 1 is 200 mm long (the table says 50.8 mm); tool 2,
# at Z25 on its gauge block, is set to read Z40 there (the table says 114.3 mm long: then 99.3 mm)
SETTER = """G21 G90 G17 G94 G40 G49 G80 G64
G10 L2 P1 X0 Y0 Z-300
G54
T1 M6
G10 L1 P1 Z200
G43 H1
G0 X-300 Y-200 Z10
G1 Z-2 F400
G1 X300
G3 X350 Y-150 I0 J50
G1 Y150
G1 X-300 Y200
G1 Y-200
G0 Z10
T2 M6
G43 H2
G0 X0 Y0 Z25
G10 L10 P2 Z40
G43 H2
G1 Z-2 F300
G1 X200 Y100
G2 X300 Y0 I0 J-100
G1 X-200
G0 Z40
M2
"""
SET_LINE = "G10 L1 P1 Z200\n"


def _compensate(tmp_path: Path, name: str, text: str, *options: str) -> tuple[Path, Path]:
    from tests.compensation.test_machine_files import ncpp

    program, tools, out = tmp_path / f"{name}.ngc", tmp_path / "tools.tbl", tmp_path / f"{name}.out.ngc"
    program.write_text(text)
    tools.write_text(TABLE)
    done = ncpp("compensate", "--machine", Z_AXIS, "--tool-table", tools, "--var-units", "inch",
                "--tolerance", "0.0002", *options, program, "-o", out)  # fmt: skip
    assert done.returncode == 0 and "warning" not in done.stderr, done.stderr
    return program, out


def test_the_abbe_arm_is_compensated_at_the_length_the_program_sets(tmp_path):
    """The setter program on the z-axis machine (its errors move with the Z position, which the length moves), its tool paths from rs274 (the tool lengths too)
    mapped through the closed-form machine: ncpp's output lands within 0.5 µm of the original's path;
    compensated at the table's length (the G10 L1 left out, then put back for the control), the tool
    whose length the program set misses it by more.  rs274 runs the output to its end: the tool
    guard after each G43 finds the length the program set."""
    from tests.compensation.closed_machine import ClosedMachine
    from tests.compensation.test_machine_files import worst_um
    from tests.compensation.tool_centre import feed_moves

    machine, tools = ClosedMachine.read(Z_AXIS), tmp_path / "tools.tbl"
    program, out = _compensate(tmp_path, "setter", SETTER)
    written = out.read_text()
    assert written.count("(ncpp tool guard:") == 3  # (in the table's inches: 200 mm and 99.3 mm)
    assert "tool 1 at length Z7.874 inch" in written and "tool 2 at length Z3.9094 inch" in written
    _, table_length = _compensate(tmp_path, "table", SETTER.replace(SET_LINE, ""), "--no-guard")
    table_length.write_text(table_length.read_text().replace("G43 H1\n", SET_LINE + "G43 H1\n", 1))
    original = feed_moves(program, tools, home=tmp_path)
    assert {round(float(m.tool[2]), 3) for m in original} == {200.0, 99.3}
    before, after, at_table = (worst_um(original, feed_moves(p, tools, home=tmp_path), machine)
                               for p in (program, out, table_length))  # fmt: skip
    print(f"residuals: before {before:.3f} µm, after {after:.3f} µm, at the table's length {at_table:.3f} µm")
    assert before > 3.0 and after <= 0.5 and at_table > 2.0, (before, after, at_table)


def test_pathcheck_passes_the_output_with_the_lengths_the_program_sets(tmp_path):
    program, out = _compensate(tmp_path, "setter", SETTER)
    rs274.pathcheck(program, out, "--tool-table", str(tmp_path / "tools.tbl"))


# A square run counter-clockwise with the tool outside it (G42), its D offset set by G10 L12 (geometry)
# and L13 (wear, set, then added to in G91): a radius of 5 - 0.1 + 0.02 = 4.92 mm, where the table's
# tool 1 is 12.7 mm across
D_SET = """O1000
G21 G90 G17 G54
G90 G10 L12 P1 R5.
G10 L13 P1 R-0.1
G91 G10 L13 P1 R0.02
G90 G0 X-20. Y0 Z5.
G1 Z-1. F200.
G42 D1 G1 X0 Y0 F300.
G1 X40.
G1 Y30.
G1 X0
G1 Y0
G40 G0 X-20. Y-20.
M30
"""
# The same for LinuxCNC, the radius given by G10 L1 R
D_SET_TWIN = """G21 G90 G17 G54
G10 L1 P1 R4.92
T1 M6
G0 X-20. Y0 Z5.
G1 Z-1. F200.
G42 G1 X0 Y0 F300.
G1 X40.
G1 Y30.
G1 X0
G1 Y0
G40 G0 X-20. Y-20.
M2
"""


def _centres(moves: list) -> list[tuple[float, ...]]:
    """Where the tool centre stands at the end of each move under cutter compensation."""
    return [tuple(np.add(m.end, m.centre_shift[1])) for m in moves if m.centre_shift is not None]


def test_fanuc_g41_g42_offset_by_the_radius_g10_l12_l13_set_as_rs274_by_g10_l1_r(tmp_path):
    """Fanuc: D offset 1 is geometry plus wear of memory C, a radius (`FanucInterpreter._set_d_offset`);
    rs274 offsets its twin by G10 L1's R: the tool centre at each move's end is one of its points."""
    offsets = replace(WorkOffsets.at((0.0, 0.0, 0.0)), tools=_table(tmp_path, "T1 P1 Z0 D0.5\n"))
    centres = _centres(_dialect_moves("fanuc", D_SET, offsets))
    table = tmp_path / "rs274.tbl"
    table.write_text("T1 P1 Z0 D0.5\n")
    done = rs274.run(D_SET_TWIN, tool_table=table, digits=7)
    assert done.returncode == 0, done.stderr
    reference = rs274.end_points(done.stdout)
    assert len(centres) == 6 and (40.0, -4.92, -1.0) in [tuple(np.round(c, 9)) for c in centres]
    for centre in centres:
        assert np.min(np.abs(np.subtract(reference, centre)).max(axis=1)) < 1e-6, (centre, reference)


@pytest.mark.parametrize(
    "dialect, setting",
    [
        ("haas", "G90 G10 L12 P1 R5."),  # (Haas's D offset is named a diameter)
        ("fanuc", "G90 G10 L12 P1 R-5."),  # (a negative radius swaps G41 and G42 on a Fanuc)
        ("fanuc", "G90 G10 L13 P1 R0.1"),  # (wear alone, no geometry told)
    ],
)
def test_a_d_offset_set_to_a_radius_ncpp_does_not_know_leaves_the_moves_on_their_points(dialect, setting):
    program = D_SET.replace("G90 G10 L12 P1 R5.\nG10 L13 P1 R-0.1\nG91 G10 L13 P1 R0.02\n", setting + "\n")
    centres = _centres(_dialect_moves(dialect, program, WorkOffsets.at((0.0, 0.0, 0.0))))
    assert centres[:-1] == [(0.0, 0.0, -1.0), (40.0, 0.0, -1.0), (40.0, 30.0, -1.0), (0.0, 30.0, -1.0),
                            (0.0, 0.0, -1.0)]  # fmt: skip


def test_fanuc_g10_l12_radius_is_compensated_without_the_unknown_radius_warning(tmp_path):
    from tests.writeback.conftest import compensate_file
    from tests.writeback.test_compensated_holes import MACHINE

    for dialect, warned in (("fanuc", False), ("haas", True)):
        (tmp_path / "p.nc").write_text(D_SET)
        said = io.StringIO()
        output = compensate_file(tmp_path / "p.nc", MACHINE, tmp_path, warnings=Warnings(stream=said),
                                 dialect=dialect)  # fmt: skip
        assert ("tool radius not known" in said.getvalue()) == warned, said.getvalue()
        assert output.read_text() != D_SET
