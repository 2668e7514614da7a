"""A feed move at a feed an F word set to 0 is refused where rs274 refuses it, with its message: a
FreeCAD program left before its author's post-processing (`G1 F0.000000 X.. Z-5.000000`, the real
one of pestami/Projects_DIY's 105-Compassbox) stops every control there (rs274ngc; grbl's error 22;
Fanuc's alarm PS0011).  A feed never set stays ncpp's leniency for program fragments."""

from __future__ import annotations

import subprocess
import sys

import pytest

from tests.conftest import ROOT, SHARED
from tests.rs274 import error, ran, run

WIDE = SHARED / "machines" / "wide.toml"
FREECAD = (
    "(Engrave)\nG0 F0.000000 Z6.000000\nG0 F0.000000 X16.98 Y57.06\nG1 F0.000000 X16.98 Y57.06 Z-5.000000\n"
)

pytestmark = pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")


def refusal(tmp_path, text: str, dialect: str) -> tuple[int, str]:
    program = tmp_path / "p.ngc"
    program.write_text(text)
    command = ["compensate", "--machine", str(WIDE), "--dialect", dialect, str(program), "-o", "-"]
    proc = subprocess.run([sys.executable, "-m", "ncpp", *command], capture_output=True, text=True, cwd=ROOT)
    return proc.returncode, proc.stderr


@pytest.mark.parametrize(
    ("text", "line"),
    [
        (FREECAD + "G1 F0.000000 X16.98 Y43.06 Z-5.000000\nG0 Z6.000000\nM2\n", 4),
        ("G21 G90\nF0\nG1 X10\nM2\n", 3),  # (a plain `G1 X..`: the interpreter's fast path)
        ("G21 G90\nG1 X1 F100\nF0\nX2\nM2\n", 4),  # (the modal G1's)
        ("G21 G91\nG1 X1 F100\nF0\nX2\nM2\n", 4),
        ("G21 G90\nG0 X1 F0\nG2 X3 I1 J0\nM2\n", 3),
        ("G21 G90\nG1 X1 F100\nG1 X2 F0\nM2\n", 3),
    ],
)
@pytest.mark.parametrize("dialect", ["linuxcnc", "grbl", "fanuc"])
def test_a_feed_move_at_a_zero_feed_is_refused_where_rs274_refuses_it(tmp_path, text, line, dialect):
    done = run(text)
    if not ran(done):
        pytest.skip("rs274 did not run")
    message, source = error(done.stderr)
    assert source == text.splitlines()[line - 1]
    code, stderr = refusal(tmp_path, text, dialect)
    assert code == 2 and f"p.ngc:{line}:" in stderr and message in stderr, stderr


def test_a_feed_never_set_is_still_left_to_the_control(tmp_path):
    code, stderr = refusal(tmp_path, "G21 G90\nG0 X0 Y0 Z5\nG1 X1\nG1 X2\nM2\n", "linuxcnc")
    assert code == 0 and "compensated 3 moves" in stderr, stderr
