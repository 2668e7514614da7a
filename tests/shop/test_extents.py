"""`ncpp extents`: the box a program's moves sweep, judged against boxes computed by hand."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ncpp.cli import main

ROOT = Path(__file__).resolve().parents[2]
HR5B = ROOT / "samples" / "machines" / "hr5b.toml"  # [limits] X 0..800, Y 0..700, Z 0..700

# G54 with tool 1: a clockwise half circle from X0 to X20 about X10, bulging to Y10 (its end
# points both lie on Y0); G55 with tool 2: a rapid to X10 Y10 and a cut to X30 at Z-2.
PROGRAM = """G21 G17 G90
T1 M6
G54
G0 X0 Y0 Z5
G1 Z-1 F100
G2 X20 Y0 I10 J0
G0 Z5
T2 M6
G55
G0 X10 Y10
G1 Z-2
G1 X30
M2
"""


def extents(tmp_path: Path, capsys, *options: str, text: str = PROGRAM, suffix: str = ".ngc") -> dict:
    program = tmp_path / f"part{suffix}"
    program.write_text(text)
    assert main(["extents", str(program), "--format", "json", *options]) == 0
    return json.loads(capsys.readouterr().out)


def box(x: tuple[float, float], y: tuple[float, float], z: tuple[float, float]) -> dict:
    return {"X": list(x), "Y": list(y), "Z": list(z)}


def by(groups: list[dict], key: str) -> dict:
    return {g[key]: g for g in groups}


def test_boxes_per_work_offset_and_tool_in_program_coordinates(tmp_path, capsys):
    report = extents(tmp_path, capsys)
    assert report["all"]["program_mm"] == box((0, 30), (0, 10), (-2, 5))
    systems = by(report["work_offsets"], "name")
    assert systems["G54"]["program_mm"] == box(
        (0, 20), (0, 10), (-1, 5)
    )  # Y10: the arc's top, not an end point
    assert systems["G55"]["program_mm"] == box((10, 30), (10, 10), (-2, 5))
    assert systems["G55"]["lines"] == [10, 12]
    tools = by(report["tools"], "tool")
    assert tools["1"]["program_mm"] == systems["G54"]["program_mm"]
    assert tools["2"]["program_mm"] == systems["G55"]["program_mm"]
    assert (
        report["all"]["machine_mm"] is None and report["all"]["moves_zero_unknown"] == 7
    )  # nobody said the zeros


def test_machine_boxes_and_travel(tmp_path, capsys):
    report = extents(tmp_path, capsys, "--work-offset", "G54=100,200,300", "--work-offset", "G55=790,200,300",
                     "--machine", str(HR5B))  # fmt: skip
    systems = by(report["work_offsets"], "name")
    assert systems["G54"]["machine_mm"] == box((100, 120), (200, 210), (299, 305))
    assert systems["G55"]["machine_mm"] == box((800, 820), (210, 210), (298, 305))
    assert all(fit["fits"] for fit in systems["G54"]["travel"].values())
    x = systems["G55"]["travel"]["X"]
    assert not x["fits"] and x["above_mm"] == pytest.approx(20.0) and x["below_mm"] == 0.0
    assert systems["G55"]["travel"]["Y"]["fits"]
    assert report["all"]["travel"]["X"]["above_mm"] == pytest.approx(20.0)


def test_a_system_whose_zero_is_not_told_has_no_machine_box(tmp_path, capsys):
    report = extents(tmp_path, capsys, "--work-offset", "G54=100,200,300")
    systems = by(report["work_offsets"], "name")
    assert systems["G54"]["machine_mm"] == box((100, 120), (200, 210), (299, 305))
    assert systems["G55"]["machine_mm"] is None and systems["G55"]["moves_zero_unknown"] == 3


def test_tool_length_moves_the_machine_box(tmp_path, capsys):
    table = tmp_path / "tool.tbl"
    table.write_text("T1 P1 Z50 D10 ;\nT2 P2 Z80 D6 ;\n")
    text = PROGRAM.replace("T1 M6", "T1 M6 G43 H1").replace("T2 M6", "T2 M6 G43 H2")
    report = extents(tmp_path, capsys, "--work-offset", "G54=100,200,300", "--work-offset", "G55=500,200,300",
                     "--tool-table", str(table), text=text)  # fmt: skip
    tools = by(report["tools"], "tool")
    assert tools["1"]["machine_mm"]["Z"] == [349.0, 355.0]
    assert tools["2"]["machine_mm"]["Z"] == [378.0, 385.0]


def test_full_circle_and_quarter_arc_reach_their_true_extent(tmp_path, capsys):
    text = "G21 G17 G90\nG0 X10 Y0 Z0\nG3 X10 Y0 I-10 J0 F100\nG0 X0 Y50\nG2 X10 Y40 I0 J-10\nM2\n"
    report = extents(tmp_path, capsys, text=text)
    # circle about (0,0) R10; then a quarter from (0,50) clockwise about (0,40) to (10,40)
    assert report["all"]["program_mm"] == box((-10, 10), (-10, 50), (0, 0))


def test_heidenhain_tool_calls_and_text(tmp_path, capsys):
    text = ("0 BEGIN PGM P MM\n1 TOOL CALL 3 Z S1000\n2 L X+0 Y+0 Z+5 FMAX\n3 CC X+10 Y+0\n"
            "4 C X+20 Y+0 DR- F100\n5 TOOL CALL 4 Z\n6 L X+40 FMAX\n7 END PGM P MM\n")  # fmt: skip
    report = extents(tmp_path, capsys, text=text, suffix=".h")
    tools = by(report["tools"], "tool")
    assert tools["3"]["program_mm"] == box((0, 20), (0, 10), (5, 5))
    assert tools["4"]["program_mm"] == box((40, 40), (0, 0), (5, 5))
    assert [g["name"] for g in report["work_offsets"]] == ["program zero"]


def test_text_says_what_counts_and_what_does_not_fit(tmp_path, capsys):
    program = tmp_path / "part.ngc"
    program.write_text(PROGRAM)
    options = ["--work-offset", "G54=100,200,300", "--work-offset", "G55=790,200,300", "--machine", str(HR5B)]
    assert main(["extents", str(program), *options]) == 0
    out = capsys.readouterr().out
    assert "feed and rapid moves, arcs by their true extent" in out
    assert "X does NOT fit the travel [0, 800]: 20.000 mm above its high end" in out


# The program sets G54's zero itself (LinuxCNC G-code manual, "G10 L2 Set Coordinate System"), and
# G55's X and Y only: G54's machine box is the program's plus (100, 50, -20), G55's is not known.
OWN_ZERO = """G21 G90
G10 L2 P1 X100 Y50 Z-20
G10 L2 P2 X300 Y50
G54
G0 X0 Y0 Z5
G1 Z-1 F100
G1 X10 Y10
G55
G0 X0 Y0
M2
"""


def test_a_zero_the_program_sets_itself_gives_machine_positions(tmp_path, capsys):
    report = extents(tmp_path, capsys, "--machine", str(HR5B), text=OWN_ZERO)
    systems = by(report["work_offsets"], "name")
    assert systems["G54"]["machine_mm"] == box((100, 110), (50, 60), (-21, -15))
    assert systems["G54"]["zero_from_program"] and systems["G54"]["moves_zero_unknown"] == 0
    assert not systems["G54"]["travel"]["Z"]["fits"]  # (Z -21 is below HR5B's travel 0..700)
    assert systems["G55"]["machine_mm"] is None and not systems["G55"]["zero_from_program"]
    program = tmp_path / "part.ngc"
    assert main(["extents", str(program)]) == 0
    assert "work offset G54 (its zero set by the program itself, G10)" in capsys.readouterr().out


def test_the_programs_zero_wins_over_the_one_told(tmp_path, capsys):
    report = extents(tmp_path, capsys, "--work-offset", "G54=1,2,3", "--work-offset", "G55=500,200,300",
                     text=OWN_ZERO)  # fmt: skip
    systems = by(report["work_offsets"], "name")
    assert systems["G54"]["machine_mm"] == box((100, 110), (50, 60), (-21, -15))
    assert systems["G55"]["machine_mm"] == box((300, 300), (50, 50), (-21, -21))  # (Z stays where it was)


def test_a_zero_set_from_where_the_tool_stands_is_not_known(tmp_path, capsys):
    text = OWN_ZERO.replace("G55\n", "G10 L20 P1 X0 Y0 Z0\n")
    report = extents(tmp_path, capsys, text=text)
    g54 = by(report["work_offsets"], "name")["G54"]
    assert g54["machine_mm"] == box((100, 110), (50, 60), (-21, -15))  # (the moves before the G10 L20)
    assert g54["moves_zero_unknown"] == 1


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_fanuc_and_haas_g91_g10_l2_adds_to_the_zero(tmp_path, capsys, dialect):
    # Fanuc 0i-MD operator's manual, "Changing workpiece coordinate system"; Haas "Programmable
    # Offsets": `G10 L2 P1 G91 X60.` moves G54's X offset 60 mm
    text = ("O1000\nG21 G90\nG10 L2 P1 X100. Y50. Z-20.\nG10 L2 P1 G91 X60.\nG90 G54\nG0 X0 Y0 Z5.\n"
            "G1 X10. Y10. F100.\nM30\n")  # fmt: skip
    report = extents(tmp_path, capsys, "--dialect", dialect, text=text)
    assert by(report["work_offsets"], "name")["G54"]["machine_mm"] == box((160, 170), (50, 60), (-15, -15))


def test_linuxcnc_g91_g10_l2_sets_the_zero_as_rs274_does(tmp_path, capsys):
    text = "G21 G90\nG10 L2 P1 X100 Y50 Z-20\nG91 G10 L2 P1 X60\nG90 G54\nG0 X0 Y0 Z5\nM2\n"
    report = extents(tmp_path, capsys, text=text)
    assert by(report["work_offsets"], "name")["G54"]["machine_mm"] == box((60, 60), (50, 50), (-15, -15))


@pytest.mark.parametrize("dialect, select", [("fanuc", "G54.1 P3"), ("haas", "G154 P3"), ("haas", "G112")])
def test_an_additional_offset_the_program_sets_with_g10_l20(tmp_path, capsys, dialect, select):
    # Fanuc 0i-MF "Additional workpiece coordinate systems": G10 L20 Pn sets G54.1 Pn's zero; Haas
    # "Programmable Offsets": G10 L20 P1-P20 set G110-G129 (G154 P1-P20); in G91 added to it
    text = (f"O1000\nG21 G90\nG10 L20 P3 X100. Y50. Z-20.\n{select}\nG0 X0 Y0 Z5.\nG1 X10. Y10. F100.\n"
            "G91 G10 L20 P3 X5.\nG90 G0 X0 Y0\nM30\n")  # fmt: skip
    report = extents(tmp_path, capsys, "--dialect", dialect, text=text)
    (system,) = report["work_offsets"]
    assert system["name"] == ("G154 P3" if dialect == "haas" else "G54.1 P3") and system["zero_from_program"]
    assert system["machine_mm"] == box((100, 110), (50, 60), (-15, -15))  # (line 8 at X105: inside)
    assert system["lines"] == [5, 8]
