"""`pipeline.process` leaves the interpreter's global state as it found it."""

import gc
import io
from pathlib import Path

from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests.conftest import READING

MACHINE = Path(__file__).resolve().parents[2] / "samples/machines/hr5b.toml"

PROGRAM = b"G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F300\nG1 X40 Y10\nG2 X60 Y30 I0 J20\nM2\n"


def test_the_garbage_collector_threshold_is_restored():
    before = gc.get_threshold()
    source = ErrorSource.from_machine_file(str(MACHINE))
    out = io.BytesIO()
    process(
        io.BytesIO(PROGRAM), out, file="t.ngc", source=source, offsets=WorkOffsets.at((400.0, 350.0, 300.0))
    )
    assert gc.get_threshold() == before
    assert out.getvalue().count(b"\n") >= PROGRAM.count(b"\n")


def test_lines_in_are_counted_with_and_without_progress():
    program = (
        b"G21 G90\n" + b"G1 X1 Y2 F100\nX2 Y3\n" * 1500 + b"M2"
    )  # 3002 lines, the last without a newline
    reported: list[int] = []
    quiet = process(io.BytesIO(program), io.BytesIO(), file="t.ngc")
    told = process(io.BytesIO(program), io.BytesIO(), file="t.ngc", progress=reported.append)
    assert quiet.lines_in == told.lines_in == 3002
    assert reported == [1000, 2000, 3000]
    assert quiet.lines_out == 3002


def test_an_earlier_lines_error_is_told_before_a_later_parse_error():
    """The first error in the program is the one told, whichever stage finds it."""
    from ncpp.errors import NcppError

    good = b"G1 X1 Y2 F100\n" * 200
    for program, line in ((b"G21 G90\n" + good + b"G1 X1 X2\n" + good + b"G1 X(unclosed\n" + good, 202),
                          (b"G21 G90\n" + good * 30 + b"G1 X(unclosed\n" + good, 6002)):  # fmt: skip
        try:
            process(
                io.BytesIO(program),
                io.BytesIO(),
                file="t.ngc",
                source=ErrorSource.from_machine_file(str(READING)),
            )
        except NcppError as err:
            assert err.where.line == line
        else:
            raise AssertionError("no error")
