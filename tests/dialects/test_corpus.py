"""Heidenhain and Sinumerik corpus programs round-trip byte for byte; every corpus file is detected right."""

from __future__ import annotations

import io

import pytest

from ncpp.program.blocks import DIGITS_AS_ONE
from ncpp.program.dialects import detect, parse_program, sniff
from ncpp.program.parser import LineParser, parse_stream
from ncpp.program.writer import write_blocks
from tests.conftest import CORPUS, READING, corpus_files, corpus_id, expected_signature

HEIDENHAIN = corpus_files("heidenhain")
SINUMERIK = corpus_files("sinumerik")
OTHERS = corpus_files("iso_gcode", "malformed", "apt_cldata", "metrology")
GRBL = corpus_files("iso_gcode/freecad_grbl")  # FreeCAD's grbl posts say so in their first comment
# Fanuc programs: a program number line (`O9250`, `O0001`), as LinuxCNC's tests of Fanuc subprograms have
FANUC = [CORPUS / "iso_gcode/haas_fanuc_macroB/O9250-DynamicOffsetRotation.nc"] + [
    CORPUS / f"iso_gcode/linuxcnc_fanuc_subs/{name}"
    for name in ("01-basics__test.ngc", "05-M98-loops__test.ngc", "07-nested-subs__test.ngc",
                 "08-sub-follows-main__test.ngc", "09-disable-fanuc-subs__test-fanuc.ngc", "10-M98-P001__test.ngc",
                 "13-named-program__test-numbered.ngc")
] + [CORPUS / "malformed/linuxcnc_m98m99/03-error-M98-no-P-word__test.ngc"] + [
    # or a macro statement (`IF [..] GOTO`, `WHILE [..] DO1`) of a program named `OCIRCLE(...)`
    CORPUS / f"iso_gcode/fanuc_macroB_sheet/{name}.NC" for name in ("7997A", "CIRCLE", "RECTANGLE")
]  # fmt: skip
PLAN_H = CORPUS / "heidenhain/jstjst_Heidenhain-Cycles/Plan.h"  # continuation lines, a cycle, a GPL header
# Plain G code with `;` comments: nothing in it is Sinumerik-only, only its name tells.
CONTENT_AMBIGUOUS = {"multiple_m_codes.mpf"}


def roundtrip(data: bytes, name: str, dialect: str) -> bytes:
    out = io.BytesIO()
    write_blocks(parse_stream(io.BytesIO(data), name, dialect), out)
    return out.getvalue()


def test_corpus_has_both_dialects(corpus):
    assert len(HEIDENHAIN) >= 2 and len(SINUMERIK) >= 30


@pytest.mark.parametrize("path", HEIDENHAIN, ids=corpus_id)
def test_heidenhain_program_roundtrips(path):
    data = path.read_bytes()
    assert roundtrip(data, str(path), "heidenhain") == data


@pytest.mark.parametrize("path", SINUMERIK, ids=corpus_id)
def test_sinumerik_program_roundtrips(path):
    data = path.read_bytes()
    assert roundtrip(data, str(path), "sinumerik") == data


@pytest.mark.parametrize("path", HEIDENHAIN + SINUMERIK + OTHERS, ids=corpus_id)
def test_dialect_is_detected(path):
    known = {**dict.fromkeys(HEIDENHAIN, "heidenhain"), **dict.fromkeys(SINUMERIK, "sinumerik"),
             **dict.fromkeys(GRBL, "grbl"), **dict.fromkeys(FANUC, "fanuc")}  # fmt: skip
    want = known.get(path, "iso")
    head = path.read_bytes()[:4096]
    assert detect(head, path.name) == want
    if path.name not in CONTENT_AMBIGUOUS:
        assert detect(head) == want


def test_heidenhain_continuation_lines_make_one_block(corpus):
    path = PLAN_H
    blocks = list(parse_stream(io.BytesIO(path.read_bytes()), str(path), "heidenhain"))
    physical = path.read_bytes().count(b"\n")
    assert len(blocks) == 216 and physical == 223  # blocks 0..215, three comments continued
    third = blocks[3]
    assert third.line == 4 and third.raw.count("\n") == 3
    (number, comment) = third.items
    assert number.value == 3 and comment.style == ";" and "GNU General Public License" in comment.text
    assert blocks[-1].items[1].kind == "program_end" and blocks[-1].items[1].node == ("Plan", "MM")


def test_sinumerik_fast_path_agrees_with_lalr_parser_on_corpus(corpus):
    parser = LineParser("sinumerik")
    checked = 0
    for path in SINUMERIK:
        for block in parse_stream(io.BytesIO(path.read_bytes()), str(path), "sinumerik"):
            fast = parser._scan_plain(block.raw)
            if fast is not None:
                items, signature, layout = fast
                assert items == parser._parse_lalr(block.raw, block.line, str(path)), (path, block.line)
                assert signature == expected_signature(items), (path, block.line)
                assert layout in (None, block.raw.encode("latin-1").translate(DIGITS_AS_ONE)), (
                    path,
                    block.line,
                )
                checked += 1
    assert checked > 100


@pytest.mark.parametrize("size", [1, 7, 4096])
def test_sniff_rereads_the_head_and_keeps_streaming(corpus, size, monkeypatch):
    import ncpp.program.dialects as dialects

    monkeypatch.setattr(dialects, "SNIFF_BYTES", size)
    path = PLAN_H
    data = path.read_bytes()
    dialect, lines = sniff(io.BytesIO(data), path.name)
    assert b"".join(lines) == data
    if size == 4096:
        assert dialect == "heidenhain"
    name, blocks = parse_program(io.BytesIO(data), str(path))
    out = io.BytesIO()
    write_blocks(blocks, out)
    assert out.getvalue() == data


def test_linuxcnc_constructs_outweigh_a_line_that_reads_like_a_label():
    """A note after M2 (`Tools: ...`) reads like a Sinumerik label; o-words and `#<name>` are
    LinuxCNC's alone (was: Sinumerik, and G21 was out of its interpreter's scope)."""
    program = b"G21\no100 sub\nG1 X#1 F100\no100 endsub\no100 call [2]\nM2\nTools: T1 6mm\n"
    assert detect(program) == "iso"
    assert detect(b"#<depth> = 2\nG1 Z-#<depth>\nM2\nnote: deburr\n") == "iso"
    assert (
        detect(b"G21\nG1 X1 F100\nM2\nTools: T1 6mm\n") == "sinumerik"
    )  # (no LinuxCNC construct: a label it is)


def test_explicit_dialect_overrides_detection():
    dialect, _ = sniff(io.BytesIO(b"G1 X1\n"), None, "Sinumerik")
    assert dialect == "sinumerik"


@pytest.mark.parametrize(
    "path", [PLAN_H, CORPUS / "sinumerik/CEAD_nc-gcode-interpreter/edge_cases.mpf"], ids=corpus_id
)
def test_cli_filter_roundtrips_from_stdin(corpus, path):
    import subprocess
    import sys

    data = path.read_bytes()
    out = subprocess.run([sys.executable, "-m", "ncpp"], input=data, capture_output=True, check=True)
    assert out.stdout == data


def test_cli_dialect_option_overrides_and_errors_name_the_line(tmp_path):
    import subprocess
    import sys

    bad = tmp_path / "bad.mpf"
    bad.write_bytes(b"G1 X1\nX=(1+\n")
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--dialect", "sinumerik", "--machine", str(READING), str(bad)],
        capture_output=True,
        text=True,
    )
    assert proc.returncode != 0 and proc.stdout == "" and proc.stderr.startswith(f"{bad}:2:")
    proc = subprocess.run(
        [sys.executable, "-m", "ncpp", "--dialect", "klingon", str(bad)], capture_output=True, text=True
    )
    assert proc.returncode != 0 and "unknown dialect" in proc.stderr and "<stdin>" not in proc.stderr
    good = tmp_path / "good.ngc"
    good.write_bytes(b"G21 G90\nG0 X1\nM2\n")
    proc = subprocess.run([sys.executable, "-m", "ncpp", "motion", "--dialect", "LinuxCNC", str(good)],
                          capture_output=True, text=True)  # fmt: skip
    assert proc.returncode == 0 and "STRAIGHT_TRAVERSE(1.0000" in proc.stdout, proc.stderr


@pytest.mark.parametrize("path", corpus_files("."), ids=corpus_id)
def test_without_a_machine_file_every_corpus_file_passes_through_byte_for_byte(path, tmp_path, capsys):
    """Nothing to compensate: the file is not read as a program, whatever it holds."""
    from ncpp.cli import main

    out = tmp_path / "out"
    assert main([str(path), "-o", str(out)]) == 0
    assert out.read_bytes() == path.read_bytes()
    assert "no machine file, nothing was compensated" in capsys.readouterr().err


# Programs a control would refuse: `ncpp` refuses them too, with a location.
REFUSED = {
    "sinumerik/CEAD_nc-gcode-interpreter/simple.mpf": "circular interpolation without I/J/K",
}


@pytest.mark.parametrize("path", [CORPUS / name for name in REFUSED], ids=corpus_id)
def test_a_program_its_control_refuses_is_refused_with_its_place(path, tmp_path, capsys):
    from ncpp.cli import main

    out = tmp_path / "out"
    status = main(["--machine", str(READING), str(path), "-o", str(out)])
    err = capsys.readouterr().err
    assert status != 0 and REFUSED[corpus_id(path)] in err and err.startswith(f"{path}:")
    assert not out.exists()
