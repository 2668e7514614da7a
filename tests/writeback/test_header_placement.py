"""The output's header says where the program was compensated for: the work offsets (machine
mm), G92/G52 from the parameter file, the tool table's hash, the units; in comments each
dialect reads as comments (rs274 reports them as COMMENT calls and accepts the program)."""

from __future__ import annotations

import hashlib
import io
import os
import re

import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from ncpp.program.blocks import Comment
from ncpp.program.dialects import parse_program
from tests import rs274
from tests.writeback.conftest import PROGRAMS
from tests.writeback.conftest import SQUARE as MACHINE

VAR = "5220 2\n5221 4\n5222 3.5\n5223 3\n5241 6.0025\n5242 -3.5\n5243 0.125\n5210 1\n5211 0.06\n5212 0\n5213 0\n"
TOOLS = "T1 P1 Z+2.0 D0.25 ;a 6 mm end mill\n"


@pytest.fixture()
def placed(tmp_path):
    machine, var, tools = tmp_path / "square.toml", tmp_path / "linuxcnc.var", tmp_path / "tool.tbl"
    machine.write_text(MACHINE)
    var.write_text(VAR)
    tools.write_text(TOOLS)
    return ErrorSource.from_machine_file(str(machine)), WorkOffsets.given({}, var, 25.4, tools), tools


def compensated(text: str, source, offsets, dialect: str) -> str:
    out = io.BytesIO()
    process(
        io.BytesIO(text.encode()),
        out,
        source=source,
        dialect=dialect,
        offsets=offsets,
        warnings=Warnings(stream=open(os.devnull, "w")),
    )
    return out.getvalue().decode()


def test_iso_header_says_the_placement_and_rs274_reads_it(placed, tmp_path):
    source, offsets, tools = placed
    text = compensated(PROGRAMS["iso"].replace("G21 G90\n", "G21 G90 G55\n"), source, offsets, "iso")
    path = tmp_path / "out.ngc"
    path.write_text(text)
    proc = rs274.run(path)
    if not rs274.ran(proc):
        pytest.skip("rs274 oracle not available")
    assert proc.returncode == 0 and "error" not in proc.stderr.lower(), proc.stderr
    said = " ".join(re.findall(r'COMMENT\("(.*)"\)', proc.stdout))
    assert (
        "G55 in effect at the start: G55 X152.4635 Y-88.9 Z3.175" in said
    )  # the parameter file's inches in mm
    assert "G54 X101.6 Y88.9 Z76.2" in said
    assert "G92/G52 offset X1.524 Y0 Z0 mm" in said
    assert f"sha256:{hashlib.sha256(tools.read_bytes()).hexdigest()[:16]}" in said
    assert "files read in inch" in said and "program units mm" in said


@pytest.mark.parametrize("dialect", ["heidenhain", "sinumerik"])
def test_other_dialects_header_lines_are_comments(placed, dialect):
    source, offsets, tools = placed
    text = compensated(PROGRAMS[dialect], source, offsets, dialect)
    _, blocks = parse_program(io.BytesIO(text.encode()), "out", dialect)
    comments = [item.text for block in blocks for item in block.items if type(item) is Comment]
    said = " ".join(comments)
    assert "ncpp compensated for" in said and "program zero at X153.9875 Y-88.9 Z3.175 machine mm" in said
    assert f"sha256:{hashlib.sha256(tools.read_bytes()).hexdigest()[:16]}" in said
    assert len([c for c in comments if c.strip().startswith("ncpp")]) == 4
