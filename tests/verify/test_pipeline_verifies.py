"""Every rewriting command verifies its output before writing it: a pass that goes wrong is
stopped at the input line where the written program parts from the input, and nothing is
written; `--no-verify` writes it."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import pytest

import ncpp.pipeline
import ncpp.program.dialects.iso
from ncpp.cli import main
from ncpp.motion.segments import Line

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples" / "machines" / "hr5b.toml"
PROGRAM = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F200\nX50\nY40\nX10\nG0 Z5\nM5\nM30\n"


def shifted_at_line(line: int, by: float):
    """A pass that moves the end of the feed moves of one input line by `by` mm in X."""

    def shift(events, ctx):
        for event in events:
            if type(event) is Line and event.block.line == line and not event.rapid:
                event = replace(event, end=(event.end[0] + by, *event.end[1:]), changed=True)
            yield event

    return shift


@pytest.fixture
def program(tmp_path: Path) -> Path:
    path = tmp_path / "part.ngc"
    path.write_text(PROGRAM)
    return path


def compensate(program: Path, *extra: str) -> int:
    out = program.with_suffix(".out.ngc")
    return main(
        [
            "compensate",
            "--machine",
            str(MACHINE),
            "--work-offset",
            "400,350,300",
            str(program),
            "-o",
            str(out),
            *extra,
        ]
    )


def test_a_pass_gone_wrong_is_stopped_and_nothing_written(program: Path, monkeypatch, capsys):
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(7, 2.0)))
    assert compensate(program) != 0
    err = capsys.readouterr().err
    assert "part.ngc:7:1: verification:" in err, err
    assert not program.with_suffix(".out.ngc").exists()


def test_no_verify_writes_what_the_passes_make(program: Path, monkeypatch):
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(7, 2.0)))
    assert compensate(program, "--no-verify") == 0
    assert program.with_suffix(".out.ngc").exists()


def noted(shift):
    """`shift`, its move noted as a correction compensation made (`PassContext.corrections`)."""

    def pass_(events, ctx):
        ctx.corrections.note(0.25)
        return shift(events, ctx)

    return pass_


def test_a_correction_within_the_bound_passes(program: Path, monkeypatch):
    """The bound follows the largest correction made: a move of 0.2 mm made as a correction passes."""
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, noted(shifted_at_line(7, 0.2))))
    assert compensate(program) == 0


def test_a_move_wider_than_the_corrections_made_is_refused(program: Path, monkeypatch, capsys):
    """A point of the written path 0.2 mm off the input's, well within the machine file's
    max_correction_mm (0.5), where hr5b's corrections are under 0.04 mm: no correction ncpp made."""
    report = program.with_suffix(".json")
    assert compensate(program, "--report", str(report)) == 0
    assert json.loads(report.read_text())["largest_correction_um"] < 40
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(7, 0.2)))
    program.with_suffix(".out.ngc").unlink()
    assert compensate(program) != 0
    err = capsys.readouterr().err
    assert "part.ngc:7:1: verification: the written path leaves the original's by more than" in err, err
    assert not program.with_suffix(".out.ngc").exists()


def test_the_filter_verifies_too(program: Path, monkeypatch, capsys):
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(6, 2.0)))
    monkeypatch.setenv("NCPP_MACHINE", str(MACHINE))
    assert main([str(program), "--work-offset", "400,350,300"]) != 0
    captured = capsys.readouterr()
    # (line 7's move starts where line 6's ends: the first point found off may be either's)
    assert (
        "part.ngc:6:1: verification:" in captured.err or "part.ngc:7:1: verification:" in captured.err
    ) and captured.out == ""


def test_a_long_program_is_verified_in_chunks(tmp_path: Path, monkeypatch, capsys):
    """Thousands of moves between two actions: chunks of a few hundred moves still find
    the one line that goes wrong, and pass the program without it."""
    import ncpp.verify

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 300)
    moves = "".join(f"X{10 + (k % 40)} Y{10 + (k * 7) % 30}\n" for k in range(3000))
    path = tmp_path / "long.ngc"
    path.write_text(f"G21 G90 G17\nT1 M6\nS1000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F200\n{moves}G0 Z5\nM5\nM30\n")
    assert compensate(path) == 0
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(2000, 2.0)))
    assert compensate(path) != 0
    assert "long.ngc:2000:1: verification:" in capsys.readouterr().err


LOOP = """G21 G90 G17
T1 M6
S1000 M3
G0 X10 Y10 Z5
G1 Z-1 F200
#1 = 0
o101 repeat [400]
#1 = [#1 + 0.9]
G1 X[10 + #1] Y10
X10 Y[10 + #1 / 2]
o102 call
o101 endrepeat
G0 Z5
M5
M30
o102 sub
G1 X12 Y12
o103 repeat [2]
G1 X11
Y11
o103 endrepeat
o102 endsub
"""


FANUC_LOOP = """%
O1000
G90 G21 G17 G54
G0 X0 Y0 Z5
#1=0
WHILE [#1 LT 400] DO1
G1 X[#1*0.1] Y10 F500
G1 Y0
#1=#1+1
END1
G1 X20 Y5
M30
%
"""


# (its formulas on `~` continuation lines: the read-back counts a block's lines as the file has them,
# drunsinn/language-klartext, `testprogramme/Krivka.klartext`)
KLARTEXT_LOOP = """0  BEGIN PGM LOOP MM
1  TOOL CALL 1 Z S900
2  L  X+0  Y+0  Z+5 R0 FMAX M3
3  L  Z-1 F300
4  Q4 = 0
5  LBL 2
6  Q4 = Q4 + ~
    0,1
7  Q2 = Q4 * 2 + ~
    10
8  L  X+Q4  Y+Q2 R0 F500
9  L  Y+0
10 FN 12: IF +Q4 LT +40 GOTO LBL 2
11 L  Z+5 R0 FMAX M30
12 END PGM LOOP MM
"""


@pytest.mark.parametrize("program, name, moves_a_run", [(LOOP, "loop.ngc", 7), (FANUC_LOOP, "loop.nc", 2),
                                                        (KLARTEXT_LOOP, "loop.h", 2)],
                         ids=["o-words", "Fanuc WHILE", "Klartext FN 12"])  # fmt: skip
def test_a_long_loop_is_verified_a_chunk_at_a_time(tmp_path: Path, monkeypatch, program, name, moves_a_run):
    """A loop's runs, whose moves are its end line's (`endrepeat`, `END1`), are compared in
    chunks as they run (memory stays flat in the number of runs), the read-back's cut where
    the input's is: runs that differ (#1 grows) and a subroutine call with a loop of its own
    in them pass."""
    import ncpp.verify

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 64)
    compared: list[int] = []  # the input's moves in each chunk compared
    step = ncpp.verify._Comparison.step

    def counted(self, a, theirs):
        compared.append(len(a.lines))
        step(self, a, theirs)

    monkeypatch.setattr(ncpp.verify._Comparison, "step", counted)
    path = tmp_path / name
    path.write_text(program)
    assert compensate(path) == 0
    assert len(compared) > 400 * moves_a_run // 64 and max(compared) <= 2 * 64, compared


def test_a_fault_in_a_loop_body_is_refused_with_its_line(tmp_path: Path, monkeypatch, capsys):
    import ncpp.verify

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 64)
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(10, 2.0)))
    path = tmp_path / "loop.ngc"
    path.write_text(LOOP)
    assert compensate(path) != 0
    err = capsys.readouterr().err
    # (the runs after the first are the loop end's moves: the fault may be told at line 12)
    assert "loop.ngc:10:1: verification:" in err or "loop.ngc:12:1: verification:" in err, err
    assert not path.with_suffix(".out.ngc").exists()


def test_a_written_loop_that_runs_once_less_is_refused(tmp_path: Path, monkeypatch, capsys):
    """The last runs of a loop are compared too: a writer that gets the count wrong is stopped (each
    run goes 0.9 mm further than the one before: the last one's path lies off the others')."""
    import ncpp.verify
    from ncpp.program.dialects.iso import IsoWriter

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 64)
    write_control = IsoWriter._write_control
    monkeypatch.setattr(IsoWriter, "_write_control", lambda self, block, first: [
        text.replace("[400]", "[399]") for text in write_control(self, block, first)])  # fmt: skip
    path = tmp_path / "loop.ngc"
    path.write_text(LOOP)
    assert compensate(path) != 0
    err = capsys.readouterr().err
    assert "loop.ngc:12:1: verification:" in err, err


def test_written_lines_are_read_back_as_the_file_holds_them(tmp_path: Path, monkeypatch, capsys):
    """A writer whose lines do not each end theirs (here: the ISO writer's ending of an unended last
    line's pieces taken away) makes a file in which they run into one (`G1 X0.0004 Y0G1 X10 ...`):
    the read-back reads that line, as the control would, and refuses the program; it read each
    piece as a line of its own and let the file be written."""
    monkeypatch.setattr(ncpp.program.dialects.iso, "_lines_ended", lambda write_group: write_group)
    path = tmp_path / "part.ngc"
    path.write_text("G21 G90 G17\nG0 X0 Y0 Z1\nG1 Z0 F100\nG1 X10 Y0")  # (the last line unended)
    assert compensate(path) != 0
    assert "verification: ncpp cannot read back the program it wrote" in capsys.readouterr().err
    assert not path.with_suffix(".out.ngc").exists()


@pytest.mark.parametrize("call, label", [("M98 P9000 L2", "O9000"), ("M97 P9000 L2", "N9000")],
                         ids=["Fanuc M98", "Haas M97"])  # fmt: skip
def test_a_call_reading_on_to_its_subprogram_after_m30_is_verified(tmp_path: Path, monkeypatch, call, label):
    """The read-back of a call near the top finds its subprogram after M30 by reading the written
    lines to it: their tags are kept until the lines are read in turn (few tags kept here, a long
    program's many in use), so the chunks are cut where the input's are."""
    import ncpp.verify

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 64)
    monkeypatch.setattr(ncpp.verify._Feed, "KEPT_TAGS", 40)
    moves = "".join(f"X{10 + (k % 40)} Y{10 + (k * 7) % 30}\n" for k in range(600))
    path = tmp_path / "call.nc"
    path.write_text(f"G21 G90 G17\nT1 M6\nS1000 M3\nG0 X10 Y10 Z5\nG1 Z-1 F200\n{call}\n{moves}G0 Z5\nM5\nM30\n"
                    f"{label} (THE SUBPROGRAM)\nG91 G1 X1.\nG90\nM99\n")  # fmt: skip
    assert compensate(path) == 0


def test_the_runs_of_a_haas_local_subprogram_are_verified_a_chunk_at_a_time(tmp_path: Path, monkeypatch):
    """`M97 P100 L99` is a control line to the writer (its runs' moves are its own, written at
    once): they are compared in chunks as they run, not held whole."""
    import ncpp.verify

    monkeypatch.setattr(ncpp.verify, "CHUNK_MOVES", 64)
    compared: list[int] = []
    step = ncpp.verify._Comparison.step

    def counted(self, a, theirs):
        compared.append(len(a.lines))
        step(self, a, theirs)

    monkeypatch.setattr(ncpp.verify._Comparison, "step", counted)
    path = tmp_path / "runs.nc"
    body = "G91 G1 X0.1 Y10. F500\nG1 Y-10.\n" * 5
    head = "%\nO1000\nG90 G21 G17 G54\nG0 X0 Y0 Z5\nM97 P100 L99\nG90 G1 X20. Y5.\nM30\n"
    path.write_text(f"{head}N100\n{body}G90\nM99\n%\n")
    assert compensate(path) == 0
    assert len(compared) > 99 * 10 // 64 and max(compared) <= 2 * 64, compared


SUBPROGRAM_FIRST = ("%\nO2000 (SUB)\nG91 G1 X10 F300\nG90\nM99\n"
                    "O1000 (MAIN)\nG21 G90 G54\nG0 X0 Y0 Z5\nG1 Z-1 F200\nM98 P2000\nG0 Z5\nM30\n%\n")  # fmt: skip


def test_a_subprogram_stored_before_the_main_program_is_read_back_where_the_call_runs_it(
    tmp_path: Path, monkeypatch, capsys
):
    """The read-back runs O1000 as the main program and O2000 where M98 calls it, as the input's
    reading does: its one run, written where its text stands, is verified; a pass that moves it off
    is stopped at its line."""
    path = tmp_path / "part.nc"
    path.write_text(SUBPROGRAM_FIRST)
    assert compensate(path, "--dialect", "fanuc") == 0
    written = path.with_suffix(".out.ngc").read_text()
    assert "G91 G1 X10 F300" not in written and written.index("G91 G1 X") < written.index("O1000")
    path.with_suffix(".out.ngc").unlink()
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(3, 0.5)))
    assert compensate(path, "--dialect", "fanuc") != 0
    assert "part.nc:3:1: verification:" in capsys.readouterr().err
    assert not path.with_suffix(".out.ngc").exists()


CONTOUR = """G21 G90 G17
T1 M6
S1000 M3
G0 X0 Y-5 Z5
G1 Z-1 F200
G41.1 D4
G1 X10 Y0
X30
X30.005
X50
Y20
X10
G40 G1 X0 Y25
G0 Z5
M5
M30
"""


def test_a_short_move_turned_round_under_cutter_compensation_is_refused(tmp_path: Path, monkeypatch, capsys):
    """Line 9's 5 µm move along the edge written 10 µm back, within the bound as a contour: under
    G41.1 the control offsets it to its other side, swinging the tool centre round by the 4 mm
    diameter and back."""
    program = tmp_path / "contour.ngc"
    program.write_text(CONTOUR)
    assert compensate(program) == 0
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(9, -0.01)))
    program.with_suffix(".out.ngc").unlink()
    assert compensate(program) != 0
    assert "contour.ngc:9:1: verification: the written path leaves the original's" in capsys.readouterr().err


def test_a_contour_under_cutter_compensation_written_a_little_off_passes(tmp_path: Path, monkeypatch):
    """The same 10 µm at the end of the edge before: the tool centre moves by as much."""
    program = tmp_path / "contour.ngc"
    program.write_text(CONTOUR)
    monkeypatch.setattr(ncpp.pipeline, "PASSES", (*ncpp.pipeline.PASSES, shifted_at_line(8, -0.01)))
    assert compensate(program) == 0
