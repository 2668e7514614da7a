"""The worked example: a warm machine grows, the ball bar sees it, `ncpp diagnose` names it.

Run from the repository root:  python samples/story/make_story.py
Writes into samples/story/:
  cold/laser_*.csv         laser measurement of the cold machine (X, Y, Z: position,
                           straightness, pitch/yaw/roll; 2 runs, 0.3 µm noise)
  cold_model.toml          the model fitted from them (ncpp.identify.fit_machine)
  warm/ballbar_*.csv       ball-bar tests of the warm machine (XY, YZ, ZX, R150, CW+CCW)
  diagnosis.txt            the account `ncpp diagnose` prints
  diagnosis.json           its report;  diagnosis.png  its plot
  updated_model.toml       the cold model plus the effect the diagnosis added
  warm_machine.toml        the simulated truth (the virtual machine the circle runs on)
  circle.ngc, circle_*.ngc a circle program and its compensations (`ncpp compensate`)
  compensation.txt         `ncpp simulate` of each on the warm machine: contour error and
                           circularity, uncompensated, with the cold model, with the updated model

The "real" machine is simulated: the HR5B sample's geometry (cold) plus, once
warm, thermal growth of X = 25 µm/m (a `scale` effect from the X reference).
"""

from __future__ import annotations

import contextlib
import io
import json
from pathlib import Path

import numpy as np

from ncpp.cli import main
from ncpp.fileio import portable_name, write_text_atomic
from ncpp.identify.fit import fit_machine
from ncpp.instruments.files import read_measurement, write_measurement
from ncpp.instruments.forward import predict_ballbar, predict_laser
from ncpp.machine import Machine, load_machine, save_machine
from ncpp.machine.effects import Scale

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
NOISE = 0.3
GROWTH = Scale("X", 25.0)  # µm/m: the warm machine's X scale has grown
CENTRE = (400.0, 350.0, 350.0)


def laser_files(cold: Machine) -> list[Path]:
    fixed = {"X": {"Y": 350, "Z": 350}, "Y": {"X": 400, "Z": 350}, "Z": {"X": 400, "Y": 350}}
    quantities = ("position", "pitch", "yaw", "roll")
    paths, seed = [], 10
    for axis in "XYZ":
        lo, hi = cold.limits[axis]
        targets = np.linspace(lo, hi, 15)
        straight = [f"straightness_{a.lower()}" for a in "XYZ" if a != axis]
        for q in (*quantities, *straight):
            m = predict_laser(cold, axis, q, targets, fixed=fixed[axis], runs=2, noise_um=NOISE, seed=seed)
            seed += 1
            path = HERE / "cold" / f"laser_{axis}_{q}.csv"
            write_measurement(m, path)
            paths.append(path)
    return paths


def ballbar_files(warm: Machine) -> list[Path]:
    paths = []
    for seed, plane in enumerate(("XY", "YZ", "ZX")):
        m = predict_ballbar(
            warm, plane, 150.0, CENTRE, feed_mm_min=1000.0, step_deg=1.0, noise_um=NOISE, seed=seed
        )
        path = HERE / "warm" / f"ballbar_{plane}_R150.csv"
        write_measurement(m, path)
        paths.append(path)
    return paths


CIRCLE = """%
(ncpp story: XY circle R150 about the program zero, placed at the ball-bar centre)
G21 G17 G90
G0 X150. Y0. Z0.
G1 F1000.
G3 X150. Y0. I-150. J0.
G0 Z10.
M2
%
"""


def run_quietly(*args: str) -> str:
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        assert main(list(args)) == 0
    return out.getvalue()


def contour_errors(models: dict[str, Path]) -> list[tuple[str, dict]]:
    """The circle program compensated with each model (`ncpp compensate`) and run
    on the warm machine (`ncpp simulate`): its contour error against the circle."""
    offset = ",".join(f"{v:g}" for v in CENTRE)
    program = HERE / "circle.ngc"
    write_text_atomic(program, CIRCLE)
    rows = []
    for label, model in models.items():
        target = program
        if model is not None:
            target = HERE / f"circle_{model.stem}.ngc"
            run_quietly(
                "compensate",
                "--machine",
                str(model),
                "--work-offset",
                offset,
                str(program),
                "-o",
                str(target),
            )
        report = HERE / "simulate.json"
        run_quietly("simulate", "--machine", str(HERE / "warm_machine.toml"), "--work-offset", offset,
                    "--reference", str(program), str(target), "--json", str(report))  # fmt: skip
        rows.append((label, json.loads(report.read_text())))
        report.unlink()
    return rows


def main_story() -> None:
    real = load_machine(ROOT / "samples/machines/hr5b.toml")
    cold, warm = real, real.replace(effects=real.effects + (GROWTH,))
    base = real.without_errors().replace(squareness=real.squareness, name="HR5B (cold laser model)")
    (HERE / "cold").mkdir(exist_ok=True)
    (HERE / "warm").mkdir(exist_ok=True)
    measurements = [read_measurement(p) for p in laser_files(cold)]
    names = {m.source: portable_name(m.source, HERE / "cold_model.toml") for m in measurements}
    save_machine(fit_machine(measurements, base, names=names), HERE / "cold_model.toml")
    balls = ballbar_files(warm)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(["diagnose", "--machine", str(HERE / "cold_model.toml"), *map(str, balls),
                   "--json", str(HERE / "diagnosis.json"), "--plot", str(HERE / "diagnosis.png"),
                   "-o", str(HERE / "updated_model.toml")])  # fmt: skip
    assert rc == 0
    text = out.getvalue().replace(str(HERE) + "/", "")
    write_text_atomic(HERE / "diagnosis.txt", text)
    save_machine(warm.replace(name="HR5B warm (the simulated truth)"), HERE / "warm_machine.toml")
    rows = contour_errors(
        {
            "not compensated": None,
            "compensated with the cold model": HERE / "cold_model.toml",
            "compensated with the updated model": HERE / "updated_model.toml",
        }
    )
    table = "circle.ngc (XY R150) run on the warm machine: contour error and circularity (µm)\n" + "".join(
        f"  {label:<38} max {r['contour_error_max_um']:6.2f}  rms {r['contour_error_rms_um']:6.2f}"
        f"  circularity {r['circles'][0]['circularity_um']:6.2f}\n"
        for label, r in rows
    )
    write_text_atomic(HERE / "compensation.txt", table)
    print(text)
    print(table)


if __name__ == "__main__":
    main_story()
