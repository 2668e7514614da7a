"""`ncpp diagnose`: account, JSON report in the contract's form, updated model, plot."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from ncpp.cli import main
from ncpp.instruments.files import write_measurement
from ncpp.instruments.forward import predict_ballbar
from ncpp.machine import load_machine
from ncpp.machine.effects import Backlash

ROOT = Path(__file__).resolve().parents[2]
MODEL = ROOT / "samples/machines/hr5b.toml"


def test_command_writes_report_model_and_plot(tmp_path, capsys):
    truth = load_machine(MODEL).replace(effects=(Backlash("Y", 8.0),))
    files = []
    for i, (plane, centre) in enumerate((("XY", (400, 350, 300)), ("YZ", (400, 350, 350)))):
        path = tmp_path / f"bb_{plane}.csv"
        write_measurement(
            predict_ballbar(truth, plane, 100, centre, step_deg=2.0, noise_um=0.3, seed=i), path
        )
        files.append(str(path))
    report, updated, plot = tmp_path / "r.json", tmp_path / "up.toml", tmp_path / "gap.png"
    rc = main(
        [
            "diagnose",
            "--machine",
            str(MODEL),
            *files,
            "--json",
            str(report),
            "-o",
            str(updated),
            "--plot",
            str(plot),
        ]
    )
    assert rc == 0
    out = capsys.readouterr().out
    assert "backlash Y" in out and "where the gap sits" in out
    data = json.loads(report.read_text())
    assert set(data) == {"gap_before", "steps", "gap_after", "model"}
    assert set(data["gap_before"]) == {"rms_um", "max_um"} == set(data["gap_after"])
    (step,) = data["steps"]
    assert set(step) == {"effect", "axis", "parameters", "uncertainty", "gap_after", "evidence",
                         "alternatives"}  # fmt: skip
    assert (step["effect"], step["axis"]) == ("backlash", "Y")
    assert step["parameters"]["um"] == pytest.approx(8.0, rel=0.1)
    assert data["model"] == "updated machine file written to up.toml"  # named relative to the report
    model = load_machine(updated)
    assert [(e.kind, e.axis) for e in model.effects] == [("backlash", "Y")]
    assert plot.read_bytes()[:4] == b"\x89PNG"


def test_unusable_file_is_a_clean_error(tmp_path, capsys):
    level = tmp_path / "level.csv"
    level.write_text("# instrument: level\n# axis: X\nposition_mm,inclination_um_per_m\n0,1\n100,2\n")
    assert main(["diagnose", "--machine", str(MODEL), str(level)]) == 2
    assert "diagnose uses ballbar" in capsys.readouterr().err
