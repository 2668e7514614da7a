"""Heidenhain Klartext blocks parse into the common items with the right values."""

from __future__ import annotations

import io
import math

import pytest

from ncpp.errors import NcppError
from ncpp.program.blocks import Comment, ExprWord, Statement, Word
from ncpp.program.parser import LineParser, parse_stream
from ncpp.program.writer import write_blocks

PARSER = LineParser("heidenhain")


def items(text: str) -> tuple:
    return PARSER.parse(text).items


def words(text: str) -> dict[str, float]:
    return {i.letter: i.value for i in items(text) if type(i) is Word}


def statements(text: str) -> list[tuple[str, tuple]]:
    return [(i.kind, i.node) for i in items(text) if type(i) is Statement]


def test_line_with_decimal_comma_and_fmax():
    block = PARSER.parse("7 L X+10,5 Y-3 R0 FMAX")
    assert words(block.raw) == {"N": 7.0, "X": 10.5, "Y": -3.0}
    x = block.words()[1]
    assert x.number == "+10,5" and block.source(x) == "X+10,5"
    assert block.source(block.words()[0]) == "7"
    assert statements(block.raw) == [("path", ("L",)), ("radius_comp", ("R0",)), ("feed", ("FMAX",))]


def test_incremental_words_feed_and_m():
    assert words("L IX+5 IY-2,25 IZ+0 RL F250 M3") == {
        "IX": 5.0,
        "IY": -2.25,
        "IZ": 0.0,
        "F": 250.0,
        "M": 3.0,
    }
    assert ("radius_comp", ("RR",)) in statements("L IX+5 RR FAUTO")
    assert ("feed", ("FAUTO",)) in statements("L IX+5 RR FAUTO")


def test_circle_centre_and_circles():
    assert statements("CC X+0 Y+0") == [("path", ("CC",))] and words("CC X+0 Y+0") == {"X": 0.0, "Y": 0.0}
    assert words("CC IX+5 Y+0") == {"IX": 5.0, "Y": 0.0}
    assert statements("C X+10 Y+0 DR-") == [("path", ("C",)), ("rotation", ("-",))]
    assert words("C X+10 Y+0 DR-") == {"X": 10.0, "Y": 0.0}
    cr = "CR X+10 Y+0 R+5 DR+"
    assert words(cr) == {"X": 10.0, "Y": 0.0, "R": 5.0} and statements(cr)[-1] == ("rotation", ("+",))
    assert statements("CT X+20 Y+5") == [("path", ("CT",))]


def test_rounding_chamfer_and_polar():
    assert statements("RND R5") == [("path", ("RND",))] and words("RND R5") == {"R": 5.0}
    assert statements("CHF 2,5") == [("path", ("CHF", 2.5))]
    assert words("LP PR+50 PA+30 RL F200") == {"PR": 50.0, "PA": 30.0, "F": 200.0}
    assert words("CP IPA+90 DR+") == {"IPA": 90.0}
    assert statements("CP IPA+90 DR+") == [("path", ("CP",)), ("rotation", ("+",))]


def test_q_parameter_words_are_expressions():
    (n, path, x, y, comp, feed) = items("89 L  X+Q1932  Y-Q1931 R0 FQ1820")
    assert type(x) is ExprWord and (x.letter, x.expr) == ("X", ("param", "q1932"))
    assert y.expr == ("neg", ("param", "q1931"))
    assert type(feed) is ExprWord and feed.letter == "F"
    assert items("RND RQ1832")[1].expr == ("param", "q1832")


def test_program_frame_tool_and_blank_form():
    assert statements("0  BEGIN PGM Plan-Beispiel MM ") == [("program_begin", ("Plan-Beispiel", "MM"))]
    assert statements("25 END PGM Plan-Beispiel INCH") == [("program_end", ("Plan-Beispiel", "INCH"))]
    assert statements("1  BLK FORM 0.1 Z  X-200  Y-100  Z-30") == [("blk_form", ("0.1", "Z"))]
    assert words("2  BLK FORM 0.2  X+200  Y+100  Z+0") == {"N": 2.0, "X": 200.0, "Y": 100.0, "Z": 0.0}
    assert (
        statements("3  TOOL CALL 1 Z S800") == [("tool_call", (1, "Z"))]
        and words("TOOL CALL 1 Z S800 F100")["S"] == 800
    )
    assert statements('TOOL CALL "MILL_D10" Z') == [("tool_call", ("MILL_D10", "Z"))]
    assert statements("TOOL DEF 5 L+0 R+5") == [("tool_def", (5,))] and words("TOOL DEF 5 L+0 R+5") == {
        "L": 0.0,
        "R": 5.0,
    }


def test_labels_calls_and_cycles():
    assert statements("LBL 1") == [("label", (1,))]
    assert statements('LBL "Spirale1"') == [("label", ("Spirale1",))]
    assert statements("CALL LBL 1 REP 2/2") == [("call_label", (1, 2))]
    assert statements('CALL LBL "x"') == [("call_label", ("x", 0))]
    assert statements("22 CALL PGM TNC:\\Plan.h") == [("call_program", ("TNC:\\Plan.h",))]
    assert statements("CYCL DEF 1.1 ABST 2") == [("cycle_def", ("1.1", ("ABST", "2")))]
    assert statements("CYCL DEF 7.1 IX+10") == [("cycle_def", ("7.1", ()))] and words(
        "CYCL DEF 7.1 IX+10"
    ) == {"IX": 10.0}
    assert statements("CYCL CALL M3") == [("cycle_call", (None,))]


def test_multi_line_cycle_definition_is_one_block_and_roundtrips():
    text = b"11 CYCL DEF 200 BOHREN ~\r\n    Q200=+2    ;SICHERHEITS-ABST. ~\r\n    Q201=-20,5 ;TIEFE\r\n12 CYCL CALL\r\n"
    blocks = list(parse_stream(io.BytesIO(text), "c.h", "heidenhain"))
    assert len(blocks) == 2 and blocks[0].eol == "\r\n" and blocks[1].line == 4
    kinds = [(type(i).__name__, getattr(i, "kind", None)) for i in blocks[0].items]
    assert kinds == [
        ("Word", None),
        ("Statement", "cycle_def"),
        ("Statement", "assignment"),
        ("Comment", None),
        ("Statement", "assignment"),
        ("Comment", None),
    ]
    assert blocks[0].items[1].node == ("200", ("BOHREN",))
    assert blocks[0].items[4].node == (("param", "q201"), ("num", -20.5))
    assert blocks[0].items[3].text == "SICHERHEITS-ABST. "
    out = io.BytesIO()
    write_blocks(blocks, out)
    assert out.getvalue() == text


def test_a_touch_probe_cycle_is_one_block_and_roundtrips():
    """TCH PROBE blocks as TNC 640 programs write them, the cycle's name with a comma and its Q
    parameters on `~` lines (Stugo/Heidenhain, `Tool-check.h`; polymech-info/heidenhain-simulator,
    `samples/a_phv3/brackets/probe-40.h`); TNC 640 User's Manual, Touch Probe Cycles: `TCH PROBE 412
    DATUM INSIDE CIRCLE`, `TCH PROBE 584 TOOL LENGTH, RADIUS` (here in Swedish)."""
    text = (
        b"TCH PROBE 584 VT-LAENGD, VT-RADIE ~\r\n    Q350=+3    ;MAETFORM ~\r\n"
        b"    Q351=+1    ;MAETOMFANG\r\nM28\r\n"
    )
    blocks = list(parse_stream(io.BytesIO(text), "t.h", "heidenhain"))
    assert len(blocks) == 2
    assert blocks[0].items[0].kind == "touch_probe" and blocks[0].items[0].node == (
        "584",
        ("VT-LAENGD,", "VT-RADIE"),
    )
    assert [i.node[0][1] for i in blocks[0].items if type(i) is Statement and i.kind == "assignment"] == [
        "q350",
        "q351",
    ]
    assert statements("17 TCH PROBE 412 DATUM INSIDE CIRCLE") == [
        ("touch_probe", ("412", ("DATUM", "INSIDE", "CIRCLE")))
    ]
    assert statements("TCH PROBE 0.0 REF PLANE Q10 Z-") == [
        ("touch_probe", ("0.0", ("REF", "PLANE", "Q10 Z-")))
    ]
    out = io.BytesIO()
    write_blocks(blocks, out)
    assert out.getvalue() == text


def test_q_formulas_and_fn_pass_through():
    (_, assign, comment) = items("30 Q1951 = INT ( ( Q1950 / Q1810 ) + 0.99999999 ) ;Anzahl")
    assert assign.node == (
        ("param", "q1951"),
        (
            "call",
            "INT",
            ("bin", "+", ("bin", "/", ("param", "q1950"), ("param", "q1810")), ("num", 0.99999999)),
        ),
    )
    assert comment.text == "Anzahl"
    assert items("Q1800 = - 200")[0].node == (("param", "q1800"), ("num", -200.0))
    assert items("Q1 = PI * Q2 ^ 2")[0].node[1] == (
        "bin",
        "*",
        ("num", math.pi),
        ("bin", "**", ("param", "q2"), ("num", 2.0)),
    )
    assert statements('8  FN 12: IF +Q1840 LT +1 GOTO LBL "1042"') == [
        ("fn", (12, 'IF +Q1840 LT +1 GOTO LBL "1042"'))
    ]
    assert statements("FN 14: ERROR= 1005") == [("fn", (14, "ERROR= 1005"))]


def test_comments():
    (n, c) = items("5  ;----- Zyklus -----")
    assert type(c) is Comment and (c.style, c.text) == (";", "----- Zyklus -----")
    (n, c) = items("6 * - interne Parameter")
    assert (c.style, c.text) == ("*", " - interne Parameter")
    assert statements("STOP M0") == [("keyword", ("STOP",))]


def test_crlf_leading_blanks_and_continued_comment_roundtrip():
    text = b"  0  BEGIN PGM T MM\r\n1 ;lang~\r\n weiter\r\n  2 L X+1,5 Y-0,25 R0 FMAX\r\n3 END PGM T MM\r\n"
    blocks = list(parse_stream(io.BytesIO(text), "t.h", "heidenhain"))
    assert [b.line for b in blocks] == [1, 2, 4, 5]
    out = io.BytesIO()
    write_blocks(blocks, out)
    assert out.getvalue() == text


@pytest.mark.parametrize(
    "text, line, col",
    [
        (b"0 BEGIN PGM T MM\n1 L X+1 Y@2\n", 2, 9),
        (b"0 BEGIN PGM T MM\n1 CYCL DEF 1.0 ~\n  Q1=+1 ;x ~\n  X+1 Y=\n", 4, 7),
    ],
)
def test_bad_input_names_file_line_and_column(text, line, col):
    with pytest.raises(NcppError) as err:
        list(parse_stream(io.BytesIO(text), "bad.h", "heidenhain"))
    where = err.value.where
    assert (where.file, where.line, where.col) == ("bad.h", line, col)


def test_a_hidden_block_keeps_its_slash_before_the_number_and_roundtrips():
    """A TNC writes a hidden block (skipped when block skip is on) with `/` before its number:
    `/ 16 STOP` (janforys/cnc-programming, cnc-programming/Heidenhain/FAZ.H), also in a `~` block."""
    assert statements("/ 16 STOP") == [("block_delete", ("/",)), ("keyword", ("STOP",))]
    assert words("/ 24 L  A+0 FMAX") == {"N": 24.0, "A": 0.0}
    assert words("/16 L X+5 F100")["N"] == 16.0
    text = "/ 23 TCH PROBE 419 PKT.BAZOW.POJED. OSI ~\n    Q263=+0    ;1.PKT POMIAROW 1.OSI\n/ 57 L M30\n"
    blocks = list(parse_stream(io.BytesIO(text.encode()), "p.h", "heidenhain"))
    assert [s.kind for s in blocks[0].items if type(s) is Statement][:2] == ["block_delete", "touch_probe"]
    out = io.BytesIO()
    write_blocks(blocks, out)
    assert out.getvalue().decode() == text


@pytest.mark.parametrize(
    "text",
    ["32 PLANE SPATIAL SPA-90 SPB+0 SPC+90 TURN F5555 SEQ- TABLE ROT",  # janforys, Heidenhain/CHWYT-125.h
     "55 PLANE SPATIAL SPA0 SPB0 SPC0 STAY SEQ+ TABLE ROT", "7 PLANE AXIAL B+45 TURN MB MAX FMAX ; tilt"],
)  # fmt: skip
def test_a_plane_function_is_read_whole_with_its_words_as_written(text):
    """PLANE's words mix keywords, angles, a feed and M140's MB (TNC 640 Klartext manual, "PLANE
    function"): the block is one statement, its words as written (the interpreter leaves it out of scope)."""
    found = statements(text)
    assert found[0][0] == "keyword" and " ".join(found[0][1]) == text.split(" ", 1)[1].split(";")[0].strip()
    assert [type(i) for i in items(text)][-1] is (Comment if ";" in text else Statement)


@pytest.mark.parametrize(
    "text, feed",
    [("79 L  Y+42.9 RL F AUTO", "FAUTO"), ("61 L X160.5 Y-35 R0 F MAX M3", "FMAX"), ("5 L X+1 FMAX", "FMAX")],
)
def test_a_feed_keyword_may_have_a_blank_after_its_f(text, feed):
    """`F AUTO` (janforys/cnc-programming, cnc-programming/Heidenhain/CHWYT-125.h, a TNC's own file) and
    `F MAX` (hyperMILL's Heidenhain post) are FAUTO and FMAX."""
    assert ("feed", (feed,)) in statements(text)


def test_the_old_pocket_cycle_writes_its_corner_radius_after_a_blank():
    """Cycle 4 POCKET MILLING ends its definition with the feed, the direction and the corner radius,
    `RADIUS` and the number apart (iTNC 530 User's Manual, Conversational Programming, "POCKET MILLING
    (Cycle 4)": `CYCL DEF 4.6 F275 DR+ RADIUS 5`); the line is a DMU 50 program's (iTNC 530), its
    block number as a TNC writes it.  Cycle 5's `RADIUS 39` reads the same way."""
    line = "41 CYCL DEF 4.6 F200 DR- RADIUS 16"
    assert statements(line) == [("cycle_def", ("4.6", ())), ("rotation", ("-",))]
    assert words(line) == {"N": 41.0, "F": 200.0, "RADIUS": 16.0}
    assert words("32 CYCL DEF 5.4 RADIUS 39")["RADIUS"] == 39.0
    text = (line + "\n").encode()
    out = io.BytesIO()
    write_blocks(list(parse_stream(io.BytesIO(text), "p.h", "heidenhain")), out)
    assert out.getvalue() == text


def test_contour_geometry_and_tolerance_cycles_parse_as_the_manual_writes_them():
    """Cycle 14 CONTOUR GEOMETRY names its subcontours `CYCL DEF 14.1 CONTOUR LABEL1 /2 /3` and cycle 32
    TOLERANCE its mode `CYCL DEF 32.2 HSC-MODE:0 TA0` (TNC 640 / iTNC 530 User's Manual, Cycle
    Programming, "CONTOUR GEOMETRY (Cycle 14)" and "TOLERANCE (Cycle 32)"; drunsinn/language-klartext,
    `testprogramme/SLII001.klartext`, `Krivka.klartext`).  A `/` in a formula stays a division."""
    assert statements("CYCL DEF 14.1 KONTURLABEL1 /2 /3") == [
        ("cycle_def", ("14.1", ())),
        ("contour_label", (2,)),
        ("contour_label", (3,)),
    ]
    labels = statements("CYCL DEF 14.1 CONTOUR LABEL 1 /2 /3 /4")[1:]
    assert labels == [("contour_label", (n,)) for n in (2, 3, 4)]
    assert statements("CYCL DEF 32.2 HSC-MODE:0 TA0") == [("cycle_def", ("32.2", ("HSC-MODE:0",)))]
    assert statements("Q51 = ( 3 / 4 ) * Q91") == [
        (
            "assignment",
            (("param", "q51"), ("bin", "*", ("bin", "/", ("num", 3.0), ("num", 4.0)), ("param", "q91"))),
        )
    ]
