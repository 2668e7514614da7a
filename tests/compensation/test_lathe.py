"""A lathe program is refused when ncpp is to compensate it (`ncpp/lathe.py`): its X is a diameter,
and the machine file is a machining centre's.  Each program below has mill-like moves before its
lathe (or turning) construct, which were compensated as a mill's before the rule; now the run
stops at the construct with nothing written.  The constructs mills write too are not taken for a
lathe's, and no program of the corpus is."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.lathe import HEAD, lathe_construct
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from tests.conftest import CORPUS, NOT_PROGRAMS, SHARED

WIDE = SHARED / "machines" / "wide.toml"

pytestmark = pytest.mark.skipif(not WIDE.exists(), reason="no shared machine file")

# Moves a mill program could start with, compensated before the construct is met
START = "G21 G90 G54\nG0 X10. Z5.\nG1 Z0.5 F100.\nX20.\n"
FANUC_HEAD = "%\nO1003\n"
# The same moves in Klartext (up to block 6) and Sinumerik
KLARTEXT_HEAD = ("0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S3000\n2 L X+10 Y+5 Z+5 R0 FMAX\n3 L Z+0.5 F100\n"
                 "4 L X+20\n5 L Z+1 FMAX\n6 L X+30\n")  # fmt: skip
SINUMERIK_HEAD = "G90 G54 G17\nG0 X10 Y5 Z5\nG1 Z0.5 F100\nX20\n"

# (dialect, program, the construct's line and column): a Fanuc lathe's two-block G71 (CNCLearn
# 1003.NC's form), Haas's one-block G71 with D (CadeKiely O58214's), G70 and G72, the spindle speed
# limit, LinuxCNC's diameter mode and lathe cycles (its nc_files/lathe_g70_71_demo.ngc's forms)
LATHE = {
    "fanuc G71 P Q": ("fanuc", FANUC_HEAD + START + "G71 U0.5 R0.2\nG71 P1 Q2 U-0.1 W0.03 F0.15\n"
                      "N1 G0 X6.\nG1 Z-8.\nN2 X12.\nM30\n%\n", (8, 1)),
    "haas G71 P Q D": ("haas", FANUC_HEAD + START + "G00 X2.\nG71 P45 Q49 U0.01 W0 D0.025 F0.02\n"
                       "N45 G00 X1.25 Z0.1\nN49 G01 Z-5.2\nM30\n%\n", (8, 1)),
    "fanuc G70 P Q": ("fanuc", FANUC_HEAD + START + "N10 G70 P1 Q2\nM30\n%\n", (7, 5)),
    "fanuc G72 P Q": ("fanuc", FANUC_HEAD + START + "G72 W1. R0.5\nG72 P1 Q2 U0.2 W0.1 F0.2\nM30\n%\n", (8, 1)),
    "fanuc G50 S": ("fanuc", FANUC_HEAD + START + "G50 S1600 (SPINDLE SPEED LIMIT)\nG96 S200 M3\nM30\n%\n",
                    (7, 1)),
    "haas G50 S": ("haas", FANUC_HEAD + START + "G50 S2400\nM30\n%\n", (7, 1)),
    "iso G50 S": ("iso", START + "G0 X1 G50 S1000\nM2\n", (5, 7)),
    "iso G7": ("iso", START + "G18 G7\nG1 X5 Z-1\nM2\n", (5, 5)),
    "grbl G7": ("grbl", START + "G7\nG1 X5\nM2\n", (5, 1)),
    "iso G71 Q": ("iso", START + "o100 sub\nG1 X3 Z-1\no100 endsub\nG18\nG71 Q100 X15 Z3 D1 I1 R0.3\nM2\n",
                  (9, 1)),
    "iso G70 Q": ("iso", START + "o100 sub\nG1 X3 Z-1\no100 endsub\nG18\nG70 Q100 X15 Z3 P2\nM2\n", (9, 1)),
    "iso G72.1 Q": ("iso", START + "o100 sub\nG1 X3 Z-1\no100 endsub\nG18\nG72.1 Q100 X15 Z3 D0.5\nM2\n",
                    (9, 1)),
    "heidenhain FUNCTION MODE TURN": ("heidenhain", KLARTEXT_HEAD + "7 FUNCTION MODE TURN\n"
                                      "8 L X+40 Z+2 FMAX\n9 END PGM T MM\n", (8, 3)),
    "heidenhain CYCL DEF 812": ("heidenhain", KLARTEXT_HEAD + "7 CYCL DEF 812 SHOULDER LONG. EXTENDED ~\n"
                                "  Q215=+0 ;MACHINING OPERATION\n8 END PGM T MM\n", (8, 3)),
    "sinumerik DIAMON": ("sinumerik", SINUMERIK_HEAD + "G18 DIAMON\nG0 X40 Z2\nM30\n", (5, 5)),
    "sinumerik DIAM90": ("sinumerik", SINUMERIK_HEAD + "N50 DIAM90\nM30\n", (5, 5)),
    "sinumerik CYCLE95": ("sinumerik", SINUMERIK_HEAD + 'CYCLE95("KONTUR",2,0.1,0.1,,0.2,0.1,0.1,9,,,1)\n'
                          "M30\n", (5, 1)),
    "sinumerik CYCLE952": ("sinumerik", SINUMERIK_HEAD + 'G18 CYCLE952("CONT",,"",2101311,0.3,0.2,0,2)\n'
                           "M30\n", (5, 5)),
}  # fmt: skip


def compensate(program: str, dialect: str | None) -> bytes:
    out = io.BytesIO()
    process(io.BytesIO(program.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(WIDE)),
            dialect=dialect, warnings=Warnings(stream=io.StringIO()))  # fmt: skip
    return out.getvalue()


@pytest.mark.parametrize("case", sorted(LATHE))
def test_a_lathe_construct_refuses_the_program_at_its_place_with_nothing_written(case):
    dialect, program, (line, col) = LATHE[case]
    out = io.BytesIO()
    with pytest.raises(NcppError) as caught:
        process(io.BytesIO(program.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(WIDE)),
                dialect=dialect, warnings=Warnings(stream=io.StringIO()))  # fmt: skip
    assert str(caught.value.where) == f"p.nc:{line}:{col}"
    message = caught.value.message
    assert "a lathe program" in message or "a turning program" in message
    assert "compensates milling programs" in message
    assert out.getvalue() == b""


def test_the_lathe_program_is_refused_as_the_command_line_detects_it():
    """CNCLearn's 1003.NC has no program number line: ncpp reads it as LinuxCNC's, where its
    `G71 P1 Q2` has LinuxCNC's Q too."""
    program = LATHE["fanuc G71 P Q"][1].replace(FANUC_HEAD, "")
    with pytest.raises(NcppError, match="G71 with Q is a lathe's roughing cycle"):
        compensate(program, None)


def test_a_construct_past_the_head_is_refused_too():
    moves = "".join(f"G1 X{k % 10}.\n" for k in range(HEAD))
    with pytest.raises(NcppError) as caught:
        compensate(START + moves + "G7\nM2\n", "iso")
    assert caught.value.where.line == 4 + HEAD + 1


def test_grbl_refuses_a_lathe_code_as_no_grbl_command():
    """grbl 1.1 has no G7 ("List of Supported G-Codes in Grbl v1.1"): it stops at it with error 20."""
    dialect, program, _ = LATHE["grbl G7"]
    refused = r'G7 is not a grbl 1\.1 command \(grbl stops at it with error 20, "Unsupported or invalid'
    with pytest.raises(NcppError, match=refused):
        compensate(program, dialect)


@pytest.mark.parametrize("dialect", ["fanuc", "haas", "iso"])
def test_motion_names_a_lathes_g50_s_a_spindle_limit_not_scaling(dialect):
    """`ncpp motion` (no machine file) stops following the program at a lathe's G50 S and says what it is."""
    interpret, _ = dialect_tools(dialect)
    said = io.StringIO()
    _, blocks = parse_program(io.BytesIO(b"G0 X1\nG50 S1600\nG0 X2\n"), "p.nc", dialect)
    list(interpret(blocks, file="p.nc", warnings=Warnings(stream=said)))
    warned = said.getvalue()
    assert "p.nc:2:1: warning: G50 with S, a lathe's spindle speed limit (a lathe program" in warned
    assert "scaling" not in warned


def test_without_a_machine_file_a_lathe_program_passes_through_byte_for_byte():
    for dialect, program, _ in LATHE.values():
        text = program.replace("\n", "\r\n").encode()
        out = io.BytesIO()
        process(io.BytesIO(text), out, file="p.nc", dialect=dialect)
        assert out.getvalue() == text


# Blocks mill programs write, each with a construct a lathe's may share (module docstring of ncpp/lathe.py)
MILL = [
    ("haas", "G70 I1.5 J0. L6"),  # a Haas mill's bolt-hole circle
    ("haas", "G83 G70 I1.5 J0. L6 Z-1. R.1 Q.2 P.5 F10."),  # with the peck drilling it repeats
    ("haas", "G71 I1.5 J0. K30. L4"),  # bolt-hole arc
    ("iso", "G70"),  # Millmaster Pro's inch (read as LinuxCNC's)
    ("fanuc", "G71"),
    ("fanuc", "G50"),  # scaling cancelled
    ("iso", "G90 G64 G50 G17 G40 G80 G94 G91.1 G49"),  # PathPilot's safety line
    ("fanuc", "G28 U0. W0."),  # additional axes U and W on a mill
    ("fanuc", "T0101 M6"),
    ("fanuc", "G96 S200"),
    ("iso", "G96 D2500 S200"),
    ("iso", "G18 G8"),
    ("fanuc", "G76 X1. Y1. Z-1. R.1 Q.05 P500 F10."),  # fine boring
    ("iso", "G76 P0.05 Z-1 I-.075 J0.008 K0.045 Q29.5"),  # LinuxCNC's threading: on mills too
    ("fanuc", "G7.1 C57299"),  # cylindrical interpolation
    ("fanuc", "G07 X1."),  # Fanuc's hypothetical axis interpolation, not a diameter mode
    ("fanuc", "G92 S3000"),  # a Fanuc machining centre's maximum speed clamp (lathe systems B/C's too)
    ("fanuc", "G92 X0. Y0. Z0."),
    ("iso", "G17 G8 G21 G40 G49 G64 P0.001 G80 G90 G91.1 G92.2 G94 G97 G98"),  # a mill's reset, radius mode
    ("heidenhain", "1 FUNCTION MODE MILL"),
    ("heidenhain", "1 CYCL DEF 200 DRILLING"),
    ("heidenhain", "1 CYCL DEF 7.0 DATUM SHIFT"),
    ("sinumerik", "DIAMOF"),
    ("sinumerik", "G96 S200 LIMS=3000"),
    ("sinumerik", 'CYCLE800(1,"TC1",0,57,0,0,0,0,0,0,0,0,0,-1,100,1)'),  # swivel: the prefix only
    ("sinumerik", "CYCLE832(0.01,1,1)"),
    ("sinumerik", "CYCLE81(10,0,1,-5,)"),
]


@pytest.mark.parametrize("dialect, text", MILL)
def test_a_mill_block_is_not_taken_for_a_lathe_construct(dialect, text):
    _, blocks = parse_program(io.BytesIO(f"{text}\n".encode()), "p.nc", dialect)
    assert [lathe_construct(block, dialect) for block in blocks] == [None]


def _corpus_programs() -> list:
    manifest = CORPUS / "MANIFEST.tsv"
    if not manifest.exists():
        return []
    rows = [row.split("\t") for row in manifest.read_text().splitlines()[1:]]
    return sorted(
        row[0]
        for row in rows
        if row[10] in ("iso_gcode", "heidenhain", "sinumerik") and not any(n in row[0] for n in NOT_PROGRAMS)
    )


@pytest.mark.skipif(not _corpus_programs(), reason="no corpus")
def test_no_program_of_the_corpus_is_taken_for_a_lathe_program():
    """Its ISO programs as detected and as Fanuc's, Haas's and grbl's, its Klartext and Sinumerik
    programs as detected: mill programs, and LinuxCNC lathe programs in radius mode without lathe
    cycles (`g76.ngc`, `lathe_pawn.ngc`), which the rule cannot tell from a mill program in G18."""
    flagged = []
    for name in _corpus_programs():
        for dialect in (None, "fanuc", "haas", "grbl") if name.startswith("iso_gcode/") else (None,):
            with open(CORPUS / name, "rb") as stream:
                read, blocks = parse_program(stream, name, dialect)
                found = next((b.line for b in blocks if lathe_construct(b, read) is not None), None)
            if found is not None:
                flagged.append((name, read, found))
    assert len(_corpus_programs()) > 100 and flagged == []


@pytest.mark.parametrize("dialect", ["fanuc", "haas"])
def test_a_g92_s_is_refused_as_the_spindle_speed_clamp_it_is(dialect):
    """Fanuc lathe G-code systems B and C clamp the spindle speed with `G92 S` (system A: G50 S), as
    a Fanuc machining centre does under constant surface speed: refused, saying so."""
    program = FANUC_HEAD + "G92 S4000\n" + START + "M30\n%\n"
    with pytest.raises(NcppError) as caught:
        compensate(program, dialect)
    assert str(caught.value.where) == "p.nc:3:1"
    assert caught.value.message.startswith("G92 with S and no axis words (a spindle speed clamp: Fanuc lathe")
    assert "ncpp does not follow it" in caught.value.message


def test_linuxcncs_g92_s_is_refused_in_rs274s_words():
    """LinuxCNC has no G92 S: rs274 refuses the block as a G92 without axes, and ncpp with its words."""
    from tests import rs274

    program = "G92 S4000\n" + START + "M2\n"
    said = rs274.error(rs274.run(program).stderr)
    assert said is not None
    with pytest.raises(NcppError) as caught:
        compensate(program, "iso")
    assert caught.value.message == said[0] == "All axes missing with g52 or g92"
