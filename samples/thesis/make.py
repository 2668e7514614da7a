"""Reproduce the comparisons of M. Rahman, *Modeling and measurement of multi-axis machine
tools to improve positioning accuracy in a software way*, University of Oulu, 2004
(section 4.8.4, Tables 2 and 5).

    python samples/thesis/make.py [OUTDIR]

1. "Measured" laser and level files of a cold machine: the HR5B sample
   machine (samples/machines/hr5b.toml) measured with the optic 120 mm off
   the tool point, 3 runs, noise 0.3 µm / 0.3 µrad (laser/), and VM182-type
   comparator files of X and Y (comparator/).
2. `ncpp fit laser/*.csv --base hr5b_structure.toml -o fitted_from_laser.toml`
   (and the same from the comparator files): the model from the measurements.
3. `ncpp predict --machine fitted_from_laser.toml --instrument ballbar ...`:
   the ball-bar traces the model predicts (XY R150 and ZX R100), and the
   comparator reading of X (laser → VM182).
4. "Measured" ball-bar traces: the true machine with what a cold static map
   lacks — backlash, servo mismatch, a reversal spike — and 0.3 µm noise.
5. comparison.md: Table 2/5-style figures, predicted vs measured; and
   ballbar_<plane>.png: the two traces side by side.

Everything uses fixed seeds; rerunning reproduces the files.
"""

from __future__ import annotations

import os
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]
sys.path.insert(0, str(ROOT))  # run from a source checkout without installing

from ncpp.cli import main as ncpp  # noqa: E402
from ncpp.fileio import write_text_atomic  # noqa: E402
from ncpp.instruments.analysis import analyze  # noqa: E402
from ncpp.instruments.files import read_measurement, write_measurement  # noqa: E402
from ncpp.instruments.forward import (  # noqa: E402
    ANGLE_COMPONENTS,
    predict_ballbar,
    predict_comparator,
    predict_laser,
    predict_level,
)  # noqa: E402
from ncpp.instruments.plots import plot_analyses  # noqa: E402
from ncpp.machine import effect_from_dict, load_machine, save_machine  # noqa: E402

MIDDLE = {"X": 400.0, "Y": 350.0, "Z": 350.0}
OPTIC = (0.0, 0.0, 120.0)
# What the laser's cold, static map cannot know (the "measured" ball bar has it).
DYNAMIC = (
    {"kind": "backlash", "axis": "X", "um": 3.0},
    {"kind": "backlash", "axis": "Y", "um": 5.0},
    {"kind": "backlash", "axis": "Z", "um": 2.0},
    {"kind": "servo_mismatch", "axes": "XY", "ms": 0.6},
    {"kind": "reversal_spike", "axis": "Y", "um": 2.0, "decay_mm": 3.0},
)
CIRCLES = (  # plane, radius, centre, feed
    ("XY", 150.0, "400,350,350", 1000.0),
    ("ZX", 100.0, "400,350,350", 1000.0),
)
FIGURES = (
    ("G", "circular deviation G (µm)"),
    ("G_ccw", "G CCW (µm)"),
    ("G_cw", "G CW (µm)"),
    ("H", "circular hysteresis H (µm)"),
    ("squareness_um_per_m", "squareness (µm/m)"),
    ("scale_mismatch_um_per_m", "scale mismatch (µm/m)"),
    ("backlash_{p}_um", "backlash {p} (µm)"),
    ("backlash_{q}_um", "backlash {q} (µm)"),
    ("servo_mismatch_ms", "servo mismatch (ms)"),
)


def measure_laser(machine, out: Path) -> list[Path]:
    """Position, straightness, pitch and yaw by laser, roll by level, every axis."""
    paths = []
    seed = 100
    for axis in "XYZ":
        lo, hi = machine.limits[axis]
        targets = np.linspace(lo, hi, 15)
        fixed = {a: v for a, v in MIDDLE.items() if a != axis}
        quantities = ["position"] + [f"straightness_{d.lower()}" for d in "XYZ" if d != axis]
        quantities += [q for (a, q) in ANGLE_COMPONENTS if a == axis and q != "roll"]
        for quantity in quantities:
            seed += 1
            m = predict_laser(
                machine,
                axis,
                quantity,
                targets,
                fixed=fixed,
                offset_mm=OPTIC,
                runs=3,
                noise_um=0.3,
                seed=seed,
            )
            paths.append(_write(m, out / f"laser_{axis}_{quantity}.csv"))
        seed += 1
        m = predict_level(machine, axis, targets, quantity="roll", fixed=fixed, noise_um=0.3, seed=seed)
        paths.append(_write(m, out / f"level_{axis}_roll.csv"))
    return paths


def measure_comparator(machine, out: Path) -> list[Path]:
    """VM182 along X (transverse Y) and Y (transverse X), head at the ball position."""
    paths = []
    for seed, (axis, transverse) in enumerate((("X", "Y"), ("Y", "X")), 200):
        lo, hi = machine.limits[axis]
        fixed = {a: v for a, v in MIDDLE.items() if a != axis}
        m = predict_comparator(
            machine, axis, transverse, np.linspace(lo, hi, 15), fixed=fixed, runs=3, noise_um=0.3, seed=seed
        )
        paths.append(_write(m, out / f"comparator_{axis}.csv"))
    return paths


def _write(m, path: Path) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    write_measurement(m, path)
    return path


def _run(*args: str) -> None:
    if ncpp(list(args)) != 0:
        raise SystemExit(f"ncpp {' '.join(args)} failed")


def _figure(figures: dict, key: str) -> str:
    value = figures.get(key)
    return "–" if value is None else f"{value:.2f}"


def circle_table(title: str, predicted: dict, measured: dict, plane: str) -> list[str]:
    p, q = plane
    rows = [
        f"### {title}",
        "",
        "| figure | predicted | measured | measured − predicted |",
        "|---|---:|---:|---:|",
    ]
    for key, label in FIGURES:
        key, label = key.format(p=p, q=q), label.format(p=p, q=q)
        a, b = predicted.get(key), measured.get(key)
        diff = "–" if a is None or b is None else f"{b - a:+.2f}"
        rows.append(f"| {label} | {_figure(predicted, key)} | {_figure(measured, key)} | {diff} |")
    return rows + [""]


def positioning_table(title: str, predicted: dict, measured: dict) -> list[str]:
    rows = [f"### {title}", "", "| figure (µm) | predicted | measured |", "|---|---:|---:|"]
    for key in ("A", "E", "M", "B", "R", "straightness_um"):
        rows.append(f"| {key} | {_figure(predicted, key)} | {_figure(measured, key)} |")
    return rows + [""]


def make(out: Path) -> None:
    """Write everything into `out`; file names in the outputs are relative to it."""
    out.mkdir(parents=True, exist_ok=True)
    os.chdir(out)
    out = Path(".")
    true = load_machine(ROOT / "samples/machines/hr5b.toml")
    structure = out / "hr5b_structure.toml"
    save_machine(true.without_errors().replace(name="Mitsui Seiki HR5B (structure only)"), structure)
    laser = measure_laser(true, out / "laser")
    comparator = measure_comparator(true, out / "comparator")
    from_laser, from_comparator = out / "fitted_from_laser.toml", out / "fitted_from_comparator.toml"
    _run(
        "fit",
        *map(str, laser),
        "--base",
        str(structure),
        "--name",
        "HR5B fitted from laser",
        "-o",
        str(from_laser),
    )
    _run(
        "fit",
        *map(str, comparator),
        "--base",
        str(structure),
        "--name",
        "HR5B fitted from VM182",
        "-o",
        str(from_comparator),
    )

    dynamic = true.replace(effects=tuple(effect_from_dict(e) for e in DYNAMIC))
    lines = [
        "# Predicted vs measured (Rahman 2004, section 4.8.4, Tables 2 and 5)",
        "",
        "M. Rahman, *Modeling and measurement of multi-axis machine tools to improve positioning",
        "accuracy in a software way*, University of Oulu, 2004.",
        "",
        'Made by `python samples/thesis/make.py` (fixed seeds). The "measured" files are',
        "simulated from `samples/machines/hr5b.toml`: laser/level files of the cold machine",
        "(optic 120 mm off the tool point, 3 runs, noise 0.3), and ball-bar traces of the same",
        "machine with what a static map lacks: "
        + ", ".join(_effect_text(e) for e in DYNAMIC)
        + ", noise 0.3 µm.",
        "The predictions come from `ncpp fit` + `ncpp predict`: laser → ball bar, comparator",
        "→ ball bar, laser → comparator. The differences are the non-geometric effects.",
        "",
    ]
    for plane, radius, centre, feed in CIRCLES:
        setup = [
            "--instrument",
            "ballbar",
            "--plane",
            plane,
            "--radius",
            f"{radius:g}",
            "--center",
            centre,
            "--feed",
            f"{feed:g}",
        ]
        predicted = out / f"ballbar_{plane}_predicted_from_laser.csv"
        _run("predict", "--machine", str(from_laser), *setup, "-o", str(predicted))
        centre_mm = np.array([float(v) for v in centre.split(",")])
        measured = _write(
            predict_ballbar(dynamic, plane, radius, centre_mm, feed_mm_min=feed, noise_um=0.3, seed=7),
            out / f"ballbar_{plane}_measured.csv",
        )
        a, b = analyze(read_measurement(predicted)), analyze(read_measurement(measured))
        lines += circle_table(
            f"Ball bar {plane} R{radius:g} F{feed:g}: laser → ball bar", a.figures, b.figures, plane
        )
        if plane == "XY":
            via = out / "ballbar_XY_predicted_from_comparator.csv"
            _run("predict", "--machine", str(from_comparator), *setup, "-o", str(via))
            lines += circle_table(
                "Ball bar XY R150: comparator → ball bar",
                analyze(read_measurement(via)).figures,
                b.figures,
                plane,
            )
        plot_analyses([a, b], out / f"ballbar_{plane}.png", dpi=75)

    predicted = out / "comparator_X_predicted_from_laser.csv"
    _run("predict", "--machine", str(from_laser), "--instrument", "comparator", "--axis", "X", "--transverse", "Y",
         "--targets", "0:800:50", "--runs", "3",
         "--fixed", "Y=350 Z=350", "-o", str(predicted))  # fmt: skip
    lines += positioning_table(
        "VM182 on X (transverse Y): laser → comparator",
        analyze(read_measurement(predicted)).figures,
        analyze(read_measurement(comparator[0])).figures,
    )
    write_text_atomic(out / "comparison.md", "\n".join(lines))


def _effect_text(effect: dict) -> str:
    what = {k: v for k, v in effect.items() if k != "kind"}
    return effect["kind"].replace("_", " ") + " " + " ".join(f"{k}={v}" for k, v in what.items())


if __name__ == "__main__":
    make(Path(sys.argv[1]).resolve() if len(sys.argv) > 1 else HERE)
