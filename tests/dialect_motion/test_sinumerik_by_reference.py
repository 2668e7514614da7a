"""Sinumerik subprograms with parameters by reference (`PROC NAME(VAR REAL A, ...)`) and the call
with a path (`PCALL/_N_WKS_DIR/_N_PART_WPD/NAME(...)`).

The rules (840D sl Programming Manual, Job Planning, "Subprogram technique": "Subprograms with
parameter transfer", call-by-value and call-by-reference; SINUMERIK One Programming Manual NC
programming 12/2019, 6FC5398-2EP40-0BA0, 3.2.1.6 "Parameter transfer"; Job Planning, "Subprogram
call with path specification and parameters (PCALL)"): a VAR parameter names the caller's variable
itself (an R parameter, a variable or an array of the program), so what the subprogram assigns to
it the caller reads after the call; a value parameter is a copy.  `PCALL path/NAME(args)` calls
the program the path ends in with those parameters; without a path as a call by the name.

The judges: moves worked out by hand from those rules (each test says how), and the same program
written again by hand with the values inlined (no call), which ncpp reads without calling
anything: the two must move alike.  There is no Sinumerik control here."""

from __future__ import annotations

import pytest

from ncpp.motion.sinumerik import interpret as sinumerik
from tests.dialect_motion.test_subprogram_calls import _events, _folder, _path

# The manual's pattern: the caller's variables given by reference, changed in the subprogram, read
# after it (here a rectangle doubled in length, widened by 5, its area returned in an R parameter)
RECT = """PROC RECT(VAR REAL _LG, VAR REAL _WD, VAR REAL _AREA) DISPLOF
_LG=_LG*2
_WD=_WD+5
G1 X=_LG Y=_WD F100
_AREA=_LG*_WD
RET
"""
MAIN = """DEF REAL LEN=20, WID=10
G0 X0 Y0 Z5
RECT(LEN, WID, R1)
G1 X=LEN Y=WID F100
G1 X=R1/10
PCALL/_N_WKS_DIR/_N_PART_WPD/RECT(LEN, WID, R2)
G1 X=LEN Y=WID+R2/1000
M30
"""


def _moves(text: str, files: dict[str, str], tmp_path) -> tuple[list[tuple], str]:
    events, warned = _events(sinumerik, "sinumerik", text, _folder(tmp_path, files))
    return _path(events), warned


def test_the_caller_reads_what_the_subprogram_assigned_to_its_var_parameters(tmp_path):
    """By hand: LEN 20 -> 40, WID 10 -> 15, R1 = 40 * 15 = 600 (the call's move to X40 Y15, left as
    programmed), then X=LEN Y=WID is X40 Y15 and X=R1/10 X60; the PCALL runs RECT again from 40 and
    15: X80 Y20, R2 = 1600, so the last move ends at X80 Y21.6."""
    moves, warned = _moves(MAIN, {"RECT.SPF": RECT}, tmp_path)
    assert warned == ""
    assert moves == [(0, 0, 2, False), (40, 15, 3, True), (40, 15, 4, False), (60, 15, 5, False),
                     (80, 20, 6, True), (80, 21.6, 7, False)]  # fmt: skip


# One of each way a variable is given by reference: an R parameter the subprogram also reads by its
# own name, one variable given twice, an INT, a 1- and a 2-dimensional array, a string, a variable
# given on to a second subprogram, and a value parameter beside them (a copy: the caller's unchanged)
FILES = {
    "ALIAS.SPF": "PROC ALIAS(VAR REAL _A, VAR REAL _B, VAR REAL _C, REAL _V)\n_A=7\nG1 X=R1 Y=_C F100\n"
    "_B=_B+1\n_C=_C*10\n_V=_V+100\nG1 X=_B Y=_C\nRET\n",
    "COUNT.SPF": "PROC COUNT(VAR INT _N, VAR REAL _P[], VAR REAL _G[,2])\nDEF INT _I\n_N=_N/3\n"
    "FOR _I=0 TO 2\n_P[_I]=_P[_I]*2+_I\nENDFOR\n_G[2,1]=_G[0,0]+_P[2]\nNEXT(_N, _G[1,0])\n"
    "G1 X=_G[1,0] Y=_N F100\nM17\n",
    "NEXT.SPF": "PROC NEXT(VAR INT _K, VAR REAL _E)\n_K=_K+4\n_E=_K*1.5\nRET\n",
    "NAMEIT.SPF": 'PROC NAMEIT(VAR STRING[8] _S)\n_S="L7"\nRET\n',
    "L7.SPF": "G1 X77 Y7 F100\nM17\n",
}
ORIGINAL = """DEF REAL WW=1, UU=2
DEF INT MM=7
DEF REAL QQ[3]=SET(1,2,3)
DEF REAL HH[3,2]=REP(0.5)
DEF STRING[8] PART
G0 X0 Y0 Z5
ALIAS(R1, WW, WW, UU)
G1 X=R1 Y=WW+UU F100
COUNT(MM, QQ, HH)
G1 X=QQ[0] Y=QQ[1]
G1 X=QQ[2] Y=HH[2,1]
G1 X=MM Y=HH[1,0]
NAMEIT(PART)
CALL PART
G1 X0 Y0
M30
"""
# By hand, with the values each name has where it is read: ALIAS: _A is R1, so R1 = 7 at once and
# X=R1 is 7; _B and _C are both WW (1): Y=_C is 1, _B=_B+1 makes WW 2, _C=_C*10 makes it 20, so
# X=_B Y=_C is X20 Y20; _V (a copy of UU) leaves UU 2; after it X=R1 Y=WW+UU is X7 Y22.  COUNT: _N
# is MM, 7/3 rounds to 2; QQ becomes 2, 5, 8; HH[2,1] = 0.5 + 8; NEXT makes MM 6 and HH[1,0] 9; the
# move X9 Y6.  Then QQ: X2 Y5, X8 Y8.5; MM and HH[1,0]: X6 Y9.  NAMEIT sets PART to "L7": CALL PART
# runs L7 (X77 Y7).
INLINED = """G0 X0 Y0 Z5
G1 X7 Y1 F100
G1 X20 Y20
G1 X7 Y22
G1 X9 Y6
G1 X2 Y5
G1 X8 Y8.5
G1 X6 Y9
G1 X77 Y7
G1 X0 Y0
M30
"""


def test_by_reference_moves_as_the_program_with_its_values_inlined(tmp_path):
    moves, warned = _moves(ORIGINAL, FILES, tmp_path)
    inlined, _ = _moves(INLINED, {}, tmp_path)
    assert warned == ""
    assert [(x, y) for x, y, _, _ in moves] == [(x, y) for x, y, _, _ in inlined]
    assert [line for _, _, line, called in moves if called] == [7, 7, 9, 14]  # (the calls' moves)


def test_an_r_parameter_given_on_by_reference_stays_the_r_parameter(tmp_path):
    """By hand: OUTER's _A is R3, given on to INNER's _B, still R3: _B=_B+5 makes R3 6 (X=R3 is 6
    in INNER), OUTER's X=_A Y=R3 is X6 Y6, the caller's X=R3*2 is 12."""
    files = {"OUTER.SPF": "PROC OUTER(VAR REAL _A)\nINNER(_A)\nG1 X=_A Y=R3 F100\nRET\n",
             "INNER.SPF": "PROC INNER(VAR REAL _B)\n_B=_B+5\nG1 X=R3 F100\nRET\n"}  # fmt: skip
    moves, warned = _moves("R3=1\nG0 X0 Y0\nOUTER(R3)\nG1 X=R3*2 Y0\nM30\n", files, tmp_path)
    assert warned == "" and [(x, y) for x, y, _, _ in moves] == [(0, 0), (6, 0), (6, 6), (12, 0)]


@pytest.mark.parametrize(
    "sub, call, said",
    [
        ("PROC SUB(VAR REAL _A)", "SUB(5)", "SUB's parameter VAR REAL _A given a value"),
        ("PROC SUB(VAR REAL _A)", "SUB(WW+1)", "SUB's parameter VAR REAL _A given a value"),
        ("PROC SUB(REAL _B, VAR REAL _A)", "SUB(1)", "SUB's parameter VAR REAL _A not given"),
        ("PROC SUB(VAR INT _A)", "SUB(WW)", "SUB's parameter VAR INT _A given WW, a variable of another type"),
        ("PROC SUB(VAR REAL _A)", "SUB(_GUD_X)", "SUB's parameter VAR REAL _A given _GUD_X (not defined"),
        ("PROC SUB(VAR REAL _A[2])", "SUB(QQ)", "VAR REAL _A given the array QQ[3] of other sizes"),
        ("PROC SUB(VAR REAL _A[])", "SUB(WW)", "VAR REAL _A given other than an array of the program"),
        ("PROC SUB(VAR REAL _A[], VAR REAL _E)", "SUB(QQ, QQ[1])", "SUB given QQ[1] and its array by reference"),
        ("PROC SUB(VAR BOOL _A)", "SUB(WW)", "SUB's parameter VAR BOOL _A"),
    ],
    ids=["a number", "an expression", "omitted", "another type", "not defined here", "array sizes",
         "no array", "element and array", "bool"],
)  # fmt: skip
def test_what_by_reference_is_not_followed_warns_naming_it_and_the_rest_passes(tmp_path, sub, call, said):
    text = f"DEF REAL WW=1\nDEF REAL QQ[3]\nG0 X0 Y0\n{call}\nG1 X5 Y5 F100\nM30\n"
    moves, warned = _moves(text, {"SUB.SPF": f"{sub}\nG1 X1 F100\nRET\n"}, tmp_path)
    assert "main:4:1: warning: " in warned and said in warned, warned
    assert moves == [(0, 0, 3, False)]  # the rest passes through


@pytest.mark.parametrize(
    "call",
    ["PCALL/_N_WKS_DIR/_N_PART_WPD/HOLE(4, R1)", "pcall /_N_SPF_DIR/_N_HOLE_SPF(4, R1)",
     "PCALL/WKS.DIR/PART.WPD/HOLE.SPF(4, R1)", "PCALL HOLE(4, R1)"],
)  # fmt: skip
def test_pcall_runs_the_program_its_path_ends_in(tmp_path, call):
    """The path's folders are the control's program memory: the program is looked for by its name
    on --subroutine-path, as a call by the name is (with `_N_` and the type, or `.SPF`)."""
    files = {"HOLE.SPF": "PROC HOLE(REAL _DIA, VAR REAL _DONE)\nG1 X=_DIA Y=_DIA F100\n_DONE=_DIA*2\nRET\n"}
    moves, warned = _moves(f"G0 X0 Y0\n{call}\nG1 X=R1 Y0\nM30\n", files, tmp_path)
    assert warned == "" and moves == [(0, 0, 1, False), (4, 4, 2, True), (8, 0, 3, False)]


def test_pcall_of_a_program_not_found_warns_naming_it_and_the_folders(tmp_path):
    moves, warned = _moves("G0 X0 Y0\nPCALL/_N_WKS_DIR/_N_PART_WPD/HOLE(4)\nG1 X1\nM30\n", {}, tmp_path)
    assert "main:2:1: warning: call HOLE (its file not found: none of HOLE.SPF" in warned
    assert moves == [(0, 0, 1, False)]


@pytest.mark.parametrize("callpath", ['CALLPATH("/_N_WKS_DIR/_N_PART_WPD")', "callpath()"])
def test_callpath_moves_nothing_and_the_calls_after_it_are_followed(tmp_path, callpath):
    """CALLPATH extends the control's search path for calls without a path (SINUMERIK One
    Programming Manual NC programming 12/2019, 6FC5398-2EP40-0BA0, 3.4.1.4 "Search path for
    subprogram call", step 5; `CALLPATH()` ends the extension): it moves nothing, and ncpp looks a
    called program up on --subroutine-path as for any call by its name."""
    files = {"HOLE.SPF": "PROC HOLE\nG1 X4 Y4 F100\nRET\n"}
    moves, warned = _moves(f"G0 X0 Y0\n{callpath}\nHOLE\nG1 X8 Y0\nM30\n", files, tmp_path)
    assert warned == "" and moves == [(0, 0, 1, False), (4, 4, 3, True), (8, 0, 4, False)]
