"""A word given by an expression (`H#33`) between a block's first two plain words is no separator:
words appended to the block are spelled with the gap between adjacent words.  The block is a Haas
macro program's (its lines 5-10: the tool number in #33, `G52 X [ 0. ] ...`), its G43 move gaining an
X word when compensated; a `G00 X0. Y0.` is added before it so that X is known (the words of G52 set
an offset and position no axis: a word for X there would move it from wherever the control has it)."""

from __future__ import annotations

import subprocess
import sys

import pytest

from ncpp.program.parser import LineParser
from ncpp.program.writer import set_words, spelling
from tests.conftest import ROOT, SHARED
from tests.rs274 import pathcheck

WIDE = SHARED / "machines" / "wide.toml"
PROGRAM = (
    "G00 G17 G40 G49 G80 G90\nG54 \nG52 X [ 0. ] Y [ 0. ] Z [ 0. ] \nG00 X0. Y0.\n\n#33= 10 ( NOMER INSTRUMENTA) \n\n"
    "T#33 M06 \nG43 H#33 Z150. \nG00 X0. Y [ 195. / 2 ] \nM30\n"
)


def test_an_expression_word_between_two_words_is_not_their_separator():
    block = LineParser("haas").parse("G43 H#33 Z150. ")
    assert spelling(block) == (" ", False)
    assert set_words(block, {"Z": "149.9982", "X": "0.0022"}) == "G43 H#33 Z149.9982 X0.0022 "
    packed = LineParser("iso").parse("G1X[#1]Y2")
    assert set_words(packed, {"Z": "3"}) == "G1X[#1]Y2Z3"


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_the_g43_move_gains_its_x_once_and_rs274_runs_the_path(tmp_path):
    program, out = tmp_path / "p.nc", tmp_path / "out.nc"
    program.write_text(PROGRAM)
    command = [
        "compensate",
        "--machine",
        str(WIDE),
        "--dialect",
        "haas",
        "--no-guard",
        str(program),
        "-o",
        str(out),
    ]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    assert proc.returncode == 0, proc.stderr  # (the verifier refused a second H#33)
    g43 = next(line for line in out.read_text().splitlines() if line.startswith("G43"))
    assert g43.count("H#33") == 1 and " X" in g43, g43
    tools = tmp_path / "tool.tbl"
    tools.write_text("T10 P10 Z0 D10 ;\n")  # (rs274 needs the tool #33 calls)
    pathcheck(program, out, "--tool-table", str(tools), "--tol-mm", "0.02")
