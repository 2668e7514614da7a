from __future__ import annotations

import numpy as np
import pytest

from ncpp.errors import NcppError
from ncpp.instruments.files import (
    Measurement,
    format_measurement,
    make_measurement,
    parse_measurement,
    read_measurement,
    write_measurement,
)

LASER = """# instrument: laser
# axis: X
# quantity: position
# fixed: Y=-250 Z=300
# offset_mm: 0,0,120
# operator: J. Smith
target_mm,run,direction,deviation_um
0,1,+,0.0
50,1,+,1.8
50,1,-,2.4
0,1,-,0.6
"""


def error_of(text: str) -> NcppError:
    with pytest.raises(NcppError) as info:
        parse_measurement(text, "f.csv")
    return info.value


def test_laser_file_columns_and_metadata():
    m = parse_measurement(LASER, "f.csv")
    assert m.instrument == "laser" and m.axis == "X" and m.quantity == "position"
    assert m.fixed == {"Y": -250.0, "Z": 300.0}
    np.testing.assert_array_equal(m.offset_mm, [0, 0, 120])
    assert m.meta["operator"] == "J. Smith"  # unknown keys are kept
    np.testing.assert_array_equal(m["target_mm"], [0, 50, 50, 0])
    assert m["run"].dtype.kind == "i" and list(m["direction"]) == ["+", "+", "-", "-"]
    np.testing.assert_array_equal(m["deviation_um"], [0.0, 1.8, 2.4, 0.6])
    assert len(m) == 4


def test_crlf_blank_lines_and_no_trailing_newline_read_the_same():
    plain = parse_measurement(LASER)
    messy = (
        LASER.replace("\n", "\r\n")
        .replace("# axis", "\r\n# axis")
        .replace("50,1,-", "\r\n\r\n50,1,-")
        .rstrip("\r\n")
    )
    assert parse_measurement(messy) == plain


def test_contract_example_with_remarks_is_understood():
    text = (
        "# instrument: ballbar\n# plane: XY                      (XY | YZ | ZX)\n# radius_mm: 150\n"
        "# center_mm: 400,-200,350        (command coordinates of the fixed ball)\n# feed_mm_min: 1000\n"
        "direction,angle_deg,deviation_um\nCCW,0.0,0.12\nCW,0.0,-0.30\n"
    )
    m = parse_measurement(text)
    assert m.plane == "XY" and m.radius_mm == 150 and m.feed_mm_min == 1000
    np.testing.assert_array_equal(m.center_mm, [400, -200, 350])
    header_remark = LASER.replace("deviation_um\n", "deviation_um      (deviation_urad for angles)\n")
    assert parse_measurement(header_remark) == parse_measurement(LASER)


def test_round_trip_of_every_sample(samples_dir, tmp_path):
    files = sorted(samples_dir.glob("*.csv"))
    assert {read_measurement(f).instrument for f in files} == {
        "laser",
        "comparator",
        "level",
        "ballbar",
        "grid",
        "cutting",
    }
    for f in files:
        m = read_measurement(f)
        write_measurement(m, tmp_path / f.name)
        assert read_measurement(tmp_path / f.name) == m
        assert (tmp_path / f.name).read_text() == format_measurement(m)


def test_samples_are_reproducible(generator, samples_dir, tmp_path):
    generator.main(tmp_path)
    for f in sorted(samples_dir.glob("*.csv")):
        assert (tmp_path / f.name).read_text() == f.read_text(), f.name


def test_round_trip_keeps_exact_floats(tmp_path):
    values = np.array([0.1, 1 / 3, -2.5e-7, 12345.678901234567, 0.0])
    m = make_measurement(
        "level",
        {"axis": "Y", "quantity": "pitch", "note": "x: y"},
        {"position_mm": np.arange(5.0), "inclination_um_per_m": values},
    )
    write_measurement(m, tmp_path / "l.csv")
    back = read_measurement(tmp_path / "l.csv")
    assert back == m and back.meta["note"] == "x: y"
    np.testing.assert_array_equal(back["inclination_um_per_m"], values)
    assert m != make_measurement(
        "level",
        {"axis": "Y", "quantity": "pitch"},
        {"position_mm": np.arange(5.0), "inclination_um_per_m": values},
    )


def test_write_is_atomic_and_leaves_no_temporary(tmp_path):
    m = parse_measurement(LASER)
    (tmp_path / "out.csv").write_text("old")
    write_measurement(m, tmp_path / "out.csv")
    assert [p.name for p in tmp_path.iterdir()] == ["out.csv"]
    assert read_measurement(tmp_path / "out.csv") == m


def test_own_instruments_grid_and_cutting():
    grid = parse_measurement(
        "# instrument: grid\n# plane: YZ\ns_mm,y_mm,z_mm,dev_y_um,dev_z_um\n0,10,0,0.5,-0.2\n"
    )
    assert grid.plane_axes == ("Y", "Z") and grid["dev_z_um"][0] == -0.2
    cut = parse_measurement("# instrument: cutting\n# radius_mm: 50\nangle_deg,radius_dev_um\n0,1.5\n90,-1\n")
    assert cut.radius_mm == 50 and list(cut["radius_dev_um"]) == [1.5, -1.0]


@pytest.mark.parametrize(
    "text, line, col, words",
    [
        ("# axis: X\ntarget_mm,run,direction,deviation_um\n0,1,+,0\n", 2, None, "instrument"),
        (LASER.replace("deviation_um\n", "deviation_mm\n"), 7, 25, "unknown column 'deviation_mm'"),
        (LASER.replace("50,1,+,1.8", "50,1,+,1.8x"), 9, 8, "'1.8x' is not a number"),
        (LASER.replace("50,1,+,1.8", "50,1,+"), 9, 1, "expected 4 columns"),
        (LASER.replace("50,1,-,2.4", "50,1,up,2.4"), 10, 6, "direction must be + or -"),
        (LASER.replace("50,1,-,2.4", "50,0,-,2.4"), 10, 4, "run counts from 1"),
        (LASER.replace("50,1,-,2.4", "50,99999999999999999999,-,2.4"), 10, 4, "run counts from 1 to 1000"),
        (LASER.replace("position", "speed"), 3, 1, "quantity"),
        (LASER.replace("0,0,120", "0,120"), 5, 1, "three numbers"),
        (LASER.replace("Y=-250", "Y-250"), 4, 1, "AXIS=value"),
        (
            "# instrument: ballbar\n# radius_mm: 150\ndirection,angle_deg,deviation_um\nCCW,0,0\nCW,360,0.1\n",
            5,
            4,
            "[0, 360)",
        ),
        (
            "# instrument: ballbar\n# radius_mm: 150\ndirection,angle_deg,deviation_um\nCCW,0,0\n+,10,0.1\n",
            5,
            1,
            "CW or CCW",
        ),
        ("# instrument: ballbar\ndirection,angle_deg,deviation_um\nCCW,0,0\n", 2, 1, "radius_mm"),
        (
            "# instrument: laser\n# quantity: pitch\ntarget_mm,run,direction,deviation_um\n0,1,+,0\n",
            3,
            1,
            "deviation_urad",
        ),
        ("# instrument: comparator\ntarget_mm,run,direction\n0,1,+\n", 2, 1, "lacks column(s) linear_um"),
        ("# instrument: laser\n", 1, None, "no CSV header"),
    ],
)
def test_bad_files_name_the_line(text, line, col, words):
    err = error_of(text)
    assert words in err.message
    assert err.where.file == "f.csv" and err.where.line == line
    if col is not None:
        assert err.where.col == col
    assert str(err).startswith(f"f.csv:{line}")


def test_unreadable_and_non_utf8(tmp_path):
    with pytest.raises(NcppError, match="cannot read"):
        read_measurement(tmp_path / "missing.csv")
    bad = tmp_path / "bad.csv"
    bad.write_bytes(b"# instrument: level\n# note: \xff\n")
    with pytest.raises(NcppError) as info:
        read_measurement(bad)
    assert info.value.where.line == 2


def test_measurement_is_a_value():
    m = parse_measurement(LASER)
    assert isinstance(m, Measurement) and m == parse_measurement(LASER)
    with pytest.raises(TypeError):
        hash(m)
