"""Machine files and reports name their input files so that they mean the same on another computer:
relative to the written file, or by name and sha256 when far off; never by an absolute path."""

from __future__ import annotations

import hashlib
import json
import re
from pathlib import Path

import numpy as np

from ncpp.cli import main
from ncpp.instruments.files import write_measurement
from ncpp.instruments.forward import predict_ballbar, predict_laser
from ncpp.machine import load_machine
from ncpp.machine.effects import Backlash

ROOT = Path(__file__).resolve().parents[2]
HR5B = ROOT / "samples/machines/hr5b.toml"
# A path of the computer that wrote the file: absolute, or a home or temporary folder
ABSOLUTE = re.compile(r"(^|[\s\"'=(\[,])(/|[A-Za-z]:\\)[^\s\"']*")


def laser_file(path: Path) -> Path:
    machine = load_machine(HR5B)
    m = predict_laser(
        machine,
        "X",
        "position",
        np.linspace(0, 800, 9),
        fixed={"Y": 350, "Z": 350},
        runs=2,
        noise_um=0.3,
        seed=1,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    write_measurement(m, path)
    return path


def test_fit_names_its_files_relative_to_the_machine_file(tmp_path, capsys):
    data = laser_file(tmp_path / "data" / "laser_X_position.csv")
    out = tmp_path / "models" / "fitted.toml"
    out.parent.mkdir()
    assert main(["fit", str(data.resolve()), "--base", str(HR5B), "-o", str(out)]) == 0
    fitted = load_machine(out).meta["fitted"]
    assert fitted["EXX"] == "../data/laser_X_position.csv [deviation_um]"
    assert str(tmp_path) not in out.read_text()


def test_a_file_far_off_is_named_by_name_and_sha256(tmp_path, capsys):
    data = laser_file(tmp_path / "a" / "b" / "c" / "laser_X_position.csv")
    out = tmp_path / "x" / "y" / "z" / "fitted.toml"
    out.parent.mkdir(parents=True)
    assert main(["fit", str(data), "--base", str(HR5B), "-o", str(out)]) == 0
    digest = hashlib.sha256(data.read_bytes()).hexdigest()[:16]
    assert load_machine(out).meta["fitted"]["EXX"] == f"laser_X_position.csv sha256:{digest} [deviation_um]"
    assert str(tmp_path) not in out.read_text()


def test_diagnose_names_its_inputs_relative_to_the_model_and_report(tmp_path, capsys):
    base = tmp_path / "shop" / "model.toml"
    laser = laser_file(tmp_path / "shop" / "laser" / "laser_X_position.csv")
    assert main(["fit", str(laser), "--base", str(HR5B), "-o", str(base)]) == 0
    truth = load_machine(HR5B).replace(effects=(Backlash("Y", 8.0),))
    ballbar = tmp_path / "shop" / "bb" / "bb_XY.csv"
    ballbar.parent.mkdir()
    write_measurement(
        predict_ballbar(truth, "XY", 100, (400, 350, 300), step_deg=2.0, noise_um=0.3, seed=0), ballbar
    )
    updated, report = tmp_path / "shop" / "out" / "updated.toml", tmp_path / "shop" / "out" / "report.json"
    updated.parent.mkdir()
    assert (
        main(["diagnose", "--machine", str(base), str(ballbar), "-o", str(updated), "--json", str(report)])
        == 0
    )
    meta = load_machine(updated).meta
    assert meta["diagnosed_from"] == "../bb/bb_XY.csv"
    assert (
        meta["fitted"]["EXX"] == "../laser/laser_X_position.csv [deviation_um]"
    )  # renamed for where it is written
    assert json.loads(report.read_text())["model"] == "updated machine file written to updated.toml"
    for written in (updated, report):
        assert str(tmp_path) not in written.read_text()


def test_bundled_samples_carry_no_path_of_the_computer_that_made_them():
    for path in sorted(ROOT.glob("samples/**/*")):
        if path.suffix not in (".toml", ".json", ".txt", ".ngc", ".csv", ".md") or not path.is_file():
            continue
        text = path.read_text(encoding="utf-8", errors="replace")
        found = [
            m.group(0)
            for m in ABSOLUTE.finditer(text)
            if re.search(r"/(work|home|tmp|Users|root)/", m.group(0))
        ]
        assert not found, f"{path.relative_to(ROOT)} names {found[:3]}"


def test_predict_saves_the_machine_it_fitted_with_portable_names(tmp_path, capsys):
    data = laser_file(tmp_path / "data" / "laser_X_position.csv")
    saved = tmp_path / "data" / "fitted.toml"
    assert main(["predict", "--from", str(data), "--base", str(HR5B), "--save-machine", str(saved),
                 "--instrument", "ballbar", "--plane", "XY", "--radius", "100", "--center", "400,350,300",
                 "-o", str(tmp_path / "bb.csv")]) == 0  # fmt: skip
    assert load_machine(saved).meta["fitted"]["EXX"] == "laser_X_position.csv [deviation_um]"
