"""A counted loop that would run more than MAX_RERUN lines again is refused as soon as one pass
has shown its length, at its own line, not after millions of lines have run."""

from __future__ import annotations

import time

import pytest

from ncpp.motion.flow import MAX_RERUN
from tests.conftest import SHARED

MACHINE = SHARED / "machines/wide.toml"
pytestmark = pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")

REPEAT = """G21 G17 G90 F200
G0 X0 Y0 Z5
o100 repeat [1000000000]
G1 X10 Y10
G1 X0 Y0
o100 endrepeat
M2
"""
NESTED_REPEAT = """G21 G17 G90 F200
G0 X0 Y0 Z5
o100 repeat [65534]
o101 repeat [20000]
G1 X10 Y10
G1 X0 Y0
o101 endrepeat
o100 endrepeat
M2
"""
# The head of the Klartext programs: a blank, a tool, the tool up
KLARTEXT_HEAD = """0 BEGIN PGM LOOP MM
1 BLK FORM 0.1 Z X+0 Y+0 Z-20
2 BLK FORM 0.2 X+100 Y+100 Z+0
3 TOOL CALL 1 Z S1000
4 L Z+5 R0 FMAX
"""
KLARTEXT = (
    KLARTEXT_HEAD
    + """5 LBL 1
6 LBL 2
7 L X+10 Y+10 R0 F200
8 L X+0 Y+0 R0 F200
9 CALL LBL 2 REP 20000
10 CALL LBL 1 REP 65534
11 L Z+50 R0 FMAX
12 END PGM LOOP MM
"""
)
# Fanuc's M98 P<n> L<repeats> (and G65's L): the subprogram's runs are a counted loop too
FANUC_L = """O1000
G21 G90 G54
G0 X0 Y0 Z5
M98 P1001 L999999999
M30
O1001
G91 G1 X1 F100
X-1
G90
M99
"""
SINUMERIK = """G17 G90 G71 F200
G0 X0 Y0 Z5
FOR R1=1 TO 100000
FOR R2=1 TO 20000
G1 X10 Y10
G1 X0 Y0
ENDFOR
ENDFOR
M30
"""


@pytest.mark.parametrize("expand", [(), ("--expand",)], ids=["", "expand"])
@pytest.mark.parametrize(
    "name, text, line",
    [
        ("repeat.ngc", REPEAT, 3),
        ("nested.ngc", NESTED_REPEAT, 3),
        ("loop.h", KLARTEXT, 11),
        ("loop.mpf", SINUMERIK, 3),  # (the outer FOR, refused at the inner loop's first pass)
        ("subs.nc", FANUC_L, 10),
    ],  # fmt: skip
)
def test_a_counted_loop_past_the_bound_is_refused_at_its_line_at_once(
    ncpp, tmp_path, name, text, line, expand
):
    program = tmp_path / name
    program.write_text(text)
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out"), *expand,
                timeout=20 if expand else 15)  # fmt: skip
    assert done.returncode == 2
    message = done.stderr.decode()
    assert f"{program}:{line}:1: " in message and f"more than {MAX_RERUN:,} lines run again" in message, (
        message
    )
    assert not (tmp_path / "out").exists()


def test_a_loop_of_a_hundred_thousand_passes_still_runs(ncpp, tmp_path):
    program = tmp_path / "many.ngc"
    program.write_text(REPEAT.replace("1000000000", "100000"))
    done = ncpp(
        "compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out"), timeout=120
    )
    assert done.returncode == 0, done.stderr


# Counted loops around a subprogram's repeated runs: the runs' first one shows their length, and the
# loops around the call are refused at their line then (before, only after a whole pass of the
# outer loop, or at the bound: 20 s to minutes).  Each program: its files, the refusing line.
ISO_REPEAT_AROUND_L = """G21 G90 G17
G0 X0 Y0 Z5 F200
o1 repeat [1000]
M98 P100 L1000000
o1 endrepeat
M2
O100
G91 G1 X1
X-1
G90
M99
"""
FANUC_L_AROUND_L = """%
O1000
G21 G90 G17
G0 X0 Y0 Z5 F200
M98 P2000 L9999
M30
O2000
M98 P3000 L9999
M99
O3000
G91 G1 X1
X-1
G90
M99
%
"""
# Fanuc 0i: `M98 P<runs><program>`, the program's number in P's last four digits
FANUC_P_AROUND_P = FANUC_L_AROUND_L.replace("P2000 L9999", "P99992000").replace("P3000 L9999", "P99993000")
# An o-word subroutine's blocks run in the pass of the repeat around its call (counted so before)
ISO_REPEAT_AROUND_CALL = """o<s> sub
o2 repeat [20000]
G1 X1
G1 X0
o2 endrepeat
o<s> endsub
G21 G90 G17
G0 X0 Y0 Z5 F200
o1 repeat [65534]
o<s> call
o1 endrepeat
M2
"""
SINUMERIK_FOR_AROUND_P = """G17 G90 G71 F200
G0 X0 Y0 Z5
FOR R1=1 TO 1000
L123 P9999
ENDFOR
M30
"""
SINUMERIK_P_AROUND_P = "G17 G90 G71 F200\nG0 X0 Y0 Z5\nL124 P9999\nM30\n"
INNER = "0 BEGIN PGM INNER MM\n1 LBL 3\n2 L X+10 Y+10 R0 F200\n3 L X+0 Y+0 R0 F200\n4 CALL LBL 3 REP 20000\n"
SUBPROGRAMS = {"L123.SPF": "G91 G1 X1\nX-1\nG90\nM17\n", "L124.SPF": "L123 P9999\nM17\n",
               "INNER.H": INNER + "5 END PGM INNER MM\n"}  # fmt: skip
# A REP section around a subprogram call whose REP sections run about 3,000,000 blocks a call
KLARTEXT_REP_AROUND_CALL = (
    KLARTEXT_HEAD
    + """5 LBL 1
6 CALL LBL 2
7 CALL LBL 1 REP 1000
8 L Z+50 R0 FMAX
9 M30
10 LBL 2
11 LBL 3
12 LBL 4
13 L X+10 Y+10 R0 F200
14 L X+0 Y+0 R0 F200
15 CALL LBL 4 REP 1000
16 CALL LBL 3 REP 1000
17 LBL 0
18 END PGM LOOP MM
"""
)

# Haas's local subprograms, each run L99 times (1-99, "M97 Local Sub-Program Call") by the one before
HAAS_L_AROUND_L = """%
O1000
G21 G90 G17
G0 X0 Y0 Z5 F200
M97 P100 L99
M30
N100
M97 P200 L99
M99
N200
M97 P300 L99
M99
N300
M97 P400 L99
M99
N400
G91 G1 X1
X-1
G90
M99
%
"""

# A REP section around a CALL PGM whose program's REP section runs 60,000 blocks
KLARTEXT_REP_AROUND_PGM = """0 BEGIN PGM LOOP MM
1 TOOL CALL 1 Z S1000
2 L Z+5 R0 FMAX
3 LBL 1
4 CALL PGM INNER
5 CALL LBL 1 REP 1000
6 L Z+50 R0 FMAX
7 END PGM LOOP MM
"""


@pytest.mark.parametrize(
    "name, text, line",
    [
        ("repeat-l.ngc", ISO_REPEAT_AROUND_L, 3),
        ("repeat-call.ngc", ISO_REPEAT_AROUND_CALL, 9),  # (the repeat: before, after its first pass, 25 s)
        ("l-l.nc", FANUC_L_AROUND_L, 5),  # (the outer M98: before, its M99 in O2000)
        ("m97.nc", HAAS_L_AROUND_L, 5),  # (the outer M97, once the innermost run has shown its length)
        ("p-p.nc", FANUC_P_AROUND_P, 5),  # (before, P99992000 was a program O99992000 not found)
        ("for-p.mpf", SINUMERIK_FOR_AROUND_P, 3),  # (the FOR: before, 5,000,000 blocks in called files)
        ("p-p.mpf", SINUMERIK_P_AROUND_P, 3),
        ("rep-call.h", KLARTEXT_REP_AROUND_CALL, 8),  # (the outer REP call: before, after its first pass)
        ("rep-pgm.h", KLARTEXT_REP_AROUND_PGM, 6),  # (before, 5,000,000 blocks in called files: 190 s)
    ],
)
def test_a_counted_loop_around_a_subprograms_repeated_runs_is_refused_at_its_line_at_once(
    ncpp, tmp_path, name, text, line
):
    program = tmp_path / name
    program.write_text(text)
    for file, body in SUBPROGRAMS.items():
        (tmp_path / file).write_text(body)
    started = time.monotonic()
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out"),
                "--subroutine-path", str(tmp_path), timeout=30)  # fmt: skip
    took = time.monotonic() - started
    message = done.stderr.decode()
    refusal = next((said for said in message.splitlines() if "lines run again" in said), message)
    assert done.returncode == 2 and refusal.startswith(f"{program}:{line}:1: "), message
    assert (
        f"more than {MAX_RERUN:,} lines run again" in refusal
        and "(the loops inside it run through)" in refusal
    )
    assert took < 6, f"refused after {took:.1f} s"


@pytest.mark.parametrize("name, text", [("l-l.nc", FANUC_L_AROUND_L), ("p-p.nc", FANUC_P_AROUND_P),
                                        ("for-p.mpf", SINUMERIK_FOR_AROUND_P)])  # fmt: skip
def test_subprogram_runs_that_stay_under_the_bound_run_to_their_end(ncpp, tmp_path, name, text):
    """The same programs with their counts made small: no refusal (the check counts, not guesses)."""
    program = tmp_path / name
    program.write_text(text.replace("9999", "30").replace("TO 1000", "TO 20"))
    for file, body in SUBPROGRAMS.items():
        (tmp_path / file).write_text(body)
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out"),
                "--subroutine-path", str(tmp_path), timeout=60)  # fmt: skip
    assert done.returncode == 0, done.stderr.decode()
