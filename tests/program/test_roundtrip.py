"""Lossless round trip: every ISO-family corpus program comes back byte for byte."""

from __future__ import annotations

import io
import subprocess
import sys

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.pipeline import ErrorSource, process
from ncpp.program.blocks import DIGITS_AS_ONE
from ncpp.program.dialects import parse_program
from ncpp.program.parser import LineParser, parse_stream
from ncpp.program.writer import write_blocks
from tests.conftest import CORPUS, READING, corpus_files, corpus_id, expected_signature

ISO_FOLDERS = ("iso_gcode",)


def reading() -> ErrorSource:
    """A machine to compensate for: ncpp reads a program only when there is one."""
    return ErrorSource.from_machine_file(str(READING))


# Malformed files that are still syntactically valid NC (their errors are semantic).
MALFORMED = [p for p in corpus_files("malformed") if p.suffix in (".ngc", ".gcode", ".nc")]
UNREADABLE = {"exists-1.ngc", "exists-2.ngc", "exists-4.ngc", "messed-up.gcode"}


def roundtrip(data: bytes, name: str) -> bytes:
    out = io.BytesIO()
    write_blocks(parse_stream(io.BytesIO(data), name), out)
    return out.getvalue()


@pytest.mark.parametrize("path", corpus_files(*ISO_FOLDERS), ids=corpus_id)
def test_corpus_program_roundtrips_byte_for_byte(path):
    data = path.read_bytes()
    assert roundtrip(data, str(path)) == data


@pytest.mark.parametrize("path", [p for p in MALFORMED if p.name not in UNREADABLE], ids=corpus_id)
def test_malformed_but_readable_programs_roundtrip(path):
    data = path.read_bytes()
    assert roundtrip(data, str(path)) == data


@pytest.mark.parametrize("name", sorted(UNREADABLE))
def test_unreadable_programs_name_file_line_and_column(corpus, name):
    """A line the grammar cannot read is read as it stands (byte for byte) and refused
    where it runs, as rs274ngc reads it (`Dialect.read_where_run`)."""
    path = next(p for p in MALFORMED if p.name == name)
    assert roundtrip(path.read_bytes(), str(path)) == path.read_bytes()
    with pytest.raises(NcppError) as err, open(path, "rb") as stream:
        process(stream, io.BytesIO(), file=str(path), source=reading())
    where = err.value.where
    assert where.file == str(path) and where.line >= 1 and where.col >= 1


def test_unreadable_lines_that_do_not_run_pass_through_with_a_warning(tmp_path):
    """rs274 reads only the lines it runs: a broken line in an uncalled subroutine, an untaken
    branch or after M2 is no error there (was refused); it passes through with a warning,
    refused with --strict, and one that runs is refused with its own line and column."""
    text = "G21 G90\no1 sub\nG1 X1 F100 Q\no1 endsub\nG1 X0 Y2 Z0 F100\no2 if [0]\nG1 X[1+\no2 endif\nM2\nX?3 (notes)\n"
    path = tmp_path / "dead.ngc"
    path.write_text(text)
    said = io.StringIO()
    out = io.BytesIO()
    with open(path, "rb") as stream:
        process(stream, out, file=str(path), warnings=Warnings(stream=said), source=reading())
    written = out.getvalue().decode()
    assert all(f"\n{line}\n" in written for line in ("G1 X1 F100 Q", "G1 X[1+", "X?3 (notes)"))
    assert [line.split(": warning")[0] for line in said.getvalue().splitlines()] == [
        f"{path}:3:12",
        f"{path}:7:7",
        f"{path}:10:2",
    ]
    with pytest.raises(NcppError, match="the line does not run here"), open(path, "rb") as stream:
        process(stream, io.BytesIO(), file=str(path), strict=True, source=reading())
    path.write_text(text.replace("o2 if [0]", "o2 if [1]"))
    with pytest.raises(NcppError) as err, open(path, "rb") as stream:
        process(stream, io.BytesIO(), file=str(path), source=reading())
    assert (err.value.where.line, err.value.where.col) == (7, 7)


def test_a_parenthesis_inside_a_comment_is_named_so():
    """`( #500 = TIPO de pieza (1-6, 0 = sin pieza)   )` (Tomasarmiento/Spirax O0001.nc): the comment ends at
    its first `)`, the last `)` closes none (rs274: "Nested comment found").  The refusal says so, at that `)`."""
    line = b"(   #500 = TIPO de pieza (1-6, 0 = sin pieza)                  )\n"
    with pytest.raises(
        NcppError, match=r"p\.ngc:2:64: a '\)' after the comment closed, comments do not nest"
    ):
        process(io.BytesIO(b"G21\n" + line + b"M2\n"), io.BytesIO(), file="p.ngc", source=reading())


def test_a_comment_inside_an_expression_is_named_so():
    """`#<d> = [80/SQRT(2)/2/25.4]` (Thaddeus-Maximus/lagun-linuxcnc, `nc_files/spr_hub_drill.ngc`):
    parentheses are a comment in RS274/NGC, not grouping, so the function has no argument (rs274:
    "Left bracket missing after unary operation name").  The comment is closed: the refusal says
    where it stands, not that it is unclosed."""
    with pytest.raises(NcppError, match=r"p\.ngc:2:16: a comment where a value belongs: '\(2\)/2/25\.4\]'"):
        process(io.BytesIO(b"G21\n#<d> = [80/SQRT(2)/2/25.4]\nG0 X#<d>\nM2\n"), io.BytesIO(), file="p.ngc",
                source=reading())  # fmt: skip
    with pytest.raises(NcppError, match=r"unclosed comment: '\(2/2/25\.4\]'"):
        process(
            io.BytesIO(b"G21\n#<d> = [80/SQRT(2/2/25.4]\nM2\n"), io.BytesIO(), file="p.ngc", source=reading()
        )


def test_an_o_word_without_its_keyword_is_named_so():
    """`o<frame_circ> [0][0] [8.0] [+1][-5]  [0.1] [+4+8]` (Thaddeus-Maximus/lagun-linuxcnc,
    `nc_files/programs/HEMA-P057.ngc`): the `call` is missing (rs274: "Unknown control command in o
    word").  The refusal says what is missing, at the arguments."""
    line = b"o<frame_circ> [0][0] [8.0] [+1][-5]  [0.1] [+4+8]\n"
    with pytest.raises(NcppError, match=r"p\.ngc:2:15: an o-word without its keyword \(call, sub, if"):
        process(io.BytesIO(b"G21\n" + line + b"M2\n"), io.BytesIO(), file="p.ngc", source=reading())
    with pytest.raises(NcppError, match=r"p\.ngc:2:6: an o-word without its keyword"):
        process(io.BytesIO(b"G21\no100 [1]\nM2\n"), io.BytesIO(), file="p.ngc", source=reading())


def test_fast_path_agrees_with_lalr_parser_on_corpus(corpus):
    """The plain-line scanner must build exactly what the grammar builds."""
    parser = LineParser("iso")
    checked = 0
    for path in corpus_files(*ISO_FOLDERS):
        for block in parse_stream(io.BytesIO(path.read_bytes()), str(path)):
            if block.line > 3000:  # the large files add nothing new past this
                break
            fast = parser._scan_plain(block.raw)
            if fast is None or block.verbatim:
                continue
            items, signature, layout = fast
            assert items == parser._parse_lalr(block.raw, block.line, str(path)), (path, block.line)
            # the signature the writer reads its facts from is that of the words, the layout that of the text
            assert signature == expected_signature(items), (path, block.line)
            assert layout in (None, block.raw.encode("latin-1").translate(DIGITS_AS_ONE)), (path, block.line)
            checked += 1
    assert checked > 20_000


def test_lines_of_one_layout_are_read_as_the_scanner_reads_each():
    """Lines differing only in their digits are cut where the first one had its words:
    numbers, G numbers in the signature, blanks inside a number, text not from bytes."""
    parser, scanner = LineParser("iso"), LineParser("iso")
    for raw in [
        "G1 X1.5 Y-2",
        "G0 X7.0 Y-9",
        "G90G1X1",
        "G91G0X2",
        " X - 5",
        " X - 6",
        "X1 (a)",
        "X2 (b)",
        "X1 (\u20ac)",
    ]:
        assert parser._scan_plain(raw)[:2] == scanner._scan_items(raw), raw
    assert parser._scan_plain("G0 X7.0 Y-9")[1:] == ("G0XY", b"G1 X1.1 Y-1")
    assert parser._scan_plain("X1 (\u20ac)")[2] is None  # (text not from bytes: no layout)


@pytest.mark.parametrize("raw", ["X1 @;c   ", "G1 X1 $;comment    ", "@@(;;)@;c   ", "X1 @ Y2", "X1 Y2 #"])
def test_a_stray_character_is_left_to_the_lalr_parser(raw):
    """The scanner's spans follow from the lengths of what it read: a character it
    skipped would shift them (and hide the error); the grammar must see the line."""
    parser = LineParser("iso")
    assert parser._scan_plain(raw) is None
    with pytest.raises(NcppError):
        parser._parse_lalr(raw, 1, "t.ngc")


def test_cli_passthrough_is_byte_identical(corpus, tmp_path):
    path = CORPUS / "iso_gcode/cncjs_toolpath_fixtures/arc-no-plane.nc"  # CRLF
    out = subprocess.run(
        [sys.executable, "-m", "ncpp"], input=path.read_bytes(), capture_output=True, check=True
    )
    assert out.stdout == path.read_bytes()
    target = tmp_path / "out.nc"
    subprocess.run([sys.executable, "-m", "ncpp", str(path), "-o", str(target)], check=True)
    assert target.read_bytes() == path.read_bytes()


def test_cli_error_has_location_no_traceback_and_no_output(tmp_path):
    bad = tmp_path / "bad.nc"
    bad.write_bytes(b"G1 X1\nG1 X2 Y(unclosed\nG1 X3\n")
    target = tmp_path / "out.nc"
    machine = ["--machine", str(READING)]
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", *machine, str(bad), "-o", str(target)], capture_output=True, text=True
    )
    assert proc.returncode != 0
    assert proc.stderr.startswith(f"{bad}:2:")
    assert "Traceback" not in proc.stderr
    assert not target.exists()
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", *machine], input=bad.read_bytes(), capture_output=True
    )
    assert proc.returncode != 0 and proc.stdout == b""


@pytest.mark.parametrize(
    "program, name",
    [(b"%\nG1 X1 F100\n%\n", "p.ngc"), (b"BEGIN PGM X MM\nL X+1 R0 FMAX\nEND PGM X MM\n", "p.h")],
)
def test_a_byte_order_mark_is_named_not_shown_as_latin_1(program, name):
    with pytest.raises(NcppError) as err:
        list(parse_program(io.BytesIO(b"\xef\xbb\xbf" + program), name, None)[1])
    assert str(err.value).startswith(f"{name}:1:1: the file starts with a UTF-8 byte order mark")


def test_lines_ended_by_cr_alone_are_refused_not_read_as_one_line():
    with pytest.raises(
        NcppError, match=r"^p\.ngc:1:2: the program's lines end in a carriage return \(CR\) alone"
    ):
        list(parse_program(io.BytesIO(b"%\rG21 G90\rG1 X10 F100\r%\r"), "p.ngc", None)[1])
    blank_crs = b"G21\r\r\nG1 X1 F100 \r\r\n"  # a CR doubled before the LF ends the line still
    assert (
        b"".join(
            b.raw.encode() + b.eol.encode() for b in parse_program(io.BytesIO(blank_crs), "p.ngc", None)[1]
        )
        == blank_crs
    )


# Programs LinuxCNC's interpreter refuses too (rs274 prints the same error):
# `ncpp` refuses to compensate them rather than rewrite a program it cannot make sense of.
REFUSED_LIKE_LINUXCNC = {
    "iso_gcode/cncjs/Circle_Diamond_Square_Calibration.gcode": "Radius to end of arc differs",
    "iso_gcode/cncjs/full-circle-without-xyz.gcode": "R i j k words all missing for arc",
    "iso_gcode/cncjs_toolpath_fixtures/arc-r.nc": "R i j k words all missing for arc",
    "iso_gcode/cncjs_toolpath_fixtures/g92offset.nc": "All axes missing with g52 or g92",
    "iso_gcode/camotics_tests/varRefTests__GlobalNamedTest__data__stdin": "Cannot assign to read-only parameter #<_x>",
    "iso_gcode/camotics_tests/varRefTests__LocalNamedTest__data__stdin": "Named parameter #<x> not defined",  # a subroutine's own
}


@pytest.mark.parametrize("name", sorted(REFUSED_LIKE_LINUXCNC))
def test_a_program_linuxcnc_refuses_is_refused_with_its_place(name, tmp_path, capsys, corpus):
    from ncpp.cli import main

    path = corpus / name
    out = tmp_path / "out"
    status = main(["--machine", str(READING), str(path), "-o", str(out)])
    err = capsys.readouterr().err
    assert status != 0 and REFUSED_LIKE_LINUXCNC[name] in err and err.startswith(f"{path}:")
    assert not out.exists()


@pytest.mark.parametrize(
    ("raw", "words"),
    [
        ("G1 X1 5 Y2", [("G", 1.0, "1"), ("X", 15.0, "15"), ("Y", 2.0, "2")]),
        ("X 2 0 . 5 Y- 1 2", [("X", 20.5, "20.5"), ("Y", -12.0, "-12")]),
        ("G 0 1 X3", [("G", 1.0, "01"), ("X", 3.0, "3")]),
        ("X1 . 5 Z. 2 F100 .", [("X", 1.5, "1.5"), ("Z", 0.2, ".2"), ("F", 100.0, "100.")]),
        ("G1 X9 0 ,R2 . 5", [("G", 1.0, "1"), ("X", 90.0, "90"), (",R", 2.5, "2.5")]),
    ],
)
def test_blanks_between_a_numbers_digits_are_read_as_rs274_reads_them(raw, words):
    """rs274ngc reads a line with its blanks removed: `X1 5` is X15.  The word's span
    covers its digits and the blanks between them, not a blank after the last one."""
    parser = LineParser("iso")
    for _ in range(
        2
    ):  # the first read learns the line's layout; the second goes as it says (to the scanner again: blanks in a number)
        found = parser.parse(raw).words()
        assert [(w.letter, w.value, w.number) for w in found] == words
        assert all(not raw[w.start : w.end].endswith(" ") for w in found)
    assert parser._scan_plain(raw)[0] == parser._parse_lalr(raw, 1, "t.ngc")
    program = f"G1 F100\n{raw}\nG1 Y9\n".encode()
    out = io.BytesIO()
    process(io.BytesIO(program), out, file="t.ngc")
    assert out.getvalue() == program
