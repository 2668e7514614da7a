"""Sinumerik blocks parse into the common items with the right values."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Line, Pass
from ncpp.motion.sinumerik import interpret
from ncpp.program.blocks import Comment, ExprWord, Statement, Word
from ncpp.program.parser import LineParser, parse_stream
from ncpp.program.writer import write_blocks

PARSER = LineParser("sinumerik")


def interpreted(text: str, file: str = "a.mpf") -> tuple[list, str]:
    """The events of a Sinumerik program's text, and the warnings said while reading it."""
    said = io.StringIO()
    events = list(interpret(parse_stream(io.BytesIO(text.encode()), file, "sinumerik"), file=file,
                            warnings=Warnings(stream=said)))  # fmt: skip
    return events, said.getvalue()


def items(text: str) -> tuple:
    return PARSER.parse(text).items


def words(text: str) -> dict[str, float]:
    return {i.letter: i.value for i in items(text) if type(i) is Word}


def exprs(text: str) -> dict[str, tuple]:
    return {i.letter: i.expr for i in items(text) if type(i) is ExprWord}


def statements(text: str) -> list[tuple[str, tuple]]:
    return [(i.kind, i.node) for i in items(text) if type(i) is Statement]


def test_plain_words_take_the_fast_path():
    assert PARSER._scan_plain("N10 G1 X1.5 Y-2. Z0.001 F2400 ; c") is not None
    assert words("N10 G1 X1.5 Y-2. Z0.001 F2400") == {
        "N": 10.0,
        "G": 1.0,
        "X": 1.5,
        "Y": -2.0,
        "Z": 0.001,
        "F": 2400.0,
    }
    assert PARSER._scan_plain("X(1)") is None  # parentheses are arithmetic, not comments


@pytest.mark.parametrize(
    "block, found",
    [
        ("g0X-170 Y20", {"G": 0.0, "X": -170.0, "Y": 20.0}),
        ("N20G1X10Y5F100", {"N": 20.0, "G": 1.0, "X": 10.0, "Y": 5.0, "F": 100.0}),
        ("g1x10 y5 f100", {"G": 1.0, "X": 10.0, "Y": 5.0, "F": 100.0}),
    ],
)
def test_words_without_blanks_and_in_lower_case_are_read(block, found):
    """An address is one letter and its number; a name starts with two letters or an underscore
    (SINUMERIK 840D sl Programming Manual, Fundamentals, "Block format" and "Definition of
    user-defined variables"), so `G0X` is two words, not a name."""
    assert {letter.upper(): value for letter, value in words(block).items()} == found
    assert PARSER._scan_plain(block) is None or PARSER._scan_plain(block)[0] == PARSER._parse_lalr(
        block, 1, "t"
    )


def test_a_name_after_a_number_is_still_no_word():
    assert [kind for kind, _ in statements("R1=5 X10 AB_C")] and "A" not in words("X10 AB_C")


def test_arcs_with_centre_and_radius():
    assert words("G2 X100 Y0 I50 J0") == {"G": 2.0, "X": 100.0, "Y": 0.0, "I": 50.0, "J": 0.0}
    assert words("G2 X10 Y0 CR=5") == {"G": 2.0, "X": 10.0, "Y": 0.0}
    assert exprs("G2 X10 Y0 CR=5") == {"CR": ("num", 5.0)}
    assert exprs("G3 X0 Y50 CR=-60") == {"CR": ("neg", ("num", 60.0))}
    assert exprs("G2 X10 Y10 I=AC(5) J=AC(0) TURN=2") == {
        "I": ("ac", ("num", 5.0)),
        "J": ("ac", ("num", 0.0)),
        "TURN": ("num", 2.0),
    }


def test_absolute_and_incremental_coordinates():
    assert exprs("X=AC(10)") == {"X": ("ac", ("num", 10.0))}
    assert exprs("G1 X=IC(2/3) Y=IC(0.1*nn)") == {
        "X": ("ic", ("bin", "/", ("num", 2.0), ("num", 3.0))),
        "Y": ("ic", ("bin", "*", ("num", 0.1), ("param", "nn"))),
    }


def test_cip_and_ct():
    block = "CIP X10 Y10 I1=5 J1=8"
    assert statements(block) == [("path", ("CIP",))]
    assert words(block) == {"X": 10.0, "Y": 10.0}
    assert exprs(block) == {"I1": ("num", 5.0), "J1": ("num", 8.0)}
    assert statements("CT X20 Y5") == [("path", ("CT",))] and words("CT X20 Y5") == {"X": 20.0, "Y": 5.0}


def test_expressions_in_addresses():
    assert exprs("X=R1+2") == {"X": ("bin", "+", ("param", "r1"), ("num", 2.0))}
    assert exprs("X=SIN(30)") == {"X": ("call", "SIN", ("num", 30.0))}
    assert exprs("X=ATAN2(30.5, 80.1)") == {"X": ("call", "ATAN2", ("num", 30.5), ("num", 80.1))}
    assert exprs("X=2+6 DIV 4") == {
        "X": ("bin", "+", ("num", 2.0), ("bin", "DIV", ("num", 6.0), ("num", 4.0)))
    }
    assert exprs("X=2*-3") == {"X": ("bin", "*", ("num", 2.0), ("neg", ("num", 3.0)))}
    assert exprs("G1 X=ACC[E]") == {"X": ("index", "acc", (("param", "e"),))}
    assert exprs('T="BALL_MILL" M6') == {"T": ("str", "BALL_MILL")}
    assert exprs("X1 Y=-2/3") == {"Y": ("bin", "/", ("neg", ("num", 2.0)), ("num", 3.0))} and words(
        "X1 Y=-2/3"
    ) == {"X": 1.0}


def test_parameters_variables_and_system_variables():
    assert statements("R1=10") == [("assignment", (("param", "r1"), ("num", 10.0)))]
    assert statements("R1 = $AA_IW[Z] ; 10") == [
        ("assignment", (("param", "r1"), ("index", "$aa_iw", (("param", "z"),))))
    ]
    assert statements("LAYER_HEIGHT = 2.5") == [("assignment", (("param", "layer_height"), ("num", 2.5)))]
    assert statements("FELD[nn,m]=1") == [
        ("assignment", (("index", "feld", (("param", "nn"), ("param", "m"))), ("num", 1.0)))
    ]
    assert statements("R11 = R_SPEED >= 100") == [
        ("assignment", (("param", "r11"), ("bin", ">=", ("param", "r_speed"), ("num", 100.0))))
    ]


def test_definitions_and_procedures():
    ((kind, (type_, length, variables)),) = statements("DEF REAL LAYER_HEIGHT = 2, PART_HEIGHT")
    assert (kind, type_, length) == ("def", "REAL", None)
    assert variables == ((("param", "layer_height"), ("num", 2.0)), (("param", "part_height"), None))
    ((_, (type_, length, variables)),) = statements('DEF STRING[28] NAME = "x"')
    assert (type_, length, variables) == ("STRING", ("num", 28.0), ((("param", "name"), ("str", "x")),))
    ((_, (_, _, variables)),) = statements("DEF REAL FELD1[10,3]=SET(0,,9)")
    assert variables[0][1] == ("call", "SET", ("num", 0.0), None, ("num", 9.0))
    assert statements("PROC CONTOUR(REAL DEPTH, VAR INT N) SAVE") == [
        ("proc", ("CONTOUR", (("REAL", "depth", False, None), ("INT", "n", True, None)), ("SAVE",)))
    ]


def test_labels_jumps_and_control():
    assert statements("N40 REPEAT_HERE: X=R1 ; jump label")[0] == ("label", ("REPEAT_HERE",))
    assert words("N40 LABEL_1: X1") == {"N": 40.0, "X": 1.0}
    assert statements("IF R4>0 GOTOB LA1") == [
        ("if", (("bin", ">", ("param", "r4"), ("num", 0.0)),)),
        ("goto", ("GOTOB", "LA1")),
    ]
    assert statements("GOTOF 90") == [("goto", ("GOTOF", "90"))]
    assert statements("N100 GOTO FINISH") == [("goto", ("GOTO", "FINISH"))]
    assert statements("WHILE (y_current <= y_end)")[0][0] == "while"
    assert statements("FOR COUNTER=0 TO NUMBER") == [
        ("for", (("param", "counter"), ("num", 0.0), ("param", "number")))
    ]
    assert [k for k, _ in statements("ELSE")] == ["else"]
    for word in ("ENDIF", "ENDWHILE", "ENDFOR", "REPEAT", "LOOP", "ENDLOOP"):
        assert statements(word) == [(word.lower(), ())]
    assert statements("UNTIL COUNTER>NUMBER")[0][0] == "until"
    assert statements("IF NOT TRACK_Y") == [("if", (("not", ("param", "track_y")),))]
    ((kind, (expr, branches, default)),) = statements(
        "CASE(4+3) OF 7 GOTOF SEVEN 9 GOTOF NINE DEFAULT GOTOF OTHER"
    )
    assert kind == "case" and branches == ((("num", 7.0), "GOTOF", "SEVEN"), (("num", 9.0), "GOTOF", "NINE"))
    assert default == ("GOTOF", "OTHER")


def test_calls_frames_messages_and_headers():
    assert statements("CYCLE81(10, 0, 2, -5)") == [
        ("call", ("CYCLE81", (("num", 10.0), ("num", 0.0), ("num", 2.0), ("neg", ("num", 5.0)))))
    ]
    assert statements('MSG("Roughing")') == [("call", ("MSG", (("str", "Roughing"),)))]
    assert statements("N53 MATERIAL_UPDATE") == [("call", ("MATERIAL_UPDATE", ()))]
    assert statements("TRANS X10 Y20") == [("frame", ("TRANS",))] and words("TRANS X10 Y20") == {
        "X": 10.0,
        "Y": 20.0,
    }
    assert statements("%_N_PART1_MPF") == [("program_name", ("%_N_PART1_MPF",))]
    (main,) = items(":10")
    assert (main.letter, main.value) == (":", 10.0)
    (comment,) = items("; (not a comment in parentheses)")
    assert type(comment) is Comment and comment.style == ";"


def test_pcall_reads_its_path_whole_and_writes_it_back_as_it_was():
    """`PCALL/_N_WKS_DIR/_N_SHAFT_WPD/SHAFT(R1, 2)` (Job Planning manual, "Subprogram call with path
    specification and parameters (PCALL)"): the path is the call's first argument, a string; the
    parser refused a path (`unexpected '/_N_WKS_DIR...'`) and read `PCALL SHAFT(1)` as two calls."""
    assert statements("N20 PCALL/_N_WKS_DIR/_N_SHAFT_WPD/SHAFT(R1, 2) ; shaft") == [
        ("call", ("PCALL", (("str", "/_N_WKS_DIR/_N_SHAFT_WPD/SHAFT"), ("param", "r1"), ("num", 2.0))))
    ]
    assert statements("pcall SHAFT(1,,3)") == [("call", ("PCALL", (("str", "SHAFT"), ("num", 1.0), None,
                                                                   ("num", 3.0))))]  # fmt: skip
    assert statements("PCALL /WKS.DIR/SHAFT.SPF") == [("call", ("PCALL", (("str", "/WKS.DIR/SHAFT.SPF"),)))]
    assert statements("PCALLS=1") == [("assignment", (("param", "pcalls"), ("num", 1.0)))]
    text = b"PCALL/_N_WKS_DIR/_N_SHAFT_WPD/SHAFT(R1, 2)\r\nN30 pcall  SHAFT ( 1 ) ; x\r\n"
    out = io.BytesIO()
    write_blocks(parse_stream(io.BytesIO(text), "p.mpf", "sinumerik"), out)
    assert out.getvalue() == text


def test_bad_input_names_file_line_and_column():
    with pytest.raises(NcppError) as err:
        list(parse_stream(io.BytesIO(b"G1 X1\nG1 X=(1+2\n"), "bad.mpf", "sinumerik"))
    assert (err.value.where.file, err.value.where.line) == ("bad.mpf", 2) and err.value.where.col >= 1
    with pytest.raises(NcppError) as err:
        list(parse_stream(io.BytesIO(b"G1 X1\r\nIF\r\n"), "bad.mpf", "sinumerik"))
    assert str(err.value).startswith("bad.mpf:2:")


@pytest.mark.parametrize(
    "block, column, message",
    [
        (
            "G1 X=1e3 Y10",
            7,
            "X=1e3: a Sinumerik writes an exponent as EX (X=1EX3); as written this is X=1 and an address E",
        ),
        ("G1 X=2*1E-3", 9, "X=2*1E-3: a Sinumerik writes an exponent as EX (X=2*1EX-3)"),
        ("R1=5e2", 5, "R1=5e2: a Sinumerik writes an exponent as EX (R1=5EX2)"),
    ],
)
def test_an_exponent_written_with_e_is_refused_not_read_as_an_address(block, column, message):
    """`X=1e3` parses as `X=1` and a word E3 (as on the control, where E is no exponent): moving
    to X1 would be a silently wrong program."""
    blocks = parse_stream(io.BytesIO(f"G0 X100\n{block}\nM30\n".encode()), "e.mpf", "sinumerik")
    with pytest.raises(NcppError) as err:
        list(interpret(blocks, file="e.mpf"))
    assert (err.value.where.line, err.value.where.col) == (2, column) and message in str(err.value)


def test_an_exponent_written_with_ex_is_a_number():
    blocks = parse_stream(io.BytesIO(b"G0 X100\nG1 X=1EX2 F100\nX=1 E3\nM30\n"), "e.mpf", "sinumerik")
    ends = [e.end[0] for e in interpret(blocks, file="e.mpf") if hasattr(e, "end")]
    assert ends == [100.0, 100.0, 1.0]  # `X=1 E3` apart: an address E, as the control reads it


@pytest.mark.parametrize(
    "block, what",
    [
        ("G2 AR=90 I5 J0 F100", "the opening angle AR="),
        ("G1 AP=45 RP=10 F100", "the polar angle AP="),
        (
            "L100 P2",
            "the subprogram call L100 (its file not found: no --subroutine-path gives the folders of "
            "called files)",
        ),  # was ignored: the next block's Y and Z were written as before the call
    ],
)
def test_geometry_the_interpreter_does_not_follow_ends_interpretation(block, what):
    """`G2 AR=90 I5` was read as a full circle about I5 (AR ignored), and AR=90 copied into every piece."""
    events, said = interpreted(f"G0 X0 Y0 Z0\n{block}\nG1 X3\nM30\n")
    assert "a.mpf:2:" in said and f"warning: {what} is outside" in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)


def test_a_string_parameter_of_a_procedure_carries_its_length():
    """`proc ms100(string[32] alat, ...)` (NadjImre/NC-Programi-za-FB422, CMA.DIR/MS100.SPF) was
    refused as a syntax error: the Job Planning manual's PROC takes the types DEF takes, STRING[n] too."""
    assert statements("proc ms100(string[32] alat,int ivica, real duz_mer)") == [
        (
            "proc",
            (
                "MS100",
                (
                    ("STRING", "alat", False, None),
                    ("INT", "ivica", False, None),
                    ("REAL", "duz_mer", False, None),
                ),
                (),
            ),
        )
    ]
    text = "PROC P(STRING[8] NAME, REAL D)\nG0 X0 Y0 Z0\nG1 X5 F100\nM17\n"
    events, said = interpreted(text, "p.spf")
    assert not said and [type(e) is Pass for e in events if e.block.line == 3] == [False]


def test_a_value_list_is_read_and_left_out_of_scope():
    """`OSCTRL[Z]=(1+2,16+32+64)` (NadjImre/NC-Programi-za-FB422, CMA.DIR/SH100.SPF), the oscillation
    options of Function Manual Extended Functions, "Oscillation (P5)" (`OSCTRL[<axis>]=(<set>,<reset>)`),
    was refused as a syntax error; a value in parentheses alone stays arithmetic."""
    ((kind, (target, value)),) = statements("OSCTRL[Z]=(1+2,16+32+64)")
    assert (kind, target[:2], value[0], len(value[1])) == ("assignment", ("index", "osctrl"), "list", 2)
    assert statements("R1=(2+3)")[0][1][1][0] == "bin"
    text = "G0 X0 Y0 Z0\nOSCTRL[Z]=(1+2,16+32+64)\nG1 X3 F100\nM30\n"
    events, said = interpreted(text)
    assert "a.mpf:2:1: warning: the value list assigned to OSCTRL is outside" in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)


@pytest.mark.parametrize(
    "block",
    [
        "ID=7 EVERY $A_IN[7]<>0 DO $R1=1",
        "ID=8 EVERY ($AA_IM[Z]<>$SA_OSCILL_REVERSE_POS1[Z]) AND ($R2<=0) DO $R1=1 ; note",
        "IDS=2 WHENEVER $R1==0 DO $AA_OVR[X]=0",
        "WHEN $AA_IW[X]>5 DO M120",
        "DO $A_OUTA[1]=$AA_IN[X]",
    ],
)
def test_a_synchronized_action_is_read_whole_and_left_out_of_scope(block):
    """`ID=7 EVERY $A_IN[7]<>0 DO $R1=1` (NadjImre/Paket-NC-programa-za-418, CMA.DIR/SH200.SPF) was refused
    as a syntax error at `<>`. Function Manual Synchronized Actions, "Definition of a synchronized action":
    `[ID=<n>|IDS=<n>] [WHEN|WHENEVER|FROM|EVERY] <condition> DO <actions>`, alone in its block."""
    ((kind, (text,)),) = statements(block)
    assert (kind, text) == ("sync_action", block)
    text = f"G0 X0 Y0 Z0\n{block}\nG1 X3 F100\nM30\n"
    events, said = interpreted(text)
    warning = "a.mpf:2:1: warning: the synchronized action (it acts beside the blocks) is outside"
    assert warning in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)


def test_names_that_begin_like_a_synchronized_action_stay_names():
    assert statements("DOX=5 FROM_A=1")[0] == ("assignment", (("param", "dox"), ("num", 5.0)))
    assert statements("N10 G1 X5 WHENX")[0] == ("call", ("WHENX", ()))


@pytest.mark.parametrize(
    "block, what",
    [
        ("G1 X5 Y2 RND=1 F100", "the rounding RND="),
        ("G1 X5 Y2 CHF=1 F100", "the chamfer CHF="),
        ("G1 X5 CHR=1 F100", "the chamfer CHR="),
        ("RNDM=0.5", "the modal rounding RNDM="),
        ("G1 X5 ANG=30 F100", "the contour angle ANG="),
        ("G1 X5 MEAS=1 F100", "the measuring move MEAS="),
        ("G1 X5 MEAW=1 F100", "the measuring move MEAW="),
        ("G1 X5 TOFFL=5 F100", "the programmable tool length offset TOFFL="),
        ("G1 X5 TOFFR=0.2 F100", "the programmable tool radius offset TOFFR="),
        ("G1 X5 DL=1 F100", "the sum offset DL="),
        ("G1 X5 DISC=2 F100", "the transition circle DISC="),
        ("G1 X5 DISR=4 F100", "the approach distance DISR="),
    ],
)
def test_corner_contour_and_measuring_words_end_interpretation(block, what):
    """`G1 X=xpos-duz_mer MEAS=1 F=brz_mer` (NadjImre/NC-Programi-za-FB422, CMA.DIR/MS100.SPF) and
    `RND=1` were read as assignments to user variables and dropped: the probing move was compensated as
    a plain move, and RND=1 stayed on the first piece of the split move, rounding the wrong corner.
    They are words of the block (Fundamentals, "Chamfer, rounding (CHF, CHR, RND, RNDM, FRC, FRCM)",
    "Contour definitions"; Job Planning, "Measurements with touch trigger probe (MEAS, MEAW)").  So are
    the tool offsets a program sets (TOFFL, TOFFR, the sum offset DL), which change the length the moves
    are placed with, and the transition circle and approach distances (DISC, DISR), whose path the
    control shapes."""
    word = block.split()[-2] if block.endswith("F100") else block
    assert exprs(block).keys() >= {word.split("=")[0]}
    events, said = interpreted(f"G0 X0 Y0 Z0\n{block}\nG1 X3\nM30\n")
    assert "a.mpf:2:" in said and f"warning: {what} is outside" in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)


@pytest.mark.parametrize("block, name", [
    ("DIAMON", "DIAMON"), ("TRAORI", "TRAORI"), ("TRACYL(40)", "TRACYL"),
    ('CTABDEF(X,C,1,1,"DRAM")', "CTABDEF"),
    ("SETINT(8) PRIO=1 SH600", "SETINT"), ('EXECSTRING("G1 X4")', "EXECSTRING"),
])  # fmt: skip
def test_a_predefined_procedure_is_named_as_such_not_looked_for_as_a_file(block, name):
    """`DIAMON`, `CTABDEF(X,C,1,1,"DRAM")`, `SETINT(8) PRIO=1 SH600`, `EXECSTRING( NAZPROG )`
    (NadjImre/NC-Programi-za-FB422, CMA.DIR/SH000.SPF, TB100.SPF) were looked for as subprogram files and
    the warning asked for a --subroutine-path; they are the control's own procedures."""
    events, said = interpreted(f"G0 X0 Y0 Z0\n{block}\nG1 X3\nM30\n")
    assert f"a.mpf:2:1: warning: the predefined procedure {name} is outside" in said
    assert "file not found" not in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)


@pytest.mark.parametrize("block", ["WAITP(Z)", "WAITS(2)", "SETMS(1)", "CLRINT(8)"])
def test_waits_and_settings_that_move_nothing_are_followed_through(block):
    """`WAITP(Z)`, `CLRINT(8)`, `WAITS(2)` (NadjImre/NC-Programi-za-FB422, SH100.SPF, SH000.SPF;
    Paket-NC-programa-za-418, ML000.SPF) ended interpretation as calls of missing files."""
    events, said = interpreted(f"G0 X0 Y0 Z0\n{block}\nG1 X3 F100\nM30\n")
    assert not said
    assert [type(e) is Pass for e in events if e.block.line == 3] == [False]


def test_the_concatenation_operator_alone_converts_to_a_string():
    """`SETAL(65017,<<(BROJ))` (NadjImre/Paket-NC-programa-za-418, CMA.DIR/SM000.SPF) was refused as a
    syntax error: Job Planning manual, "String operations": `STRING_ERG = <<any type`."""
    assert statements("SETAL(65017,<<(BROJ))") == [
        ("call", ("SETAL", (("num", 65017.0), ("bin", "<<", ("str", ""), ("param", "broj")))))
    ]
    assert statements('MSG("A"<< <<R2)')[0][1][1][0] == (
        "bin",
        "<<",
        ("str", "A"),
        ("bin", "<<", ("str", ""), ("param", "r2")),
    )


def test_a_contour_offset_ends_interpretation_and_its_reset_does_not():
    """`OFFN=2` was read and ignored: under G41/G42 the control cuts 2 mm further from the contour
    (Fundamentals, "Tool radius compensation (G40, G41, G42, OFFN)")."""
    text = "G0 X0 Y0 Z0\nG1 X5 Y1 OFFN=2 F100\nG1 X3\nOFFN=0\nM30\n"
    events, said = interpreted(text)
    assert "a.mpf:2:10: warning: the contour offset OFFN= is outside" in said
    assert all(type(e) is Pass for e in events if e.block.line >= 2)
    text = "G0 X0 Y0 Z0\nG1 X5 Y1 OFFN=0 F100\nG1 X3\nM30\n"
    events, said = interpreted(text)
    assert not said and [type(e) is Pass for e in events if e.block.line == 3] == [False]


@pytest.mark.parametrize("block", ["FB=50", "MYGUD=3", "ADISX=1"])
def test_an_assignment_to_a_name_the_program_does_not_define_ends_interpretation(block):
    """A name the program does not DEF is a global variable of the control's files or an address
    ncpp does not read (`FB=`, the feed of one block, which a split move would carry on its first
    piece only): both were stored as a variable of the program and the block's effect dropped."""
    text = f"G0 X0 Y0 Z0\nG1 X1 F100\n{block}\nG1 X3\nM30\n"
    events, said = interpreted(text)
    assert "a.mpf:3:1: warning: the assignment to " in said and "not defined" in said
    assert all(type(e) is Pass for e in events if e.block.line >= 3)


def test_settings_cam_posts_write_and_defined_variables_are_followed():
    """`ADIS=`, `CTOL=` and the like set smoothing and tolerances, no path (they are words, not
    variables); a DEF'd variable, an R parameter and a FOR counter are the program's own."""
    said = io.StringIO()
    text = ("DEF REAL DEPTH=2\nG0 X0 Y0 Z0\nADIS=0.5 CTOL=0.01 G642\nR1=4\nDEPTH=DEPTH+1\n"
            "FOR K=1 TO 2\nG1 X=K*R1 Z=-DEPTH F100\nENDFOR\nM30\n")  # fmt: skip
    events = list(interpret(parse_stream(io.BytesIO(text.encode()), "a.mpf", "sinumerik"), file="a.mpf",
                            warnings=Warnings(stream=said)))  # fmt: skip
    assert "outside" not in said, said
    ends = [e.end for e in events if type(e) is Line]
    assert ends[-2:] == [(4.0, 0.0, -3.0), (8.0, 0.0, -3.0)]


def test_an_r_parameter_read_before_the_program_sets_it_is_out_of_scope():
    """The channel's R parameters hold what an earlier program or a measuring cycle left there (840C
    installation guide, NC setting data, "R parameters"): `G1 X=R1`, R1 unset, ends interpretation at its
    block, where it was read as 0 (and rewritten as a move to X0); set first, it is followed."""
    from ncpp.errors import Warnings
    from ncpp.motion.segments import Line, Pass
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    run, _ = dialect_tools("sinumerik")
    for head, ends in (("", None), ("R1=4\n", 4.0)):
        said = io.StringIO()
        text = "G17 G90 G54\nG0 X10 Y10 Z5\n" + head + "G1 X=R1 F100\nM30\n"
        _, blocks = parse_program(io.BytesIO(text.encode()), "p.mpf", "sinumerik")
        moves = [
            e for e in run(blocks, file="p.mpf", warnings=Warnings(stream=said)) if type(e) in (Line, Pass)
        ]
        if ends is None:
            assert "3:4: warning: the R parameter R1 (not set in the program" in said.getvalue(), (
                said.getvalue()
            )
            assert [type(e) for e in moves][-2:] == [Pass, Pass]
        else:
            assert [e.end[0] for e in moves if type(e) is Line][-1] == ends
