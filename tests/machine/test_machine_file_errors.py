"""Bad machine files: a message naming the file, line (and column where it helps) and
the key, saying what is expected; never a traceback or a machine that fails later."""

import re

import pytest

from ncpp.errors import NcppError
from ncpp.machine import load_machine, loads_machine

BASE = """\
[machine]
name = "demo"
chain = "XYFZ"

[offsets]
tool = [0.0, 0.0, -200.0]
reference.X = [0.0, 100.0, 0.0]

[limits]
X = [0.0, 800.0]
Y = [0.0, 500.0]

[errors.EXX]
positions = [0.0, 400.0, 800.0]
values_um = [0.0, 2.0, 3.0]

[errors.EYY]
kind = "polynomial"
coefficients_um = [0.0, 0.01]
reference_mm = 100.0
range_mm = [0.0, 500.0]

[errors.EBX]
positions = [0.0, 800.0]
values_urad = [5.0, 5.0]

[squareness]
C0Y_urad = 20.0

[[effects]]
kind = "scale"
axis = "X"
um_per_m = 5.0

[[effects]]
kind = "straightness"
axis = "X"
direction = "Y"
um = 2.0

[compensation]
max_correction_mm = 0.5
"""

# effects as an inline array, as the sample machines write them
INLINE = """\
effects = [
    { kind = "backlash", axis = "X", um = 3.0 },
    { kind = "servo_mismatch", axes = "XY", ms = 0.4 },
]

[machine]
chain = "XYFZ"
"""


def _error(tmp_path, text: str) -> NcppError:
    path = tmp_path / "bad.toml"
    path.write_text(text, encoding="utf-8")
    with pytest.raises(NcppError) as err:
        load_machine(path)
    assert err.value.where.file == str(path)
    return err.value


def test_the_base_files_are_good():
    m = loads_machine(BASE)
    assert len(m.effects) == 2 and set(m.components) == {"EXX", "EYY", "EBX"}
    assert len(loads_machine(INLINE).effects) == 2


POLY_OVERFLOW = "coefficients_um = [" + ", ".join(["1e-3"] * 400) + "]"


@pytest.mark.parametrize(
    "old, new, line, message",
    [
        # effect parameters: type checked at load, not when the effect is applied
        (
            "um_per_m = 5.0",
            'um_per_m = "5"',
            33,
            "effects #1: effect scale: um_per_m must be a finite number, not '5'",
        ),
        ("um_per_m = 5.0", 'um_per_m = 5.0\nref_mm = "a"', 34, "ref_mm must be a finite number, not 'a'"),
        ("um_per_m = 5.0", "um_per_m = nan", 33, "effects #1: um_per_m must be a finite number, not nan"),
        ("um = 2.0", "um = inf", 39, "effects #2: um must be a finite number, not inf"),
        (
            "um = 2.0",
            "um = 2.0\nrange_mm = [1.0]",
            40,
            "range_mm must be [lo, hi], two finite numbers, not [1.0]",
        ),
        ('axis = "X"', "axis = 5", 32, "effects #1: axis must be X, Y or Z, not 5"),
        ('axis = "X"', 'axis = "XY"', 32, "axis must be X, Y or Z, not 'XY'"),
        ('kind = "scale"', 'kind = ["scale"]', 31, "unknown effect kind ['scale']"),
        # limits and offsets: the key and the shape expected
        ("X = [0.0, 800.0]", "X = [800.0]", 10, "limits: X must be two numbers [lo, hi] in mm, not [800.0]"),
        (
            "X = [0.0, 800.0]",
            'X = "0..800"',
            10,
            "limits: X must be two numbers [lo, hi] in mm, not '0..800'",
        ),
        ("X = [0.0, 800.0]", "X = [-inf, inf]", 10, "limits: X must be finite numbers, not -inf (item 1)"),
        ("Y = [0.0, 500.0]", "Y = [0.0, 500.0]\nW = [0.0, 1.0]", 12, "unknown key 'W' in [limits]"),
        (
            "tool = [0.0, 0.0, -200.0]",
            'tool = "abc"',
            6,
            "offsets: tool must be three numbers [x, y, z] in mm, not 'abc'",
        ),
        ("tool = [0.0, 0.0, -200.0]", "tool = [[0.0], 0.0, -200.0]", 6, "not [[0.0], 0.0, -200.0]"),
        ("tool = [0.0, 0.0, -200.0]", "tool = [true, 0.0, -200.0]", 6, "offsets: tool must be three numbers"),
        ("reference.X = [0.0, 100.0, 0.0]", "reference = 5", 7, "reference must be a table"),
        (
            "max_correction_mm = 0.5",
            'max_correction_mm = "x"',
            42,
            "compensation: max_correction_mm must be a finite number, not 'x'",
        ),
        (
            "max_correction_mm = 0.5",
            "max_correction_mm = inf",
            42,
            "max_correction_mm must be a finite number, not inf",
        ),
        # error components
        (
            "reference_mm = 100.0",
            'reference_mm = "a"',
            20,
            "errors.EYY: reference_mm must be a finite number, not 'a'",
        ),
        (
            "reference_mm = 100.0",
            "reference_mm = inf",
            20,
            "errors.EYY: reference_mm must be a finite number, not inf",
        ),
        (
            "range_mm = [0.0, 500.0]",
            "range_mm = [500.0]",
            21,
            "errors.EYY: range_mm must be two numbers [lo, hi] in mm, not [500.0]",
        ),
        # (the unknown key's line, not that of a key as long named among those expected)
        (
            "range_mm = [0.0, 500.0]",
            "range_mm = [0.0, 500.0]\nvalues_um_minus = [1.0]",
            22,
            "errors.EYY: unknown key(s) values_um_minus",
        ),
        ("coefficients_um = [0.0, 0.01]", POLY_OVERFLOW, 19, "coefficients_um overflow between 0 and 500 mm"),
        (
            "positions = [0.0, 400.0, 800.0]",
            'positions = ["0", "400", "800"]',
            14,
            "positions must be a finite number, not '0'",
        ),
        (
            "values_urad = [5.0, 5.0]",
            "values_urad = [5.0, 2e4]",
            25,
            "values_urad must be within ±10000 µrad",
        ),
        (
            "[compensation]",
            "[errors.xx]\npositions = [0.0]\nvalues_um = [1.0]\n\n[compensation]",
            41,
            "EXX is given twice, as EXX and xx",
        ),
        # errors of a metre and more are typing errors (1e300 µm of backlash simulated as 'inf µm')
        ("um = 2.0", "um = 1e300", 39, "effects #2: effect straightness: um must be within ±1e+06"),
        ("um_per_m = 5.0", "um_per_m = -2e6", 33, "effect scale: um_per_m must be within ±1e+06"),
        (
            "values_um = [0.0, 2.0, 3.0]",
            "values_um = [0.0, 2e6, 3.0]",
            15,
            "errors.EXX: values_um must be within ±1e+06 µm (a metre), not 2e+06",
        ),
        (
            "coefficients_um = [0.0, 0.01]",
            "coefficients_um = [0.0, 1e4]",
            19,
            "coefficients_um between 0 and 500 mm must be within ±1e+06 µm",
        ),
        # offsets, reference points and travel past a kilometre (a reference of 1e308 mm simulated 'inf µm')
        (
            "tool = [0.0, 0.0, -200.0]",
            "tool = [0.0, 0.0, -2e6]",
            6,
            "offsets: tool must be within ±1e+06 mm (a kilometre)",
        ),
        (
            "reference.X = [0.0, 100.0, 0.0]",
            "reference.X = [0.0, 1e308, 0.0]",
            7,
            "offsets.reference: X must be within ±1e+06 mm",
        ),
        ("X = [0.0, 800.0]", "X = [0.0, 8e300]", 10, "limits: X must be within ±1e+06 mm"),
        # an integer a float cannot hold (TOML has them): was an OverflowError
        (
            "X = [0.0, 800.0]",
            "X = [0.0, 1" + "0" * 310 + "]",
            10,
            "limits: X must be two numbers [lo, hi] in mm",
        ),
        (
            "values_um = [0.0, 2.0, 3.0]",
            "values_um = [0.0, 1" + "0" * 310 + ", 3.0]",
            15,
            "errors.EXX: values_um must be a finite number",
        ),
        ("um = 2.0", "um = 1" + "0" * 310, 39, "effects #2: effect straightness: um must be a finite number"),
        # squareness: one value each, and a small angle
        (
            "C0Y_urad = 20.0",
            "C0Y_urad = 1e300",
            28,
            "C0Y_urad must be within ±10000 µrad (the model's small angles), not 1e+300",
        ),
        (
            "C0Y_urad = 20.0",
            "C0Y_urad = 20.0\nC0Y_um_per_m = 3.0",
            29,
            "C0Y is given twice, as C0Y_urad and C0Y_um_per_m",
        ),
    ],
)
def test_bad_values_name_the_key_and_line(tmp_path, old, new, line, message):
    assert old in BASE
    err = _error(tmp_path, BASE.replace(old, new, 1))
    assert message in err.message
    assert err.where.line == line, err


NUMBERS = list(re.finditer(r"-?\d+\.\d+", BASE))


def _line_of(match: re.Match) -> int:
    return BASE.count("\n", 0, match.start()) + 1


@pytest.mark.parametrize("bad", ["nan", "inf", "-inf"])
@pytest.mark.parametrize("number", NUMBERS, ids=lambda m: f"line{_line_of(m)}:{m.group()}")
def test_no_number_anywhere_may_be_nan_or_infinite(tmp_path, number, bad):
    err = _error(tmp_path, BASE[: number.start()] + bad + BASE[number.end() :])
    assert re.search(rf"\w+ must be (a finite number|finite numbers), not {bad}\b", err.message), err
    assert err.where.line == _line_of(number), err


@pytest.mark.parametrize(
    "old, new, line, col, message",
    [
        (
            '{ kind = "backlash", axis = "X", um = 3.0 }',
            '"backlash"',
            2,
            5,
            'effects #1: must be a table such as { kind = "backlash"',
        ),
        ("um = 3.0", 'um = "3"', 2, 38, "effects #1: effect backlash: um must be a finite number, not '3'"),
        ("um = 3.0", "um = nan", 2, 38, "effects #1: um must be a finite number, not nan"),
        ("ms = 0.4", "ms = inf", 3, 45, "effects #2: ms must be a finite number, not inf"),
        ('axes = "XY"', 'axes = "X"', 3, 32, "axes must name two different axes"),
        (", ms = 0.4", "", 3, 5, "effects #2: effect servo_mismatch: missing key(s) ms"),
    ],
)
def test_inline_effects_are_located_by_item_and_key(tmp_path, old, new, line, col, message):
    assert old in INLINE
    err = _error(tmp_path, INLINE.replace(old, new, 1))
    assert message in err.message
    assert (err.where.line, err.where.col) == (line, col), err


def test_a_file_that_is_not_utf8_is_located_at_its_first_bad_byte(tmp_path):
    path = tmp_path / "latin1.toml"  # é in UTF-8, then é in Latin-1: the column counts characters
    path.write_bytes(BASE.encode().replace(b'name = "demo"', b'name = "\xc3\xa9\xe9mo"'))
    with pytest.raises(NcppError) as err:
        load_machine(path)
    assert "not UTF-8" in err.value.message and "0xe9" in err.value.message
    assert (err.value.where.file, err.value.where.line, err.value.where.col) == (str(path), 2, 10)


def test_a_long_file_is_located_past_the_readers_first_chunk(tmp_path):
    path = tmp_path / "long.toml"
    padding = "# " + "x" * 78 + "\n"
    path.write_bytes((padding * 500).encode() + b"# \xff\n" + BASE.encode())
    with pytest.raises(NcppError, match="not UTF-8") as err:
        load_machine(path)
    assert (err.value.where.line, err.value.where.col) == (501, 3)


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + BASE.encode("utf-8"))
    assert load_machine(path) == loads_machine(BASE)


def test_a_truncated_file_points_at_its_last_line(tmp_path):
    err = _error(tmp_path, BASE + "[errors.EZZ]\npositions")
    assert "not valid TOML" in err.message and "end of document" not in err.message
    assert err.where.line == BASE.count("\n") + 2
