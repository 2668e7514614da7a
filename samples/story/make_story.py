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
  compensation.txt         simulated contour error of a circle on the warm machine:
                           uncompensated, compensated with the cold model, with the updated model

The "real" machine is simulated: the HR5B sample's geometry (cold) plus, once
warm, thermal growth of X = 25 µm/m (a `scale` effect from the X reference).
"""

from __future__ import annotations

import contextlib
import io
from pathlib import Path

import numpy as np

from ncpp.cli import main
from ncpp.fileio import write_text_atomic
from ncpp.identify.fit import fit_machine
from ncpp.instruments.files import read_measurement, write_measurement
from ncpp.instruments.forward import predict_ballbar, predict_laser
from ncpp.machine import Machine, Trajectory, load_machine, save_machine
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
        m = predict_ballbar(warm, plane, 150.0, CENTRE, feed_mm_min=1000.0, step_deg=1.0, noise_um=NOISE, seed=seed)
        path = HERE / "warm" / f"ballbar_{plane}_R150.csv"
        write_measurement(m, path)
        paths.append(path)
    return paths


class WithEffects:
    """The model as an error map for compensation, its position-only effects
    (scale, squareness, straightness, cyclic, angular) included.  (`ncpp
    compensate` uses `Machine.deviation`, which leaves [[effects]] out.)"""

    STATIC = ("scale", "squareness", "straightness", "cyclic", "angular")

    def __init__(self, machine: Machine) -> None:
        self.machine = machine

    def deviation(self, P, direction=None):
        d = self.machine.deviation(P, direction)
        trajectory = Trajectory(np.atleast_2d(P), 1000.0)
        for e in self.machine.effects:
            if e.kind in self.STATIC:
                d = d + e.apply(trajectory, self.machine)
        return d


def contour_error(warm: Machine, model: Machine | None) -> float:
    """Max radial error (µm) of an XY circle R150 cut on the warm machine with
    commands compensated by `model` (None: not compensated)."""
    wanted = Trajectory.circle("XY", CENTRE, 150.0, "CCW", 1000.0, step_deg=1.0).positions
    command = wanted.copy()
    if model is not None:
        emap = WithEffects(model)
        for _ in range(3):  # C <- P − E(C): E is microns
            command = wanted - emap.deviation(command)
    actual = warm.simulate(Trajectory(command, 1000.0))
    radial = np.linalg.norm((actual - np.asarray(CENTRE))[:, :2], axis=1) - 150.0
    return float(np.ptp(radial) * 1e3)


def main_story() -> None:
    real = load_machine(ROOT / "samples/machines/hr5b.toml")
    cold, warm = real, real.replace(effects=real.effects + (GROWTH,))
    base = real.without_errors().replace(squareness=real.squareness, name="HR5B (cold laser model)")
    (HERE / "cold").mkdir(exist_ok=True)
    (HERE / "warm").mkdir(exist_ok=True)
    model = fit_machine([read_measurement(p) for p in laser_files(cold)], base)
    save_machine(model, HERE / "cold_model.toml")
    balls = ballbar_files(warm)
    out = io.StringIO()
    with contextlib.redirect_stdout(out):
        rc = main(["diagnose", "--machine", str(HERE / "cold_model.toml"), *map(str, balls),
                   "--json", str(HERE / "diagnosis.json"), "--plot", str(HERE / "diagnosis.png"),
                   "-o", str(HERE / "updated_model.toml")])  # fmt: skip
    assert rc == 0
    text = out.getvalue().replace(str(HERE) + "/", "")
    write_text_atomic(HERE / "diagnosis.txt", text)
    for name in ("diagnosis.json", "updated_model.toml"):
        path = HERE / name
        write_text_atomic(path, path.read_text().replace(str(HERE) + "/", "").replace(str(ROOT) + "/", ""))
    updated = load_machine(HERE / "updated_model.toml")
    rows = [
        ("not compensated", contour_error(warm, None)),
        ("compensated with the cold model", contour_error(warm, model)),
        ("compensated with the updated model", contour_error(warm, updated)),
    ]
    table = "XY circle R150 on the warm machine, radial error range (µm)\n" + "".join(
        f"  {label:<38} {value:6.2f}\n" for label, value in rows
    )
    write_text_atomic(HERE / "compensation.txt", table)
    print(text)
    print(table)


if __name__ == "__main__":
    main_story()
