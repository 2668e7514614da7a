"""Sinumerik subprogram calls (`L100`, `MYSUB(1, 2)`, `P` runs) and Klartext `CALL PGM`: the called
file, found on --subroutine-path, runs where it is called; its moves are left as programmed
(FLOW: they run from a text ncpp does not rewrite) and the caller's moves after the call are
compensated.  Positions are worked out by hand from the programs; the command line is run end to
end, its verifier reading the input again."""

from __future__ import annotations

import io
from pathlib import Path

import pytest

from ncpp.cli import main
from ncpp.errors import NcppError, Warnings
from ncpp.motion.heidenhain import interpret as heidenhain
from ncpp.motion.offsets import WorkOffsets
from ncpp.motion.segments import FLOW, Arc, Line
from ncpp.motion.sinumerik import interpret as sinumerik
from ncpp.program.dialects import parse_program
from tests.conftest import CORPUS

WIDE = "/work/shared/machines/wide.toml"
ROOT = Path(__file__).resolve().parents[2]
MACHINE = WIDE if Path(WIDE).is_file() else str(ROOT / "samples/machines/hr5b.toml")

# A Sinumerik main program: a subprogram by number twice (incremental moves: each run goes on
# from where the last left), then one by name with value parameters, which sets R1 for the caller
SINUMERIK_MAIN = """N10 G0 X0 Y0 Z10
N20 G1 X10 F100
N30 L0100 P2
N40 G1 X50 Y50
N50 MYSUB(5, 7)
N60 G1 X=R1 Y60
N70 M30
"""
SINUMERIK_FILES = {
    "L0100.SPF": "%_N_L0100_SPF\nN10 G91 G1 X1 Y2\nN20 G90\nN30 M17\n",
    "L100.SPF": "N10 G1 X999\nM17\n",  # another subprogram: leading zeros count
    "_N_MYSUB_SPF": "PROC MYSUB(REAL A, INT B) DISPLOF\nDEF REAL C=0.4\nN10 G1 X=A Y=B+C\nN20 R1=A*2\n"
    "N30 RET\n",
}
# (x, y, line of the main program the move belongs to, left as programmed)
SINUMERIK_PATH = [(0, 0, 1, False), (10, 0, 2, False), (11, 2, 3, True), (12, 4, 3, True),
                  (50, 50, 4, False), (5, 7.4, 5, True), (10, 60, 6, False)]  # fmt: skip

# A Klartext program calling one by its control path; the called program reads the caller's Q1 and
# sets Q2 for it (Q parameters are global), and runs a subprogram of its own (CALL LBL)
HEIDENHAIN_MAIN = """0 BEGIN PGM MAIN MM
1 L X+0 Y+0 Z+10 R0 FMAX
2 L X+10 R0 F100
3 Q1 = 5
4 CALL PGM TNC:\\parts\\SUB1.H
5 L X+Q2 Y+50 R0 F100
6 L X+60 Y+60
7 END PGM MAIN MM
"""
HEIDENHAIN_FILES = {
    "sub1.h": "0 BEGIN PGM SUB1 MM\n1 L IX+Q1 IY+2 R0 F100\n2 CALL LBL 1\n3 Q2 = Q1 * 3\n4 L Z+20 FMAX\n"
    "5 FN 9: IF +0 EQU +0 GOTO LBL 99\n6 LBL 1\n7 L IX+1\n8 LBL 0\n9 LBL 99\n10 END PGM SUB1 MM\n",
}
HEIDENHAIN_PATH = [(0, 0, 2, False), (10, 0, 3, False), (15, 2, 5, True), (16, 2, 5, True),
                   (16, 2, 5, True), (15, 50, 6, False), (60, 60, 7, False)]  # fmt: skip


def _folder(tmp_path: Path, files: dict[str, str]) -> Path:
    folder = tmp_path / "subs"
    folder.mkdir(exist_ok=True)
    for name, text in files.items():
        (folder / name).write_text(text)
    return folder


def _events(interpret, dialect: str, text: str, folder: Path | None) -> tuple[list, str]:
    warned = io.StringIO()
    _, blocks = parse_program(io.BytesIO(text.encode()), "main", dialect)
    offsets = WorkOffsets.given({}, subroutine_path=[folder] if folder else [])
    warnings = Warnings(stream=warned)
    return list(interpret(blocks, file="main", warnings=warnings, offsets=offsets)), warned.getvalue()


def _path(events: list) -> list[tuple]:
    moves = [e for e in events if type(e) is Line or type(e) is Arc]
    return [(round(m.end[0], 6), round(m.end[1], 6), m.block.line, m.fixed == FLOW) for m in moves]


@pytest.mark.parametrize(
    "interpret, dialect, main_text, files, expected",
    [
        (sinumerik, "sinumerik", SINUMERIK_MAIN, SINUMERIK_FILES, SINUMERIK_PATH),
        (heidenhain, "heidenhain", HEIDENHAIN_MAIN, HEIDENHAIN_FILES, HEIDENHAIN_PATH),
    ],
    ids=["sinumerik", "heidenhain"],
)
def test_a_called_file_moves_where_it_is_called_and_the_caller_goes_on_from_there(
    tmp_path, interpret, dialect, main_text, files, expected
):
    events, warned = _events(interpret, dialect, main_text, _folder(tmp_path, files))
    assert warned == ""
    assert _path(events) == [(float(x), float(y), line, fixed) for x, y, line, fixed in expected]


def _motion_cli(capsys, program: Path, folder: Path | None) -> tuple[int, list[str], str]:
    argv = ["motion", str(program)] + (["--subroutine-path", str(folder)] if folder else [])
    status = main(argv)
    out, err = capsys.readouterr()
    return status, out.splitlines(), err


@pytest.mark.parametrize(
    "name, main_text, files, expected",
    [
        ("main.mpf", SINUMERIK_MAIN, SINUMERIK_FILES, SINUMERIK_PATH),
        ("main.h", HEIDENHAIN_MAIN, HEIDENHAIN_FILES, HEIDENHAIN_PATH),
    ],
    ids=["sinumerik", "heidenhain"],
)
def test_ncpp_motion_prints_the_called_moves(tmp_path, capsys, name, main_text, files, expected):
    program = tmp_path / name
    program.write_text(main_text)
    status, lines, err = _motion_cli(capsys, program, _folder(tmp_path, files))
    assert status == 0 and err == ""
    z = {"main.mpf": [10.0] * 7, "main.h": [10.0] * 4 + [20.0] * 3}[name]  # (the called Klartext lifts Z)
    rapid = {"main.mpf": {0}, "main.h": {0, 4}}[name]  # (`L Z+20 FMAX` in the called Klartext)
    calls = ["STRAIGHT_TRAVERSE" if n in rapid else "STRAIGHT_FEED" for n in range(len(expected))]
    assert lines == [f"{c}({x:.4f}, {y:.4f}, {h:.4f}, 0.0000, 0.0000, 0.0000)"
                     for c, (x, y, _, _), h in zip(calls, expected, z)]  # fmt: skip


def _compensate_cli(capsys, program: Path, folder: Path | None, *extra: str) -> tuple[int, str, str]:
    argv = ["compensate", "--machine", MACHINE, *extra, str(program)]
    status = main(argv + (["--subroutine-path", str(folder)] if folder else []))
    out, err = capsys.readouterr()
    return status, out, err


@pytest.mark.parametrize(
    "name, main_text, files, call, after",
    [
        ("main.mpf", SINUMERIK_MAIN, SINUMERIK_FILES, "N30 L0100 P2", "N40 G1 X50 Y50"),
        ("main.h", HEIDENHAIN_MAIN, HEIDENHAIN_FILES, "CALL PGM TNC:\\parts\\SUB1.H", "L X+Q2 Y+50 R0 F100"),
    ],
    ids=["sinumerik", "heidenhain"],
)
def test_compensate_goes_on_after_the_call(tmp_path, capsys, name, main_text, files, call, after):
    """End to end (the verifier reads the input again, with the called files): the call line is
    written as it is, the moves after it are compensated; without the folder they pass through."""
    program = tmp_path / name
    program.write_text(main_text)
    folder = _folder(tmp_path, files)
    status, out, err = _compensate_cli(capsys, program, folder)
    assert status == 0, err
    assert call in out and after not in out  # the call as written, the next move rewritten
    assert "outside the motion interpreter's scope" not in err
    assert "warning: loop or subroutine" in err  # the called moves, left as programmed
    for called, text in files.items():  # the called files are read, not written
        assert (folder / called).read_text() == text
    status, out, err = _compensate_cli(capsys, program, None)
    assert status == 0 and after in out and "its file not found" in err


@pytest.mark.parametrize(
    "name, main_text, message, after",
    [
        ("main.mpf", SINUMERIK_MAIN, "main.mpf:3:5: {} the subprogram call L0100 (its file not found: "
         "none of L0100.SPF, _N_L0100_SPF, _N_L0100_SPF.SPF, L0100.MPF", "N40 G1 X50 Y50\n"),
        ("main.h", HEIDENHAIN_MAIN, "main.h:5:3: {} CALL PGM TNC:\\parts\\SUB1.H (its file not found: "
         "none of SUB1.H in ", "L X+Q2 Y+50 R0 F100\n"),
    ],
    ids=["sinumerik", "heidenhain"],
)  # fmt: skip
def test_a_missing_file_warns_naming_it_and_the_folders_or_is_refused_strictly(
    tmp_path, capsys, name, main_text, message, after
):
    program = tmp_path / name
    program.write_text(main_text)
    empty = _folder(tmp_path, {})
    status, out, err = _compensate_cli(capsys, program, empty)
    assert status == 0 and message.format("warning:") in err and str(empty) in err, err
    assert after in out  # the rest as it was
    status, out, err = _compensate_cli(capsys, program, empty, "--strict")
    assert (
        status != 0 and out == "" and message.format("").replace("  ", " ") in err.replace("error: ", "")
    ), err


def test_sinumerik_file_names_ignore_case_and_accept_the_control_s_own(tmp_path):
    folder = _folder(tmp_path, {"l7.spf": "G1 X7 F100\nM17\n", "_N_PART2_MPF": "G1 Y3 F100\nRET\n"})
    events, warned = _events(sinumerik, "sinumerik", "G0 X0 Y0\nL7\n_N_PART2_MPF\nG1 X1\nM30\n", folder)
    assert warned == "" and _path(events) == [
        (0, 0, 1, False),
        (7, 0, 2, True),
        (7, 3, 3, True),
        (1, 3, 4, False),
    ]


def test_sinumerik_subprogram_variables_are_its_own_r_parameters_the_channel_s(tmp_path):
    """A DEF in the subprogram is its local: the caller's variable of that name is untouched."""
    folder = _folder(tmp_path, {"SETR.SPF": "DEF REAL A=2\nR5=A*10\nM17\n"})
    text = "DEF REAL A=1\nG0 X0\nSETR\nG1 X=A+R5 F100\nM30\n"
    events, warned = _events(sinumerik, "sinumerik", text, folder)
    assert warned == "" and _path(events)[-1] == (21.0, 0.0, 4, False)


@pytest.mark.parametrize(
    "files, call, reason",
    [
        (
            {"DEEP.SPF": "G91 G1 X1 F100\nDEEP\nM17\n"},
            "DEEP",
            "nests deeper than the control's 16 program levels",
        ),
    ],
)
def test_sinumerik_a_subprogram_that_calls_itself_for_ever_is_refused(tmp_path, files, call, reason):
    with pytest.raises(NcppError) as err:
        _events(sinumerik, "sinumerik", f"G0 X0\n{call}\nM30\n", _folder(tmp_path, files))
    assert reason in str(err.value) and "DEEP.SPF:2:1" in str(err.value)


@pytest.mark.parametrize(
    "files, call, where, reason",
    [
        ({"END.SPF": "G1 X1 F100\nM30\n"}, "END", "END.SPF:2:1", "M30 in a subprogram"),
        ({"NORET.SPF": "G1 X1 F100\n"}, "NORET", "NORET.SPF:1:",
         "the subprogram NORET ends without M17 or RET"),
        ({"SAVED.SPF": "PROC SAVED SAVE\nG1 X1 F100\nM17\n"}, "SAVED", "main:2:1",
         "the subprogram SAVED with PROC ... SAVE"),
        ({"REF.SPF": "PROC REF(VAR REAL A)\nM17\n"}, "REF(5)", "main:2:1",
         "parameter VAR REAL A given a value"),
        ({"TWO.SPF": "PROC TWO(REAL A)\nG1 X=A F100\nM17\n"}, "TWO(1) P2", "main:2:1",
         "with parameters and P"),
        ({"ALONE.SPF": "G1 X1 F100\nM17\n"}, "G1 Y2 L100", "main:2:1", "the subprogram call L100 with more"),
    ],
    ids=["m30", "no return", "save", "a value by reference", "parameters and runs", "not alone"],
)  # fmt: skip
def test_sinumerik_calls_ncpp_does_not_follow_end_interpretation(tmp_path, files, call, where, reason):
    folder = _folder(tmp_path, {**files, "L100.SPF": "M17\n"})
    events, warned = _events(sinumerik, "sinumerik", f"G0 X0 Y0\n{call}\nG1 X5 Y5 F100\nM30\n", folder)
    assert f"{where}" in warned and reason in warned, warned
    assert (5.0, 5.0, 3, False) not in _path(events)  # the rest passes through


@pytest.mark.parametrize(
    "files, call, reason",
    [
        ({"self.h": "0 BEGIN PGM SELF MM\n1 CALL PGM SELF\n2 END PGM SELF MM\n"}, "CALL PGM SELF",
         "a program that calls itself"),
        ({"end.h": "0 BEGIN PGM END MM\n1 L X+1 R0 F100 M30\n2 END PGM END MM\n"}, "CALL PGM END",
         "M30 in a program CALL PGM runs"),
        ({"iso.i": "%ISO G71\n"}, "CALL PGM ISO.I", "a program that is not Klartext"),
    ],
    ids=["itself", "m30", "iso"],
)  # fmt: skip
def test_klartext_calls_ncpp_does_not_follow_end_interpretation(tmp_path, files, call, reason):
    text = f"0 BEGIN PGM M MM\n1 L X+0 Y+0 R0 FMAX\n2 {call}\n3 L X+5 Y+5 R0 F100\n4 END PGM M MM\n"
    events, warned = _events(heidenhain, "heidenhain", text, _folder(tmp_path, files))
    assert reason in warned, warned
    assert (5.0, 5.0, 4, False) not in _path(events) and len(_path(events)) == 1


def test_klartext_called_program_in_inch_keeps_the_caller_s_millimetres(tmp_path):
    files = {"inch.h": "0 BEGIN PGM INCH INCH\n1 L X+1 R0 F10\n2 END PGM INCH INCH\n"}
    text = "0 BEGIN PGM M MM\n1 L X+0 Y+0 R0 FMAX\n2 CALL PGM INCH\n3 L IX+1 R0 F100\n4 END PGM M MM\n"
    events, warned = _events(heidenhain, "heidenhain", text, _folder(tmp_path, files))
    moves = [e for e in events if type(e) is Line]
    assert warned == "" and [round(m.end[0], 6) for m in moves] == [0.0, 1.0, 26.4]  # 25.4 mm, then 1 mm more
    assert [m.context.inch for m in moves] == [False, True, False]


def test_sinumerik_indirect_call_by_a_string_or_a_string_variable(tmp_path):
    """`CALL "NAME"` and `CALL variable` (Job Planning manual, "Indirect program call"); the parser
    refused `CALL "NAME"` as a syntax error."""
    folder = _folder(tmp_path, {"PART2.SPF": "G1 X7 F100\nM17\n", "L0100.SPF": "G1 Y3 F100\nM17\n"})
    text = 'DEF STRING[20] P="l0100"\nG0 X0 Y0\nCALL "/_N_WKS_DIR/PART2"\nCALL P\nG1 X1\nM30\n'
    events, warned = _events(sinumerik, "sinumerik", text, folder)
    assert warned == ""
    assert _path(events) == [(0, 0, 2, False), (7, 0, 3, True), (7, 3, 4, True), (1, 3, 5, False)]


@pytest.mark.parametrize(
    "call",
    ['EXTCALL("/_N_WKS_DIR/_N_SHAFT_WPD/part2.spf")', 'EXTCALL "PART2"', 'extcall ("LOCAL_DRIVE:PART2_SPF")',
     'EXTCALL("\\\\server\\cam\\PART2.SPF")'],
)  # fmt: skip
def test_sinumerik_external_call_runs_the_named_program(tmp_path, call):
    """`EXTCALL("<path/><program name>")` (Function Manual Basic Functions K1, "Program control":
    a path, a drive's short name, the type after `_` or `.`) runs the program from the subroutine
    path, as an indirect CALL; the parser refused `EXTCALL "NAME"`, and the call ended interpretation."""
    folder = _folder(tmp_path, {"PART2.SPF": "G1 X7 F100\nRET\n"})
    events, warned = _events(sinumerik, "sinumerik", f"G0 X0 Y0\n{call}\nG1 Y1\nM30\n", folder)
    assert warned == ""
    assert _path(events) == [(0, 0, 1, False), (7, 0, 2, True), (7, 1, 3, False)]


def test_sinumerik_subprogram_file_as_the_control_writes_it_out(tmp_path):
    """Its name and path lines above the PROC (as a control writes a subprogram out)."""
    sub = "%_N_HOLE_SPF\n;$PATH=/_N_SPF_DIR\nPROC HOLE(REAL X0) SBLOF\nG1 X=X0 F100\nM17\n"
    events, warned = _events(
        sinumerik, "sinumerik", "G0 X0\nHOLE(4)\nM30\n", _folder(tmp_path, {"HOLE.SPF": sub})
    )
    assert warned == "" and _path(events) == [(0, 0, 1, False), (4, 0, 2, True)]


PLAN = CORPUS / "heidenhain" / "jstjst_Heidenhain-Cycles"


@pytest.mark.skipif(not (PLAN / "Plan.h").is_file(), reason="no corpus")
def test_the_corpus_face_milling_cycle_runs_where_its_example_calls_it(tmp_path, capsys):
    """Plan-Beispiel.h calls Plan.h (a face-milling spiral: labels, FN 9-12 jumps, RND, CT) by
    `CALL PGM TNC:\\Plan.h`.  Plan.h reads Q108, the tool radius the control sets at TOOL CALL from
    its tool table (TNC 640 Klartext manual, "Preassigned Q parameters"), which ncpp does not read:
    as given, interpretation stops in Plan.h at its first use, the warning at the calling line;
    with Q108 set in the caller (5 mm, a stand-in for the table), the whole cycle runs."""
    main_text = (PLAN / "Plan-Beispiel.h").read_text()
    program = tmp_path / "Plan-Beispiel.h"
    program.write_text(main_text)
    status, lines, err = _motion_cli(capsys, program, PLAN)
    assert (
        status == 0 and "Plan-Beispiel.h:23:1: warning: the parameter Q108" in err and "Plan.h:41:4)" in err
    )
    assert len(lines) == 1  # the move before the call

    program.write_text(main_text.replace("R0 FMAX M3\n", "R0 FMAX M3\n4 Q108 = 5\n"))
    events, warned = _events(heidenhain, "heidenhain", program.read_text(), PLAN)
    moves = [e for e in events if type(e) is Line or type(e) is Arc]
    called = [m for m in moves if m.block.line == 24]
    assert "Q108" not in warned and len(called) == len(moves) - 2 and all(m.fixed == FLOW for m in called)
    # From its Q parameters: start X = Q1800 - Q108 - Q1832 = -210; Y = Q1803 - (Q1962 - Q108) - Q108 -
    # Q1832 with the side step Q1962 = (200 + 2 * 0.05 * 5) / INT(200.5 / (2 * 0.7 * 5) + 0.999) = 200.5 / 29
    y = 100 - 200.5 / 29 - 5
    assert [tuple(round(v, 6) for v in m.end) for m in called[:3]] == [
        (-210.0, round(y, 6), 50.0),
        (-210.0, round(y, 6), 50.0),  # to the second safety height Q1804 + Q1831, where it stands
        (-210.0, round(y, 6), -1.0),  # the first of three infeeds of 1 mm (Q1805 = -3, Q1810 = 1)
    ]
    assert {m.end[2] for m in called if not (type(m) is Line and m.rapid)} == {-1.0, -2.0, -3.0}
    assert called[-1].end[2] == 5.0 and called[-1].rapid  # out to the safety height Q1804 + Q1830
    assert moves[-1].end == (0.0, 200.0, 300.0) and not moves[-1].fixed  # the caller's, compensated


@pytest.mark.parametrize(
    "interpret, dialect, text, files",
    [
        (sinumerik, "sinumerik", "G0 X0\nOUTER P40\nM30\n",  # (P9999 P9999: refused as a counted loop at once)
         {"OUTER.SPF": "INNER P40\nM17\n", "INNER.SPF": "G91 G1 X1 F100\nM17\n"}),
        (heidenhain, "heidenhain", "0 BEGIN PGM M MM\n1 CALL PGM OUTER\n2 END PGM M MM\n",
         {"OUTER.H": "0 BEGIN PGM OUTER MM\n1 LBL 1\n2 CALL PGM INNER\n3 CALL LBL 1 REP 9999\n"
          "4 END PGM OUTER MM\n", "INNER.H": "0 BEGIN PGM INNER MM\n1 L IX+1 R0 F100\n2 END PGM INNER MM\n"}),
    ],
    ids=["sinumerik", "heidenhain"],
)  # fmt: skip
def test_calls_repeated_past_the_rerun_limit_are_refused_as_never_ending(
    tmp_path, monkeypatch, interpret, dialect, text, files
):
    import ncpp.motion.called as called

    monkeypatch.setattr(called, "MAX_RERUN", 1000)  # (the real limit, 5,000,000 blocks, takes a minute)
    with pytest.raises(NcppError) as err:
        _events(interpret, dialect, text, _folder(tmp_path, files))
    assert "more than 1,000 blocks run in called files" in str(err.value) and "main:2:" in str(err.value)


@pytest.mark.parametrize("passes, refused", [(3500, False), (6000, True)])
def test_a_for_around_calls_is_bound_by_its_blocks_and_the_called_blocks_apart(
    tmp_path, monkeypatch, passes, refused
):
    """A FOR whose passes run 2 blocks of the program and 4 of a subprogram's file: the blocks run
    again in the program and those run in called files have a bound each (20,000 here), so 3,500
    passes (7,000 and 14,000 blocks, 21,000 together) run to the end and 6,000 passes are refused
    when the called blocks pass theirs."""
    import ncpp.motion.called as called
    import ncpp.motion.flow as flow
    import ncpp.motion.sinumerik_flow as sinumerik_flow

    for module in (called, flow, sinumerik_flow):
        monkeypatch.setattr(module, "MAX_RERUN", 20_000)
    text = f"G0 X0\nFOR R1=1 TO {passes}\nL123\nENDFOR\nM30\n"
    folder = _folder(tmp_path, {"L123.SPF": "G91 G1 X1 F100\nX-1\nG90\nM17\n"})
    if refused:
        with pytest.raises(NcppError, match="main:4:1: more than 20,000 blocks run in called files"):
            _events(sinumerik, "sinumerik", text, folder)
    else:
        events, _ = _events(sinumerik, "sinumerik", text, folder)
        assert len([e for e in events if type(e) is Line]) == 1 + 2 * passes


def test_sinumerik_ret_in_the_main_program_is_no_subprogram_call(tmp_path):
    _, warned = _events(sinumerik, "sinumerik", "G0 X0\nRET\nM30\n", _folder(tmp_path, {"RET.SPF": "M17\n"}))
    assert "main:2:1: warning: call RET is outside" in warned


def _long_zigzag(runs: int) -> str:
    return "".join(f"G1 X{(n % 50) * 0.1:.1f} Y{n * 0.01:.2f}\n" for n in range(runs))


@pytest.mark.parametrize(
    "main_text, files",
    [
        ("G0 X0 Y0 Z5\nG1 Z0 F100\nLONG\nG1 X50 Y50\nM30\n", {"LONG.SPF": "G1 F100\n" + _long_zigzag(6000) + "M17\n"}),
        ("G0 X0 Y0 Z5\nG1 Z0 F100\nZIG P3000\nG1 X50 Y50\nM30\n",
         {"ZIG.SPF": "G91 G1 X0.01 Y0.01 F100\nG1 X-0.01\nG90\nM17\n"}),
        ("DEF INT I\nG0 X0 Y0 Z5\nG1 Z0 F100\nFOR I=1 TO 3000\nG91 G1 X0.01 Y0.01\nG1 X-0.01\nG90\nENDFOR\n"
         "G1 X50 Y50\nM30\n", {}),
    ],
    ids=["a long subprogram", "a subprogram run 3000 times", "a loop run 3000 times"],
)  # fmt: skip
def test_sinumerik_long_runs_are_written_and_verified_a_chunk_at_a_time(tmp_path, capsys, main_text, files):
    """Over 4096 moves owned by one line (the call, the loop's end): the verifier compared them as one
    piece and refused the program ("the written path leaves the original's")."""
    _long_runs_compensate(tmp_path, capsys, "long.mpf", main_text, files, "\nG1 X50 Y50\n")


def _long_runs_compensate(tmp_path, capsys, name: str, main_text: str, files: dict, after: str) -> None:
    program = tmp_path / name
    program.write_text(main_text)
    status, out, err = _compensate_cli(capsys, program, _folder(tmp_path, files))
    assert status == 0 and "verification" not in err, err
    assert after not in out and ("X50.0" in out or "X+50.0" in out)  # the move after the runs, compensated


@pytest.mark.parametrize(
    "main_text, files",
    [
        ("0 BEGIN PGM M MM\n1 L X+0 Y+0 Z+5 R0 FMAX\n2 L Z+0 R0 F100\n3 CALL PGM LONG\n4 L X+50 Y+50 R0 F100\n"
         "5 END PGM M MM\n", {"LONG.H": "0 BEGIN PGM LONG MM\n" + "".join(
             f"{n + 1} L X+{(n % 50) * 0.1:.1f} Y+{n * 0.01:.2f} R0 F100\n" for n in range(6000))
             + "6001 END PGM LONG MM\n"}),
        ("0 BEGIN PGM M MM\n1 L X+0 Y+0 Z+5 R0 FMAX\n2 L Z+0 R0 F100\n3 LBL 1\n4 L IX+0.01 IY+0.01 R0 F100\n"
         "5 L IX-0.01\n6 CALL LBL 1 REP 3000\n7 L X+50 Y+50 R0 F100\n8 END PGM M MM\n", {}),
    ],
    ids=["a long called program", "a section repeated 3000 times"],
)  # fmt: skip
def test_klartext_long_runs_are_written_and_verified_a_chunk_at_a_time(tmp_path, capsys, main_text, files):
    """As for Sinumerik: a call or repeat line owning over 4096 moves was refused by the verifier."""
    _long_runs_compensate(tmp_path, capsys, "long.h", main_text, files, " L X+50 Y+50 R0 F100\n")


def test_sinumerik_a_subprogram_by_number_takes_parameters(tmp_path):
    """`L140(2)` calls the subprogram L140 with a PROC parameter (PDubovikov/SinumerikLanguage,
    `SinumerikLanguage/test/123.mpf`: `N12 L140(2)`, `N15 L143(90)`; 840D sl Programming Manual,
    Fundamentals, "Program names": a subprogram may be named L and 1-7 digits).  It was left out of
    scope as an unknown call, even with its file at hand, and without saying the file was missing."""
    folder = _folder(tmp_path, {"L140.SPF": "PROC L140(REAL A)\nG1 X=A*10 F100\nM17\n"})
    events, warned = _events(sinumerik, "sinumerik", "G0 X0 Y0 Z10\nL140(2)\nG1 Y5\nM30\n", folder)
    assert warned == "" and _path(events) == [
        (0.0, 0.0, 1, False),
        (20.0, 0.0, 2, True),
        (20.0, 5.0, 3, False),
    ]
    _, warned = _events(sinumerik, "sinumerik", "G0 X0 Y0 Z10\nL143(90)\nM30\n", folder)
    assert "main:2:1: warning: call L143 (its file not found: none of L143.SPF" in warned


def test_sinumerik_a_program_of_the_user_s_under_a_cycle_prefix_runs_when_its_file_is_there(tmp_path):
    """A user's subprogram named like a Siemens cycle (nie11kun/TP_Worm, `NC code/MAIN.MPF`:
    `F_TP_GRINDING_PARAMETERS(pRad-(cyT*fR-cyR*fR), alpha, ...)`, its file beside the main program):
    E_ and F_ are the prefixes Siemens reserves for its cycles (Programming Manual Fundamentals
    12/2019, "Naming rules"), but the control runs the program of the called name, which is the
    user's where its file is on the subroutine path.  One not there stays a cycle ncpp does not follow."""
    folder = _folder(
        tmp_path, {"F_TP_STEP.SPF": "PROC F_TP_STEP(REAL A, REAL B) DISPLOF\nG1 X=A Y=B F500\nRET\n"}
    )
    events, warned = _events(
        sinumerik, "sinumerik", "G0 X0 Y0 Z5\nF_TP_STEP(10, 2*10)\nG1 X30\nM30\n", folder
    )
    assert warned == "" and _path(events) == [
        (0.0, 0.0, 1, False),
        (10.0, 20.0, 2, True),
        (30.0, 20.0, 3, False),
    ]
    _, warned = _events(sinumerik, "sinumerik", "G0 X0 Y0 Z5\nF_DRILL(1, 2)\nG1 X30\nM30\n", folder)
    assert (
        "main:2:1: warning: call F_DRILL (a Siemens cycle's name; as a program of the user's, its file not found: none of F_DRILL.SPF"
        in warned
    )
