"""Without --expand, a Klartext subprogram that runs once -- `CALL LBL n` once, from the main
program's straight code, its text (`LBL n` ... `LBL 0`) after M30 as the TNC 640 Klartext manual
places subprograms ("Subprograms and program section repeats") -- is compensated where its text
stands: that text runs once, so it can carry the run's corrections.  One whose text runs again
(called twice, the call in a repeated section or in another subprogram, the program running into
its text) stays as programmed, with the warning; one never called is written as it stands.

There is no oracle that runs Klartext: the judge is closed form.  The test reads the written
program in the order the control runs it (`run_order`: each call followed by its subprogram's
lines) with a reader of its own (`points`), maps the numbers through the formula of a machine
whose errors are linear in position (`machine`), and every programmed point must be reached
within 0.5 µm, where the program as written misses them by more than 5 µm.  A loop of FN 9-12 jumps
back whose first pass does not go back is compensated in its place too."""

from __future__ import annotations

import re

import pytest

import ncpp.motion.once as once_module
from ncpp.cli import main
from ncpp.program.dialects.heidenhain import HeidenhainWriter
from tests.compensation.test_dialect_cutter_comp import compensated
from tests.writeback.closed_form import landed
from tests.writeback.test_klartext_expand import _wide, points

HEAD = """BEGIN PGM CONTOUR MM
BLK FORM 0.1 Z X+0 Y+0 Z-20
BLK FORM 0.2 X+200 Y+150 Z+0
TOOL CALL 1 Z S3000
L X-10 Y-10 Z+5 R0 FMAX
L Z-2 F300
"""
# the contour of LBL 1: lines and an arc about its pole
BODY = """L X+160 Y+20 F500
L X+180 Y+120
CC X+130 Y+120
C X+80 Y+120 DR+
L X+40 Y+60
"""
SLOT = 'LBL "SLOT"\nL X+100 Y+140 F400\nL X+100 Y+100\nLBL 0\n'


def numbered(text: str) -> str:
    """`text`'s lines numbered one after another from 0 (`~` continuation lines aside)."""
    lines, n = [], 0
    for line in text.splitlines():
        if line.startswith(" "):
            lines.append(line)
            continue
        lines.append(f"{n} {line}")
        n += 1
    return "\n".join(lines) + "\n"


def program(main_part: str, after: str = "LBL 1\n" + BODY + "LBL 0\n") -> str:
    """HEAD, `main_part`, `L Z+50 FMAX M30`, the subprograms `after` and END PGM, numbered."""
    return numbered(f"{HEAD}{main_part}L Z+50 FMAX M30\n{after}END PGM CONTOUR MM\n")


ONCE = {
    "a contour": program("CALL LBL 1\nL X+10 Y+140 F300\n"),
    "two subprograms, one named": program(
        'CALL LBL 1\nL X+10 Y+140 F300\nCALL LBL "SLOT"\n', "LBL 1\n" + BODY + "LBL 0\n" + SLOT
    ),
    "hole positions": numbered(
        """BEGIN PGM HOLES MM
TOOL CALL 1 Z S3000
CYCL DEF 200 DRILLING ~
  Q200=+2 ;SAFETY CLEARANCE ~
  Q201=-10 ;DEPTH ~
  Q206=+150 ;FEED RATE FOR PLNGNG ~
  Q202=+5 ;PLUNGING DEPTH ~
  Q210=+0 ;DWELL TIME AT TOP ~
  Q203=+0 ;SURFACE COORDINATE ~
  Q204=+50 ;2ND SET-UP CLEARANCE ~
  Q211=+0 ;DWELL TIME AT DEPTH
L X-10 Y-10 Z+50 R0 FMAX
CALL LBL 1
L Z+100 FMAX M30
LBL 1
L X+20 Y+30 FMAX M99
L X+150 Y+30 FMAX M99
L X+150 Y+120 FMAX M99
L X+20 Y+120 FMAX M99
LBL 0
END PGM HOLES MM
"""
    ),
}
CONTOUR = [(160, 20, -2), (180, 120, -2), (80, 120, -2), (40, 60, -2)]
MAIN = [(-10, -10, 5), (-10, -10, -2), (10, 140, -2), (10, 140, 50)]
WANTED = {
    "a contour": MAIN + CONTOUR,
    "two subprograms, one named": MAIN[:3] + CONTOUR + [(100, 140, -2), (100, 100, -2), (100, 100, 50)],
    "hole positions": [(-10, -10, 50), (20, 30, 50), (150, 30, 50), (150, 120, 50), (20, 120, 50)],
}
# the subprogram's text runs more than once, or is never called
AGAIN = {
    "called twice": program("CALL LBL 1\nL X+10 Y+140 F300\nCALL LBL 1\nL X+10 Y+140\n"),
    "called in a repeated section": program("LBL 2\nCALL LBL 1\nL X+10 Y+140 F300\nCALL LBL 2 REP 1\n"),
    "called from another subprogram": program(
        "CALL LBL 2\nL X+10 Y+140 F300\n", "LBL 2\nCALL LBL 1\nLBL 0\nLBL 1\n" + BODY + "LBL 0\n"
    ),
    "run into after its call": numbered(
        f"{HEAD}CALL LBL 1\nL X+10 Y+140 F300\nLBL 1\n{BODY}LBL 0\nL Z+50 FMAX M30\nEND PGM CONTOUR MM\n"
    ),
}
NEVER = program("L X+10 Y+140 F300\n")


def run_order(text: str) -> str:
    """The written program's lines in the order the control runs them, for this test's programs:
    the main part up to M30, each `CALL LBL n` followed by the lines after `LBL n` up to `LBL 0`
    (TNC 640 Klartext manual, "Subprograms"), calls in them followed so too; the main part runs
    through a `LBL 0` of its own, and `FN 9: IF +0 EQU +0 GOTO LBL n` goes on at `LBL n`."""
    lines = text.splitlines()
    heads = [line.split(";")[0].split(None, 1)[-1].strip() for line in lines]

    def run(start: int, subprogram: bool) -> list[str]:
        out, index = [], start
        while index < len(lines):
            line, head = lines[index], heads[index]
            out.append(line)
            if (head == "LBL 0" and subprogram) or re.search(r"\bM30\b|END PGM", head):
                return out
            called = re.fullmatch(r"CALL LBL (\S+)", head)
            if called:
                out += run(heads.index(f"LBL {called.group(1)}") + 1, True)
            jump = re.fullmatch(r"FN 9: IF \+0 EQU \+0 GOTO LBL (\S+)", head)
            index = heads.index(f"LBL {jump.group(1)}") if jump else index + 1
        return out

    return "\n".join(run(0, False))


def _code(text: str) -> str:
    """The lines without their block numbers."""
    return "\n".join(line.split(" ", 1)[1] if " " in line else line for line in text.splitlines())


@pytest.mark.parametrize("name", ONCE)
def test_a_subprogram_that_runs_once_is_compensated_where_its_text_stands(tmp_path, name):
    """Every programmed point, the written numbers read in the order they run, within 0.5 µm;
    the program as written misses them by more than 5 µm.  The subprograms stay after M30, and
    the blocks are numbered one after another."""
    written, messages = compensated(tmp_path, "once.h", ONCE[name])
    wanted = WANTED[name]
    assert landed(points(run_order(written)), wanted).max() < 0.5e-3
    assert landed(points(run_order(ONCE[name])), wanted).max() > 5e-3  # (the measure can fail)
    assert "loop or subroutine" not in messages
    main_part, _, after = written.partition("M30")
    label = re.compile(r"^\d+ LBL 1$", re.M)
    assert label.search(after) and not label.search(main_part)
    assert after.count("LBL 0") == main_part.count("CALL LBL")
    numbers = [int(line.split()[0]) for line in written.splitlines() if not line.startswith(" ")]
    assert numbers == list(range(len(numbers)))


@pytest.mark.parametrize("name", AGAIN)
def test_a_subprogram_whose_text_runs_again_stays_as_programmed(tmp_path, name):
    """Its text is written as it stands, with the warning; the main program's moves are compensated."""
    written, messages = compensated(tmp_path, "again.h", AGAIN[name])
    assert BODY.strip() in _code(written)
    assert "warning: loop or subroutine" in messages
    ends = points(written)
    if name != "called in a repeated section":  # (its main moves run twice too)
        assert landed(ends, MAIN[1:3]).max() < 0.5e-3
    assert landed(ends, CONTOUR).min() > 2e-3  # (as programmed: the machine's error stays)


def test_a_subprogram_never_called_is_written_as_it_stands(tmp_path):
    written, messages = compensated(tmp_path, "never.h", NEVER)
    assert BODY.strip() in _code(written)
    assert "loop or subroutine" not in messages
    assert landed(points(written), MAIN).max() < 0.5e-3


def test_the_events_held_past_the_bound_leave_the_run_as_programmed(tmp_path, monkeypatch):
    """The run and the program after it are held to the program's end, at most MAX_ONCE events."""
    monkeypatch.setattr(once_module, "MAX_ONCE", 3)
    written, messages = compensated(tmp_path, "once.h", ONCE["a contour"])
    assert BODY.strip() in _code(written)
    assert "warning: loop or subroutine" in messages


def test_a_run_written_where_it_runs_and_at_its_text_is_refused_by_the_verifier(
    tmp_path, monkeypatch, capsys
):
    """A writer that does not place the run (its lines after the call, the text after M30 as well:
    the control would run the contour twice) is refused: the verifier reads the written program
    as the control runs it, not as the writer meant it."""
    write = HeidenhainWriter.write

    def unplaced(self, events, after=None, before=None):
        self.once_runs = None
        return write(self, events, after, before)

    monkeypatch.setattr(HeidenhainWriter, "write", unplaced)
    program = tmp_path / "once.h"
    program.write_text(ONCE["a contour"])
    code = main(
        ["compensate", "--machine", str(_wide(tmp_path)), str(program), "-o", str(tmp_path / "out.h")]
    )
    assert code != 0 and "verification" in capsys.readouterr().err


@pytest.mark.parametrize("name", ONCE)
def test_the_command_line_compensates_and_verifies_on_the_wide_machine(tmp_path, name):
    program, out = tmp_path / "once.h", tmp_path / "out.h"
    program.write_text(ONCE[name])
    assert main(["compensate", "--machine", str(_wide(tmp_path)), str(program), "-o", str(out)]) == 0
    assert "CALL LBL 1" in out.read_text().partition("M30")[0]


def test_a_repeat_of_zero_more_runs_is_not_guessed_at(tmp_path):
    """`CALL LBL n REP k` runs the section k more times (TNC 640 Klartext manual, "Program section
    repeats"); the parser reads `REP 0` as a call with no REP, which the control may not: it leaves
    the interpreter's scope at its word.  A label whose name holds REP is no repeat."""
    repeated = program("LBL 2\nL X+10 Y+140 F300\nCALL LBL 2 REP 0\n")
    _, messages = compensated(tmp_path, "rep0.h", repeated)
    assert re.search(
        r"rep0\.h:\d+:3: warning: CALL LBL \.\.\. REP 0 .* outside the motion interpreter's scope", messages
    )
    named = ONCE["a contour"].replace("LBL 1", 'LBL "REPAIR"')
    written, messages = compensated(tmp_path, "repair.h", named)
    assert "scope" not in messages and "loop or subroutine" not in messages
    assert landed(points(run_order(written)), WANTED["a contour"]).max() < 0.5e-3


# a jump back (TNC 640 Klartext manual, "If-then decisions with Q parameters") whose loop runs once:
# Q1 is 10 after the first pass, and FN 12 goes back while it is below `{end}`
JUMP_BACK = "FN 0: Q1 = +0\nLBL 2\nFN 1: Q1 = +Q1 + +10\n{body}FN 12: IF +Q1 LT +{end} GOTO LBL 2\nL X+10 Y+140 F300\n"


def test_a_jumps_loop_that_runs_once_is_compensated_in_its_place(tmp_path):
    """Its first pass is held until the flow goes on past the jump: the loop did not go back, so
    its text ran once and is compensated, the FN lines as they are."""
    text = program(JUMP_BACK.format(body=BODY, end=10), "")
    written, messages = compensated(tmp_path, "jump.h", text)
    assert landed(points(written), MAIN + CONTOUR).max() < 0.5e-3
    assert landed(points(text), MAIN + CONTOUR).max() > 5e-3
    assert "loop or subroutine" not in messages
    assert "FN 12: IF +Q1 LT +10 GOTO LBL 2" in written and "FN 1: Q1 = +Q1 + +10" in written


def test_a_jumps_loop_that_goes_back_stays_as_programmed(tmp_path):
    written, messages = compensated(tmp_path, "jump.h", program(JUMP_BACK.format(body=BODY, end=20), ""))
    assert BODY.strip() in _code(written)
    assert "warning: loop or subroutine" in messages
    ends = points(written)
    assert landed(ends, MAIN[1:3]).max() < 0.5e-3 and landed(ends, CONTOUR).min() > 2e-3


def test_a_loops_first_pass_held_past_the_bound_stays_as_programmed(tmp_path, monkeypatch):
    """What a first pass holds past MAX_ONCE events stays as programmed (the held events go)."""
    monkeypatch.setattr(once_module, "MAX_ONCE", 3)
    written, messages = compensated(tmp_path, "jump.h", program(JUMP_BACK.format(body=BODY, end=10), ""))
    assert "L X+160 Y+20 F500\nL X+180 Y+120" in _code(written)
    assert "warning: loop or subroutine" in messages


# a subprogram's text before its call, behind a jump the program takes over it: the control runs a
# text where it stands unless it stands after M2/M30 or a jump goes over it (TNC 640 Klartext
# manual, "Subprograms and program section repeats"), so the call is its only run
BEHIND_A_JUMP = numbered(
    f"{HEAD}FN 9: IF +0 EQU +0 GOTO LBL 99\nLBL 1\n{BODY}LBL 0\nLBL 99\nL X+10 Y+140 F300\n"
    "CALL LBL 1\nL X+10 Y+140\nL Z+50 FMAX M30\nEND PGM CONTOUR MM\n"
)
# the program runs into the text before it calls it: the text runs twice
RUN_INTO_BEFORE = BEHIND_A_JUMP.replace("FN 9: IF +0 EQU +0 GOTO LBL 99", "L X+10 Y+140 F300")


def test_a_subprogram_behind_a_jump_before_its_only_call_is_compensated_where_it_stands(tmp_path):
    """Every programmed point, read in the order the control runs the written program, within
    0.5 µm (as written, more than 5 µm off); the text stays before the call, between its jump and
    the jump's label, and the blocks are numbered one after another."""
    written, messages = compensated(tmp_path, "before.h", BEHIND_A_JUMP)
    wanted = MAIN + CONTOUR
    assert landed(points(run_order(written)), wanted).max() < 0.5e-3
    assert landed(points(run_order(BEHIND_A_JUMP)), wanted).max() > 5e-3
    assert "loop or subroutine" not in messages
    code = _code(written)
    assert (
        code.index("GOTO LBL 99")
        < code.index("LBL 1\n")
        < code.index("LBL 0\nLBL 99")
        < code.index("CALL LBL 1")
    )
    numbers = [int(line.split()[0]) for line in written.splitlines() if not line.startswith(" ")]
    assert numbers == list(range(len(numbers)))


def test_a_subprogram_behind_a_jump_called_twice_stays_as_programmed(tmp_path):
    text = BEHIND_A_JUMP.replace("L X+10 Y+140\n", "CALL LBL 1\nL X+10 Y+140\n", 1)
    assert text.count("CALL LBL 1") == 2
    written, messages = compensated(tmp_path, "twice.h", text)
    assert BODY.strip() in _code(written)
    assert "warning: loop or subroutine" in messages
    ends = points(written)
    assert landed(ends, MAIN[:3]).max() < 0.5e-3 and landed(ends, CONTOUR).min() > 2e-3


def test_a_text_run_into_before_its_call_stays_as_programmed_and_the_blocks_after_it_are_compensated(
    tmp_path,
):
    """The control runs the text where it stands and again at the call: both runs as programmed,
    with the warning.  A call without REP runs the text from its label to LBL 0 alone, so the main
    program's moves between that LBL 0 and the call, which run once, are compensated."""
    written, messages = compensated(tmp_path, "into.h", RUN_INTO_BEFORE)
    assert BODY.strip() in _code(written)
    assert "warning: loop or subroutine" in messages
    ends = points(written)
    assert landed(ends, MAIN[:3]).max() < 0.5e-3 and landed(ends, CONTOUR).min() > 2e-3
    before = _code(written.partition("LBL 99")[0]).splitlines()
    moves = sum(line.split()[:1] in (["L"], ["C"]) for line in before)  # (the moves up to LBL 99)
    assert "L X+10 Y+140 F300" not in written.partition("LBL 99")[2]
    assert landed(ends[moves : moves + 1], [(10, 140, -2)]).max() < 0.5e-3


@pytest.mark.parametrize("text", [BEHIND_A_JUMP, RUN_INTO_BEFORE], ids=["behind a jump", "run into"])
def test_a_text_before_its_call_compensates_and_verifies_on_the_wide_machine(tmp_path, text):
    program, out = tmp_path / "before.h", tmp_path / "out.h"
    program.write_text(text)
    assert main(["compensate", "--machine", str(_wide(tmp_path)), str(program), "-o", str(out)]) == 0
