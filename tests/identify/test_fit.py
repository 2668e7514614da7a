"""fit_machine: tables from laser / comparator / level files, Abbe terms removed."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from ncpp.cli import main
from ncpp.errors import NcppError
from ncpp.identify import fit_machine, fit_residuals
from ncpp.instruments.analysis import analyze
from ncpp.instruments.files import read_measurement, write_measurement
from ncpp.instruments.forward import (
    ANGLE_COMPONENTS,
    predict_ballbar,
    predict_comparator,
    predict_grid,
    predict_laser,
    predict_level,
)
from ncpp.machine import Machine, Polynomial, Table, load_machine
from ncpp.machine.effects import Backlash

ROOT = Path(__file__).resolve().parents[2]
TARGETS = np.arange(0.0, 801.0, 50.0)
EXX = Table((0.0, 400.0, 800.0), (0.0, 0.006, -0.004), interpolation="smooth")
EBX = Polynomial((0.0, 2e-8))
EAX = Polynomial((0.0, -1.5e-8))


def true_machine() -> Machine:
    return Machine(
        name="true", chain="XYFZ", tool=(0, 0, -100), components={"EXX": EXX, "EBX": EBX, "EAX": EAX}
    )


def test_abbe_offset_of_the_optic_is_removed_with_the_pitch_file():
    true = true_machine()
    position = predict_laser(true, "X", "position", TARGETS, offset_mm=(0, 0, 120), runs=2)
    pitch = predict_laser(true, "X", "pitch", TARGETS, offset_mm=(0, 0, 120))
    fitted = fit_machine([position, pitch], base=true.without_errors())
    assert np.allclose(fitted.component("EXX")(TARGETS) * 1e3, EXX(TARGETS) * 1e3, atol=1e-3)
    assert np.allclose(fitted.component("EBX")(TARGETS), EBX(TARGETS), atol=1e-10)
    # Without the pitch file the table keeps pitch × Abbe offset: the reading at the
    # optic, 120 mm above a tool point 100 mm below the reference point.
    alone = fit_machine([position], base=true.without_errors())
    gap = (alone.component("EXX")(TARGETS) - EXX(TARGETS)) * 1e3
    assert np.allclose(gap, 20.0 * EBX(TARGETS) * 1e3, atol=1e-3)


def test_level_roll_on_a_workpiece_side_axis():
    true = true_machine()
    level = predict_level(true, "X", TARGETS, quantity="roll", fixed="Y=100 Z=0")
    fitted = fit_machine([level], base=true.without_errors())
    assert np.allclose(fitted.component("EAX")(TARGETS), EAX(TARGETS), atol=1e-10)


def test_comparator_gives_linear_and_transverse():
    true = Machine(name="true", chain="XYFZ", components={"EXX": EXX, "EYX": Polynomial((0.0, 0.0, 1e-8))})
    comp = predict_comparator(true, "X", "Y", TARGETS, runs=2)
    fitted = fit_machine([comp])  # default chain XYFZ, zero offsets
    assert fitted.chain == "XYFZ"
    assert set(fitted.components) == {"EXX", "EYX"}
    assert np.allclose(fitted.component("EYX")(TARGETS), true.component("EYX")(TARGETS), atol=1e-6)


def test_reversal_gives_per_direction_tables_unless_the_base_explains_it():
    true = true_machine().replace(effects=(Backlash("X", 3.0),))
    position = predict_laser(true, "X", "position", TARGETS, runs=3, noise_um=0.1, seed=1)
    fitted = fit_machine([position], base=true.without_errors())
    table = fitted.component("EXX")
    assert table.directional
    assert np.allclose((table(TARGETS, 1.0) - table(TARGETS, -1.0)) * 1e3, -3.0, atol=0.3)
    explained = fit_machine([position], base=true.without_errors().replace(effects=(Backlash("X", 3.0),)))
    assert not explained.component("EXX").directional


def test_fitted_sample_machine_predicts_the_same_ballbar():
    true = load_machine(ROOT / "samples/machines/hr5b.toml")
    middle = {"X": 400.0, "Y": 350.0, "Z": 350.0}
    files = []
    for axis in "XYZ":
        lo, hi = true.limits[axis]
        targets = np.linspace(lo, hi, 15)
        fixed = {a: v for a, v in middle.items() if a != axis}
        quantities = ["position"] + [f"straightness_{d.lower()}" for d in "XYZ" if d != axis]
        quantities += [q for (a, q) in ANGLE_COMPONENTS if a == axis and q != "roll"]
        files += [
            predict_laser(true, axis, q, targets, fixed=fixed, offset_mm=(0, 0, 120), runs=2)
            for q in quantities
        ]
        files.append(predict_level(true, axis, targets, quantity="roll", fixed=fixed))
    fitted = fit_machine(files, base=true.without_errors())
    assert max(fit_residuals(fitted, files).values()) < 1e-3
    centre = (400.0, 350.0, 350.0)
    a = analyze(predict_ballbar(true, "XY", 150, centre, step_deg=2.0)).figures
    b = analyze(predict_ballbar(fitted, "XY", 150, centre, step_deg=2.0)).figures
    for key in ("G", "H", "squareness_um_per_m", "backlash_X_um", "backlash_Y_um"):
        assert b[key] == pytest.approx(a[key], abs=0.15), key


def test_files_the_fit_cannot_use():
    true = true_machine()
    with pytest.raises(NcppError, match="grid"):
        fit_machine([predict_grid(true, "XY", "circle", (400, 0, 0), 100, step_deg=10.0)])
    one = predict_laser(true, "X", "position", TARGETS)
    two = predict_comparator(true, "X", "Y", TARGETS)
    with pytest.raises(NcppError, match="EXX is given by both"):
        fit_machine([one, two])
    with pytest.raises(NcppError, match="no measurement"):
        fit_machine([])


def test_fit_and_predict_commands(tmp_path):
    samples = ROOT / "samples/measurements"
    files = [
        str(samples / n)
        for n in (
            "laser_X_position.csv",
            "laser_X_pitch.csv",
            "laser_X_straightness_y.csv",
            "level_X_roll.csv",
        )
    ]
    out = tmp_path / "fitted.toml"
    assert main(["fit", *files, "--chain", "XZFY", "-o", str(out)]) == 0
    machine = load_machine(out)
    assert machine.chain == "XZFY" and {"EXX", "EYX", "EBX", "EAX"} <= set(machine.components)
    assert machine.component("EXX").directional  # the sample has a 3.2 µm reversal
    bb = tmp_path / "bb.csv"
    png = tmp_path / "bb.png"
    args = ["predict", "--from", *files, "--chain", "XZFY", "--instrument", "ballbar", "--plane", "ZX",
            "--radius", "100", "--center", "500,0,0", "-o", str(bb), "--plot", str(png)]  # fmt: skip
    assert main(args) == 0
    assert read_measurement(bb).instrument == "ballbar" and png.stat().st_size > 10_000
    laser = tmp_path / "laser.csv"
    args = ["predict", "--machine", str(ROOT / "samples/machines/tl_tuotanto.toml"), "--instrument", "laser",
            "--axis", "Y", "--targets", "0:500:50", "--runs", "3", "--noise", "0.2", "--seed", "1", "-o", str(laser)]  # fmt: skip
    assert main(args) == 0
    assert analyze(read_measurement(laser)).figures["B"] > 3.0  # the machine's 4 µm Y backlash


def test_command_errors_are_messages(tmp_path, capsys):
    bad = tmp_path / "x.csv"
    write_measurement(predict_grid(true_machine(), "XY", "circle", (400, 0, 0), 100, step_deg=30.0), bad)
    assert main(["fit", str(bad), "-o", str(tmp_path / "m.toml")]) == 2
    assert "grid" in capsys.readouterr().err
    args = [
        "predict",
        "--machine",
        str(ROOT / "samples/machines/hr5b.toml"),
        "--instrument",
        "laser",
        "--targets",
        "5:1",
        "-o",
        str(tmp_path / "o.csv"),
    ]
    assert main(args) == 2
    assert "--targets" in capsys.readouterr().err
