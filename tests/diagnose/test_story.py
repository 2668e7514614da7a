"""The README's worked example, rerun on its committed measurement files."""

from __future__ import annotations

import json
import subprocess
import sys

from tests.conftest import ROOT

STORY = ROOT / "samples/story"


def test_diagnose_names_the_thermal_growth_of_x(tmp_path):
    report = tmp_path / "report.json"
    updated = tmp_path / "updated.toml"
    balls = sorted(str(p) for p in (STORY / "warm").glob("ballbar_*.csv"))
    proc = subprocess.run(
        [
            sys.executable,
            "-m",
            "ncpp",
            "diagnose",
            "--machine",
            str(STORY / "cold_model.toml"),
            *balls,
            "--json",
            str(report),
            "-o",
            str(updated),
        ],  # fmt: skip
        capture_output=True,
        text=True,
    )
    assert proc.returncode == 0, proc.stderr
    data = json.loads(report.read_text())
    first = data["steps"][0]
    assert (first["effect"], first["axis"]) == ("scale", "X")
    assert abs(first["parameters"]["um_per_m"] - 25.0) < 0.2 * 25.0
    assert data["gap_after"]["rms_um"] < data["gap_before"]["rms_um"] / 2
    assert "scale" in updated.read_text()
