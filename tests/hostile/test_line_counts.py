"""The run summary's "lines in, out" are the files' lines, however many lines a block spans."""

from __future__ import annotations

import re

import pytest

from tests.conftest import SHARED

MACHINE = SHARED / "machines/wide.toml"
CONTINUED = """0 BEGIN PGM CONT MM
1 BLK FORM 0.1 Z X+0 Y+0 Z-20
2 BLK FORM 0.2 X+100 Y+100 Z+0
3 TOOL CALL 1 Z S1000
4 L Z+5 R0 FMAX
5 CYCL DEF 200 DRILLING ~
    Q200=2 ;SET-UP CLEARANCE ~
    Q201=-15 ;DEPTH ~
    Q206=250 ;FEED RATE FOR PLNGNG ~
    Q202=5 ;PLUNGING DEPTH ~
    Q210=0 ;DWELL TIME AT TOP ~
    Q203=+0 ;SURFACE COORDINATE ~
    Q204=50 ;2ND SET-UP CLEARANCE ~
    Q211=0 ;DWELL TIME AT DEPTH
6 L X+10 Y+10 R0 FMAX M99
7 L Z+50 R0 FMAX
8 END PGM CONT MM
"""


@pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
@pytest.mark.parametrize("eol", ["\n", "\r\n"], ids=["lf", "crlf"])
def test_continued_klartext_lines_are_counted_as_lines(ncpp, tmp_path, eol):
    program, written = tmp_path / "cont.h", tmp_path / "out.h"
    program.write_bytes(CONTINUED.replace("\n", eol).encode())
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(written))
    assert done.returncode == 0, done.stderr
    counts = re.search(r"(\d+) lines in, (\d+) out", done.stderr.decode())
    assert counts is not None, done.stderr
    assert int(counts[1]) == CONTINUED.count("\n") == 17
    assert int(counts[2]) == written.read_bytes().count(b"\n")
