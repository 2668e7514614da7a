"""Settings files read whole are refused at a place when they are damaged or deep."""

from __future__ import annotations

import pytest

from ncpp.errors import NcppError
from ncpp.instruments.files import read_measurement
from ncpp.machine.io import loads_machine


def test_arrays_nested_thousands_deep_are_a_located_error():
    """(tomllib reads arrays recursively: 3000 deep ended in a RecursionError's traceback)"""
    with pytest.raises(NcppError) as caught:
        loads_machine("[machine]\nname = " + "[" * 3000 + "]" * 3000 + "\n", "m.toml")
    assert str(caught.value) == "m.toml:2:40: arrays or tables nested deeper than 32"


def test_brackets_in_strings_and_comments_are_not_nesting():
    with pytest.raises(NcppError, match="unknown key 'x'"):
        loads_machine('[machine]\nx = "' + "[" * 40 + '" # ' + "{" * 40 + "\n", "m.toml")


def test_a_metadata_number_is_refused_at_its_line_and_cut_short(tmp_path):
    path = tmp_path / "laser.csv"
    path.write_text(
        "# instrument: laser\n# axis: X\n# quantity: position\n# feed_mm_min: 1" + "#1=" * 5000 + "\n"
        "target_mm,run,direction,deviation_um\n0,1,+,0\n10,1,+,1\n"
    )
    with pytest.raises(NcppError) as caught:
        _ = read_measurement(path).feed_mm_min
    message = str(caught.value)
    assert message.startswith(f"{path}:4:1: feed_mm_min: '1#1=#1=") and len(message) < len(str(path)) + 100


def test_a_measurement_problem_of_the_whole_file_points_at_its_instrument_line(ncpp, tmp_path):
    path = tmp_path / "m.csv"
    path.write_text(
        "# a comment\n# instrument: level\x1b[2J\n# axis: X\ntarget_mm,run,direction,deviation_um\n0,1,+,0\n"
    )
    done = ncpp("analyze", str(path))
    assert done.returncode == 2 and b"\x1b" not in done.stderr
    assert done.stderr.decode().startswith(f"{path}:2:1: ")


def test_an_integer_of_thousands_of_digits_is_a_located_error():
    """(past Python's int digit limit tomllib's int() raised a ValueError: a traceback)"""
    with pytest.raises(NcppError) as caught:
        loads_machine("[machine]\nname = 'm'\n\n[limits]\nX = [-5, 1" + "0" * 5000 + "]\n", "m.toml")
    assert str(caught.value) == "m.toml:5:10: a number of more than 4,300 digits"
