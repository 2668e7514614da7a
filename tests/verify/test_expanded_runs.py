"""With --expand the verifier compares the written program with a reading of the input that writes
its loops out too, so a fault of the writing out would be in both; that reading is checked move by
move against a reading without --expand (the program's own run), and a move written out of its
place is refused.  The fault is planted here: the first two moves of the expanded reading swapped."""

import io

import pytest

import ncpp.pipeline as pipeline
from ncpp.errors import NcppError, Warnings
from ncpp.motion.segments import Arc, Line
from ncpp.pipeline import ErrorSource, process
from tests.conftest import SHARED

PROGRAM = b"G21 G90 G17\nG0 X0 Y0 Z5\n#1=0\no100 while [#1 LT 3]\nG1 X[#1*10] Y5 F300\nY0\n#1=[#1+1]\no100 endwhile\nM2\n"


def swapping(real):
    """`dialect_tools` whose interpreter, with --expand, hands out its first two moves swapped."""

    def tools(name):
        interpret, writer = real(name)

        def interpreted(blocks, **options):
            events = interpret(blocks, **options)
            return _swapped(events) if options.get("expand") else events

        return interpreted, writer

    return tools


def _swapped(events):
    held = None
    swapped = False
    for event in events:
        if not swapped and (type(event) is Line or type(event) is Arc):
            if held is None:
                held = event
                continue
            yield event
            yield held
            swapped = True
            continue
        yield event


def run(expand: bool) -> None:
    wide = SHARED / "machines" / "wide.toml"
    if not wide.is_file():
        pytest.skip(f"{wide} not found")
    process(io.BytesIO(PROGRAM), io.BytesIO(), file="p.ngc", source=ErrorSource.from_machine_file(str(wide)),
            warnings=Warnings(stream=io.StringIO()), expand=expand)  # fmt: skip


def test_a_move_written_out_of_its_place_is_refused(monkeypatch):
    run(expand=True)  # (as it is, the program written out passes)
    monkeypatch.setattr(pipeline, "dialect_tools", swapping(pipeline.dialect_tools))
    with pytest.raises(
        NcppError, match=r"p.ngc:\d+:1: verification: --expand wrote a move the program does not make"
    ):
        run(expand=True)
    run(expand=False)  # (without --expand nothing is swapped: the check is --expand's)
