"""A counted loop that would run more than MAX_RERUN lines again is refused as soon as one pass
has shown its length, at its own line, not after millions of lines have run."""

from __future__ import annotations

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
KLARTEXT = """0 BEGIN PGM LOOP MM
1 BLK FORM 0.1 Z X+0 Y+0 Z-20
2 BLK FORM 0.2 X+100 Y+100 Z+0
3 TOOL CALL 1 Z S1000
4 L Z+5 R0 FMAX
5 LBL 1
6 LBL 2
7 L X+10 Y+10 R0 F200
8 L X+0 Y+0 R0 F200
9 CALL LBL 2 REP 20000
10 CALL LBL 1 REP 65534
11 L Z+50 R0 FMAX
12 END PGM LOOP MM
"""
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
