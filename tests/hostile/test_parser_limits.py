"""Lines and brackets past what a control reads are refused quickly, with their place."""

from __future__ import annotations

import time

import pytest

from ncpp.errors import NcppError
from ncpp.program.dialects import get_dialect
from ncpp.program.parser import LineParser, parse_text
from tests.conftest import READING

MAX_NESTING = 128  # the bound README states


def test_the_scanner_is_linear_in_a_line_of_open_brackets():
    """200k `(` once took the plain-line scanner 48 s (each `(` tried to the end of the line)."""
    scan = LineParser("iso")._scan_items
    started = time.perf_counter()
    assert scan("G1 " + "(" * 200_000) is None
    assert scan("G1 " + "(" * 100_000 + ")") is not None
    assert time.perf_counter() - started < 2.0


@pytest.mark.parametrize("dialect, limit", [("iso", 256), ("sinumerik", 512), ("heidenhain", 4096)])
def test_a_block_longer_than_the_dialect_reads_is_refused_at_its_limit(dialect, limit):
    line = "X1 " * (limit // 3 + 2)
    with pytest.raises(NcppError) as caught:
        parse_text(f"{line}\n", "long.nc", dialect)
    assert caught.value.where.line == 1 and caught.value.where.col == limit + 1
    assert f"may have {limit}" in caught.value.message


def test_a_block_of_the_iso_limit_is_read():
    line = "G1 X1 (" + "a" * 248 + ")"
    assert len(line) == 256
    assert parse_text(line + "\n")[0].items[0].value == 1.0


def test_fifty_megabytes_of_one_line_are_refused_in_bounded_time(ncpp, tmp_path):
    program = tmp_path / "wide.ngc"
    program.write_bytes(b"X1 " * (16 << 20) + b"\n")
    started = time.perf_counter()
    done = ncpp("--machine", str(READING), str(program), memory_mb=1024, timeout=60)
    assert time.perf_counter() - started < 10  # (the dialect's detection once read the whole line: 37 s)
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert done.stderr.decode().startswith(f"{program}:1:257: block too long")


@pytest.mark.parametrize(
    "dialect, text",
    [
        ("iso", "G1 X{open}1{close}"),
        ("sinumerik", "R1={open}1{close}"),
        ("heidenhain", "1 Q1 = {open}1{close}"),
    ],
)
def test_brackets_nest_to_one_bound_in_every_dialect(dialect, text):
    opening, closing = ("[", "]") if dialect == "iso" else ("(", ")")
    deep = MAX_NESTING + 1
    line = text.format(open=opening * deep, close=closing * deep)
    with pytest.raises(NcppError) as caught:
        parse_text(line + "\n", "deep.nc", dialect)
    if len(line) > get_dialect(dialect).max_line:  # (an ISO line cannot hold them)
        assert "block too long" in caught.value.message
    else:
        assert caught.value.where.col == line.index(opening) + deep
        assert "nested deeper than 128" in caught.value.message
    ok = text.format(open=opening * MAX_NESTING, close=closing * MAX_NESTING)
    if len(ok) <= get_dialect(dialect).max_line:
        parse_text(ok + "\n", "deep.nc", dialect)


@pytest.mark.parametrize("dialect, suffix", [("sinumerik", "mpf"), ("heidenhain", "h")])
def test_a_million_brackets_are_refused_in_a_second(ncpp, tmp_path, dialect, suffix):
    program = tmp_path / f"deep.{suffix}"
    start = "1 Q1 = " if dialect == "heidenhain" else "R1="
    program.write_text(start + "(" * 10**6 + "1" + ")" * 10**6 + "\n")
    started = time.perf_counter()
    done = ncpp("--machine", str(READING), "--dialect", dialect, str(program), timeout=60)
    assert time.perf_counter() - started < 5
    assert done.returncode == 2 and b"block too long" in done.stderr
