"""A Fanuc file whose subprograms stand before its main program is read ahead to tell which program
is the main one (`Flow._stored_first`), but not to its end: the lines held stay bounded however long
the main program runs (memory flat in program length).  Past the read-ahead the program the lines
read make the main one runs so, and the rest of the file must agree, else the program is refused.

Judged by the flow's own buffer (the lines held, counted, not the process's memory) with the bounds
made small, and by the same program read with the bounds as they are: the moves and the compensated
text are the same."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError
from ncpp.motion import flow
from tests.motion.test_fanuc_files import moves
from tests.writeback.conftest import compensate_file
from tests.writeback.test_compensated_holes import MACHINE

STORED = "%\nO2000 (SIDE)\nG91 G1 X1 F300\nG1 Y1\nG90\nM99\nO3000\nG91 G1 Y-1 F300\nG90\nM99\n"
AFTER = "O4000\nG91 G1 Z-1\nG90\nM99\n%\n"
SMALL = {"MAX_SUBPROGRAM": 50, "_TRIM": 64}  # the bounds made small: a few hundred lines go past them


def long_main(lines: int, end: str = "M30") -> str:
    """O1000: `lines` feed moves around a square, M98 calls among them, then `end`."""
    moves = [f"G1 X{i % 40} Y{(i * 7) % 40} F500" for i in range(lines)]
    moves[lines // 3] += "\nM98 P2000"
    moves[lines // 2] += "\nM98 P3000"
    return (
        "O1000 (MAIN)\nG21 G90 G54 G17\nG0 X0 Y0 Z5\nG1 Z-1 F200\n" + "\n".join(moves) + f"\nG0 Z5\n{end}\n"
    )


@pytest.fixture
def small(monkeypatch):
    """The read-ahead's bounds made small, and the most lines the flow holds at once, as it reads."""
    held = [0]
    keep = flow.Flow._keep

    def counted(self, block):
        keep(self, block)
        held[0] = max(held[0], len(self.buffer))

    for name, value in SMALL.items():
        monkeypatch.setattr(flow, name, value)
    monkeypatch.setattr(flow.Flow, "_keep", counted)
    return held


def test_the_lines_held_stay_bounded_however_long_the_main_program_runs(small):
    program = STORED + long_main(2_000) + AFTER
    said = io.StringIO()
    found = moves(program, "fanuc", said)
    assert "ncpp runs O1000 as the main program; O2000 and O3000 are subprograms" in said.getvalue()
    assert "outside" not in said.getvalue(), said.getvalue()
    assert small[0] <= 3 * SMALL["_TRIM"] + SMALL["MAX_SUBPROGRAM"] + STORED.count("\n"), small[0]
    assert len(found) > 2_000


def test_past_the_read_ahead_the_moves_are_those_of_the_whole_file_read(monkeypatch):
    program = STORED + long_main(600) + AFTER
    whole = moves(program, "fanuc")
    for name, value in SMALL.items():
        monkeypatch.setattr(flow, name, value)
    assert moves(program, "fanuc") == whole and len(whole) > 600


def test_past_the_read_ahead_the_compensated_text_is_the_same(tmp_path, monkeypatch):
    (tmp_path / "p.nc").write_text(STORED + long_main(300) + AFTER)
    whole = compensate_file(tmp_path / "p.nc", MACHINE, tmp_path, dialect="fanuc").read_bytes()
    for name, value in SMALL.items():
        monkeypatch.setattr(flow, name, value)
    bounded = compensate_file(tmp_path / "p.nc", MACHINE, tmp_path, dialect="fanuc").read_bytes()
    assert bounded == whole and b"G1 X" in whole


@pytest.mark.parametrize(
    "rest, why",
    [
        ("O5000\nG0 X5\nM30\n%\n", "2 later programs end with M30 or M2 (O1000, O5000)"),
        ("", "no later program of the file ends with M30 or M2"),
    ],
)
def test_where_the_rest_of_the_file_names_no_main_program_or_another_the_program_is_refused(small, rest, why):
    """Read whole, the file passes through (`test_fanuc_files.UNTOLD`); past the read-ahead its main
    program has run, so it is refused: no line of it is written."""
    program = STORED + long_main(300, "M30" if rest else "M99") + rest + ("" if rest else "%\n")
    with pytest.raises(NcppError) as refused:
        moves(program, "fanuc")
    assert f"ncpp ran O1000 as the main program, from the first 50 blocks after its O line, but the file goes on and {why}" in str(refused.value)  # fmt: skip
    assert refused.value.where.line == STORED.count("\n") + 1


# The usual layout: the main program first, its subprograms after M30, called from far before them
CALLED_AHEAD = "%\nO1000\nG21 G90 G54 G17\nG0 X0 Y0 Z5\nM98 P2000\n{moves}\nG0 Z5\nM30\nO2000\nG91 G1 X1 F300\nG90\nM99\n%\n"


def test_a_call_searches_for_its_subprogram_at_most_max_ahead_blocks_ahead(monkeypatch):
    """Near enough, the call runs it; further ahead, the call is out of scope: the flow holds no more
    than MAX_AHEAD blocks to find it."""
    moves_text = "\n".join(f"G1 X{i % 40} Y{(i * 7) % 40} F500" for i in range(300))
    program = CALLED_AHEAD.format(moves=moves_text)
    near = moves(program, "fanuc")
    for name, value in SMALL.items():  # (the blocks read ahead at the start hold no O2000)
        monkeypatch.setattr(flow, name, value)
    monkeypatch.setattr(flow, "MAX_AHEAD", 1_000)
    assert moves(program, "fanuc") == near and ("STRAIGHT_FEED", (1.0, 0.0, 5.0)) in near
    monkeypatch.setattr(flow, "MAX_AHEAD", 100)
    said = io.StringIO()
    assert moves(program, "fanuc", said) == [("STRAIGHT_TRAVERSE", (0.0, 0.0, 5.0))]
    assert "p.nc:5:1: warning: M98 P2000: a subprogram the program does not define within 100 blocks ahead (ncpp reads no further ahead)" in said.getvalue()  # fmt: skip


def test_a_haas_local_call_searches_for_its_block_at_most_max_ahead_blocks_ahead(monkeypatch):
    moves_text = "\n".join(f"G1 X{i % 40} Y{(i * 7) % 40} F500" for i in range(300))
    program = f"%\nO1000\nG21 G90 G54\nG0 X0 Y0 Z5\nM97 P100\n{moves_text}\nM30\nN100 G1 Z4 F100\nM99\n%\n"
    assert ("STRAIGHT_FEED", (0.0, 0.0, 4.0)) in moves(program, "haas")
    for name, value in SMALL.items():
        monkeypatch.setattr(flow, name, value)
    monkeypatch.setattr(flow, "MAX_AHEAD", 100)
    said = io.StringIO()
    assert moves(program, "haas", said) == [("STRAIGHT_TRAVERSE", (0.0, 0.0, 5.0))]
    assert "p.nc:5:1: warning: M97 P100: N100 is not within 100 blocks ahead" in said.getvalue()


def test_an_o_word_call_searches_for_its_subroutine_at_most_max_ahead_blocks_ahead(monkeypatch):
    moves_text = "\n".join(f"G1 X{i % 40} Y{(i * 7) % 40} F500" for i in range(300))
    program = f"G21 G90\nG0 X0 Y0 Z5\no100 call\n{moves_text}\nM2\no100 sub\nG1 Z4 F100\no100 endsub\n"
    assert ("STRAIGHT_FEED", (0.0, 0.0, 4.0)) in moves(program, "iso")
    for name, value in {**SMALL, "MAX_AHEAD": 100}.items():
        monkeypatch.setattr(flow, name, value)
    said = io.StringIO()
    assert moves(program, "iso", said) == [("STRAIGHT_TRAVERSE", (0.0, 0.0, 5.0))]
    assert "p.nc:3:1: warning: a call of o100, which the program does not define within 100 blocks ahead" in said.getvalue()  # fmt: skip
