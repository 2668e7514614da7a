"""The parser reads ahead of the interpreter in runs (`pipeline._parsed_ahead`): the same
output and the same first error as line by line."""

import io

import pytest

import ncpp.pipeline as pipeline
from ncpp.errors import NcppError
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from ncpp.program.blocks import Block
from tests.conftest import ROOT

from .conftest import QUIET

OFFSET = (400.0, 350.0, 300.0)


@pytest.fixture(scope="module")
def source():
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def _run(data: bytes, source) -> bytes:
    out = io.BytesIO()
    process(
        io.BytesIO(data), out, file="t.ngc", source=source, warnings=QUIET, offsets=WorkOffsets.at(OFFSET)
    )
    return out.getvalue()


def _program(lines: int) -> bytes:
    body = "".join(
        f"G1 X{(k % 37) * 0.5:.3f} Y{(k % 23) * 0.7:.3f}\nG2 X{(k % 37) * 0.5 + 1:.3f} Y{(k % 23) * 0.7:.3f} R0.6\n"
        for k in range(lines // 2)
    )
    return f"G21 G90 G17\nF600\n{body}M2\n".encode()


def test_runs_of_any_length_write_what_one_line_at_a_time_writes(source, monkeypatch):
    data = _program(3000)
    monkeypatch.setattr(pipeline, "PARSED_AHEAD", 1)
    monkeypatch.setattr(pipeline, "FIRST_RUN", 1)
    one_by_one = _run(data, source)
    monkeypatch.setattr(pipeline, "PARSED_AHEAD", 4096)
    monkeypatch.setattr(pipeline, "FIRST_RUN", 7)
    assert _run(data, source) == one_by_one


def test_a_fault_in_an_earlier_line_is_reported_before_a_line_the_parser_refuses(source):
    # the zero-radius arc (line 3) is the interpreter's to refuse; the parser refuses line 5
    # (a number no float holds), which it reads first, in one run with line 3
    data = b"G21 G90\nG1 X1 F100\nG2 X10 Y0 I0 J0\nG1 X2\nG1 X" + b"9" * 400 + b"\nM2\n"
    with pytest.raises(NcppError) as error:
        _run(data, source)
    assert error.value.where.line == 3


def _pulls(n: int, log: list[int]):
    """Blocks of lines 1..n that log each line as the parser gives it."""
    for line in range(1, n + 1):
        log.append(line)
        yield Block(f"L{line}\n", "\n", (), line, True)


def test_runs_grow_from_the_first_to_the_most():
    log: list[int] = []
    taken = []
    for block in pipeline._parsed_ahead(_pulls(20_000, log), most=4096):
        taken.append(len(log) - block.line)  # how far the parser is ahead of the block handed on
    assert max(taken) == 4095
    assert taken[:2] == [0, 1023]  # the first block alone, then the first run of FIRST_RUN blocks
    assert len(taken) == 20_000
