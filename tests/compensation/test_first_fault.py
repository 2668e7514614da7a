"""The fault reported is the program's first, whichever stage finds it: a pass that reads
events in batches hands on the events it holds when an earlier stage refuses a later line,
and `replace_arcs` hands on the lines before an arc it refuses (`ncpp/passes/__init__.py`)."""

import io

import numpy as np
import pytest

import ncpp.passes.replace_arcs as replace_arcs
from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests.conftest import ROOT

OFFSET = (400.0, 350.0, 300.0)

# Program X runs from -400 to 400 on HR5B's X travel [0, 800] with OFFSET
OUTSIDE = "G0 X3000\nG0 X0\n"  # the solve refuses the first line (apply_error_map, the last pass)
UNREADABLE_ARC = "G2 X10 Y0 I1 J0\n"  # the interpreter refuses it: its radii differ
BULGING_ARC = "G0 X392 Y-10\nG3 X392 Y10 I0 J10\n"  # its ends lie inside the travel, its middle (X402) does not: replace_arcs refuses it


@pytest.fixture(scope="module")
def source():
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def _moves(n: int) -> str:
    return "".join(f"G1 X{(k % 7) * 3:.3f} Y{(k % 5) * 2:.3f}\n" for k in range(n))


def _program(*pieces: str) -> bytes:
    return ("G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F300\n" + "".join(pieces) + "M2\n").encode()


def _line_of(text: bytes, piece: str) -> int:
    return text.decode().splitlines().index(piece.splitlines()[0]) + 1


def _refused(data: bytes, source) -> NcppError:
    with pytest.raises(NcppError) as error:
        process(
            io.BytesIO(data),
            io.BytesIO(),
            file="t.ngc",
            source=source,
            warnings=Warnings(stream=io.StringIO()),
            offsets=WorkOffsets.at(OFFSET),
        )
    return error.value


def test_a_pass_refusing_a_line_is_heard_before_the_interpreter_refusing_a_later_one(source):
    data = _program(_moves(100), OUTSIDE, _moves(500), UNREADABLE_ARC)
    error = _refused(data, source)
    assert (error.where.line, error.where.col) == (_line_of(data, OUTSIDE), 4)  # at its X word
    alone = _program(_moves(100), "G0 X0\n", _moves(500), UNREADABLE_ARC)
    assert _refused(alone, source).where.line == _line_of(
        alone, UNREADABLE_ARC
    )  # the interpreter's fault is found


def test_a_line_before_an_arc_replace_arcs_refuses_is_heard_first(source):
    data = _program(_moves(50), OUTSIDE, _moves(50), BULGING_ARC, _moves(50))
    assert _refused(data, source).where.line == _line_of(data, OUTSIDE)
    alone = _program(_moves(50), "G0 X0\n", _moves(50), BULGING_ARC, _moves(50))
    error = _refused(alone, source)
    assert error.where.line == _line_of(alone, BULGING_ARC) + 1 and "outside the X travel" in error.message
    assert error.where.col == 4  # `G3 X392 ...`: at its X word


@pytest.mark.parametrize("arcs, events", [(1024, 4096), (1, 4096), (3, 7), (1024, 2)])
def test_the_first_fault_whatever_the_batches(source, monkeypatch, arcs, events):
    monkeypatch.setattr(replace_arcs, "BATCH_ARCS", arcs)
    monkeypatch.setattr(replace_arcs, "BATCH_EVENTS", events)
    data = _program(_moves(20), BULGING_ARC, _moves(3), OUTSIDE, _moves(30), UNREADABLE_ARC, OUTSIDE)
    assert _refused(data, source).where.line == _line_of(data, BULGING_ARC) + 1
    data = _program(_moves(20), OUTSIDE, BULGING_ARC, _moves(30), UNREADABLE_ARC)
    assert _refused(data, source).where.line == _line_of(data, OUTSIDE)


class _Kinked:
    """A map with 0.5 µm of reversal error in X, and 0.6 mm more travelling -X between machine
    Y 359.5 and 360.5, program Y 9.5 and 10.5 (a correction there exceeds the 0.5 mm allowed)."""

    def deviation(self, P, direction=None):
        sign = np.zeros(len(P)) if direction is None else np.asarray(direction, dtype=float)[:, 0]
        error = np.zeros_like(P)
        error[:, 0] = 0.0005 * sign + np.where((sign < 0) & (np.abs(P[:, 1] - 360) < 0.5), 0.6, 0.0)
        return error


def test_a_reversal_step_refused_before_a_line_end_in_the_same_chunk_is_heard_first():
    """The solve checks a chunk's line ends before its reversal steps' starts.  Line 4 reverses X
    at Y10: it starts with a step there travelling -X (refused), and ends outside the band (too
    short, 0.6 mm, to be split); line 41 ends in the band travelling -X (refused)."""
    source = ErrorSource(model=_Kinked(), name="kinked", digest="0", max_correction=0.5)
    fillers = "".join(f"G1 Y{k % 2}\n" for k in range(35))
    data = (
        f"G21 G90 G17\nG0 X0 Y0 Z0\nG1 X5 Y10 F100\nG1 X4.9 Y10.6\n{fillers}G1 X10\nG1 X5 Y10\nM2\n".encode()
    )
    error = _refused(data, source)
    assert error.where.line == 4 and "exceeds the machine file's limit" in error.message
    outside = data.replace(
        b"G1 X5 Y10 F100\nG1 X4.9 Y10.6\n", b"G1 X5 Y11 F100\nG1 X4.9 Y11.6\n"
    )  # the step at Y11
    assert _refused(outside, source).where.line == 41


@pytest.mark.parametrize("block, col", [("G0 X3000", 4), ("n10 g0 y0 x3000", 11)])
def test_a_pass_names_the_column_of_the_word_it_refuses(source, block, col):
    error = _refused(_program(_moves(10), block + "\nG0 X0\n", _moves(10)), source)
    assert error.where.col == col and "outside the X travel" in error.message


def test_a_block_without_the_word_a_pass_refuses_is_named_by_its_first_column(source):
    """With G54's zero 1 mm short of the X travel, the X of the first move, G0 Z5, is outside
    the X travel, on a line with no X word."""
    with pytest.raises(NcppError) as error:
        process(io.BytesIO(b"G21 G90\n  G0 Z5\nM2\n"), io.BytesIO(), file="t.ngc", source=source, warnings=Warnings(stream=io.StringIO()),
                offsets=WorkOffsets.at((-1.0, 0.0, 0.0)))  # fmt: skip
    assert str(error.value).startswith("t.ngc:2:1: command X-1.00") and "is outside the X travel" in str(
        error.value
    )


def test_a_fault_named_past_its_batch_is_raised_without_solving_the_batch_again(source, monkeypatch):
    """A kernel's fault at a line its batch does not hold (none does so today) is raised as it
    is: the lines before it are the whole batch, which just failed."""
    import ncpp.passes.apply_error_map as apply_error_map
    from ncpp.errors import Location

    def refuse(*args):
        raise NcppError("refused", Location("t.ngc", 10**6))

    data = _program(_moves(30), "G0 X0 Y0\nG3 X0 Y20 I0 J10\n")  # an arc: replace_arcs fits a batch
    for module, name in ((replace_arcs, "_replace"), (apply_error_map, "_directional")):
        with monkeypatch.context() as patch:
            patch.setattr(module, name, refuse)
            assert _refused(data, source).where.line == 10**6
