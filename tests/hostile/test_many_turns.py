"""An arc of many turns (LinuxCNC's `G2 ... P10000`) at a large radius: its pieces are fitted a slice
at a time, so compensating it unverified takes a bounded memory, and the verifier refuses it at
its line once its chords are more than it holds at once, rather than filling the memory."""

from __future__ import annotations

import pytest

from ncpp.verify import MAX_CHORDS
from tests.conftest import SHARED
from tests.hostile.test_resources import peak_kb

MACHINE = SHARED / "machines/wide.toml"
pytestmark = pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
TURNS = "G21 G17 G90 F200\nG0 X200 Y0 Z5\nG1 Z0\nG2 X0 Y200 I-200 J0 P10000\nG0 Z5\nM2\n"


def test_an_arc_of_ten_thousand_turns_is_compensated_in_bounded_memory(tmp_path):
    program = tmp_path / "turns.ngc"
    program.write_text(TURNS)
    out = tmp_path / "out.ngc"
    peak = peak_kb("compensate", "--machine", str(MACHINE), str(program), "-o", str(out), "--no-verify")
    assert out.read_text().count("\nG2") > 10_000
    assert peak < 450_000, peak  # (each piece's samples held at once: 1.1 GB)


def test_an_arc_of_more_chords_than_the_verifier_holds_is_refused_at_its_line(ncpp, tmp_path):
    program = tmp_path / "turns.ngc"
    program.write_text(TURNS)
    done = ncpp("compensate", "--machine", str(MACHINE), str(program), "-o", str(tmp_path / "out"),
                memory_mb=1500, timeout=60)  # fmt: skip
    said = done.stderr.decode()
    assert done.returncode == 2, said
    assert f"{program}:4:1: verification: an arc of " in said and f"({MAX_CHORDS:,})" in said, said
    assert not (tmp_path / "out").exists()
