"""Machine files: round trip, the aliases of M. Rahman, *Modeling and measurement of multi-axis
machine tools to improve positioning accuracy in a software way*, University of Oulu, 2004,
errors that name file and line."""

import numpy as np
import pytest

from ncpp.errors import NcppError
from ncpp.machine import load_machine, loads_machine, save_machine
from ncpp.machine.effects import Backlash

SAMPLES = "samples/machines"


@pytest.mark.parametrize("name", ["hr5b", "tl_tuotanto", "valmet"])
def test_samples_round_trip(name, tmp_path):
    m = load_machine(f"{SAMPLES}/{name}.toml")
    out = tmp_path / f"{name}.toml"
    save_machine(m, out)
    again = load_machine(out)
    assert again == m
    P = np.random.default_rng(0).uniform(0, 500, (100, 3))
    assert np.array_equal(again.deviation(P), m.deviation(P))


def test_sample_magnitudes_are_the_thesis_kind():
    m = load_machine(f"{SAMPLES}/tl_tuotanto.toml")
    P = np.linspace(m.limits["X"][0], m.limits["X"][1], 101)
    pos = m.components["EXX"](P)
    assert 5e-3 < np.ptp(pos) < 60e-3  # tens of µm
    for axis in "XYZ":
        for r in "ABC":
            ang = m.components[f"E{r}{axis}"](np.linspace(*m.limits[axis], 50))
            assert np.abs(ang).max() < 20e-6  # a few arcsec
    assert all(5e-6 < abs(v) < 60e-6 for v in m.squareness.values())
    assert any(isinstance(e, Backlash) for e in m.effects)


FULL = """
[machine]
name = "demo"
chain = "XZFY"

[offsets]
tool = [0.0, 0.0, -200.0]
reference.X = [0.0, 100.0, 0.0]

[limits]
X = [0, 800]

[errors.Xxx]
positions = [0.0, 100.0]
values_um = [0.0, 10.0]
values_um_minus = [2.0, 12.0]
interpolation = "smooth"

[errors.bx]
kind = "table"
positions = [0.0, 800.0]
values_urad = [5.0, 5.0]

[errors.yx]
kind = "polynomial"
coefficients_um = [1.0, 0.01]
reference_mm = 50.0

[squareness]
kxy_um_per_m = 20.0

[[effects]]
kind = "backlash"
axis = "X"
um = 4.0

[compensation]
max_correction_mm = 0.2
"""


def test_thesis_names_and_units():
    m = loads_machine(FULL, "demo.toml")
    assert set(m.components) == {"EXX", "EBX", "EYX"}
    assert m.components["EXX"](50.0, 1) == pytest.approx(0.005)
    assert m.components["EXX"](50.0, -1) == pytest.approx(0.007)
    assert m.components["EBX"](10.0) == pytest.approx(5e-6)
    assert m.components["EYX"](150.0) == pytest.approx(2e-3)
    assert m.squareness["C0Y"] == pytest.approx(20e-6)
    assert m.references["X"] == (0.0, 100.0, 0.0)
    assert m.max_correction_mm == 0.2
    assert m.effects == (Backlash("X", 4.0),)


@pytest.mark.parametrize(
    "old, new, line, message",
    [
        ('chain = "XZFY"', 'chain = "XZY"', 4, "chain"),
        ("values_urad = [5.0, 5.0]", "values_um = [5.0, 5.0]", 22, "angle"),
        ("[errors.yx]", "[errors.qq]", 24, "unknown error component"),
        ("um = 4.0", "microns = 4.0", 35, "unknown key"),
        ("X = [0, 800]", "X = [800, 0]", 11, "lo < hi"),
        ("kxy_um_per_m = 20.0", "kxy = 20.0", 30, "unit"),
        ("tool = [0.0, 0.0, -200.0]", "tool = [0.0, -200.0]", 7, "three"),
        ("values_um = [0.0, 10.0]", "values_um = [0.0, 10.0, 3.0]", 14, "3 values"),
        ("[compensation]", "[compensate]", 37, "unknown section"),
        ('name = "demo"', 'name = "demo', 3, "TOML"),
        (
            "max_correction_mm = 0.2",
            "max_correction_mm = 0.2\nrotary_xyz_are_axis_positions = 1",
            39,
            "true or false",
        ),
    ],
)
def test_errors_name_file_and_line(tmp_path, old, new, line, message):
    assert old in FULL
    path = tmp_path / "bad.toml"
    path.write_text(FULL.replace(old, new, 1))
    with pytest.raises(NcppError) as err:
        load_machine(path)
    assert err.value.where.file == str(path)
    assert message in err.value.message
    # the reported line is the offending key or its table header
    text_lines = path.read_text().splitlines()
    assert err.value.where.line is not None
    assert err.value.where.line == line, (err.value, text_lines[err.value.where.line - 1])


def test_missing_file():
    with pytest.raises(NcppError, match="cannot read"):
        load_machine("/nonexistent/m.toml")


def test_rotary_xyz_are_axis_positions_is_read_and_written(tmp_path):
    path = tmp_path / "rotary.toml"
    path.write_text(
        FULL.replace(
            "max_correction_mm = 0.2", "max_correction_mm = 0.2\nrotary_xyz_are_axis_positions = true"
        )
    )
    machine = load_machine(path)
    assert (
        machine.rotary_xyz_are_axis_positions
        and not load_machine(f"{SAMPLES}/hr5b.toml").rotary_xyz_are_axis_positions
    )
    save_machine(machine, tmp_path / "again.toml")
    assert load_machine(tmp_path / "again.toml").rotary_xyz_are_axis_positions
