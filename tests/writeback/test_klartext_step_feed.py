"""A Klartext block that sets the feed and is written in pieces: a reversal step before the block's
own move runs at the block's feed.  The step is a block of its own before the block (the block's text
says its own move), and a Klartext F is modal from the block that programs it: the step carries the
F too, else it runs at the feed before, which after FMAX blocks is none."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import Warnings
from ncpp.motion.segments import Arc, Line
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from tests.conftest import SHARED

WIDE = SHARED / "machines" / "wide.toml"
# the start of a Fusion 360 face milling program for a TNC (its blocks 9-21): an arc in the ZX plane
# (`CC X.. Z..`, `CP IPA+90 DR+ F1000`) after rapids only, then a line at that feed
FACE = """0  BEGIN PGM tb-final-face MM
9  M5
10 TOOL CALL 23 Z S5000
12 M3
13 L  X+513.43  Y-195.07 R0 FMAX
14 L  Z+15 R0 FMAX
18 L  Z+7.5 FMAX
19 CC  X+505.43  Z+7.5
20 CP IPA+90 DR+ F1000
21 L  X-40.01  Z-0.5
37 M30
38 END PGM tb-final-face MM
"""


@pytest.mark.skipif(not WIDE.exists(), reason="the shared machine files are not here")
def test_a_step_before_a_block_that_sets_the_feed_runs_at_that_feed():
    out = io.BytesIO()
    process(io.BytesIO(FACE.encode()), out, file="face.h", source=ErrorSource.from_machine_file(str(WIDE)),
            warnings=Warnings(stream=io.StringIO()), dialect="heidenhain")  # fmt: skip
    written = out.getvalue().decode()
    interpret, _ = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(written.encode()), "face.h", "heidenhain")
    events = interpret(blocks, file="face.h", warnings=Warnings(stream=io.StringIO()))
    feeds = [e for e in events if (type(e) is Line and not e.rapid) or type(e) is Arc]
    assert len(feeds) >= 3, written  # the step, the arc, the line
    assert [e.feed for e in feeds] == [1000.0] * len(feeds), written
