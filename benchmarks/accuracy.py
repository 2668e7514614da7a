"""Accuracy of `ncpp compensate` on the virtual machine.

For each sample machine and program: place the program inside the machine's
travel (work offset = centre of travel minus the centre of the program's
sampled bounding box, in mm), run the program on the modelled machine
(`ncpp.simulate`), compensate it at 1, 2 and 5 µm, run the result, and
compare both with the nominal path, over the moves compensation answers for
(`answerable`: not those it leaves as programmed with a warning, such as the
moves under cutter compensation; a note says how many).  Two model cases:

* exact: compensate with the very model that simulates the machine
  (geometry only: the effects are not in the compensation model).  The
  sample HR5B and Valmet have direction-dependent (reversal) tables, which
  a compensated path's own micro-motions switch; the `no reversal` variant
  replaces them by their mean so the guarantee "within tolerance + 0.5 µm"
  is checked on a model without them.
* fitted: the model is fitted (`fit_machine`) from laser and level files
  the true machine would give with 0.3 µm (µrad) noise; the compensated
  program runs on the true machine.

Run alone: `python benchmarks/accuracy.py [--quick]`, or as the `accuracy`
section of `benchmarks/run.py`.
"""

from __future__ import annotations

import io
import os
import sys
import time
from dataclasses import dataclass
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent
sys.path.insert(0, str(ROOT))

from ncpp.errors import Warnings  # noqa: E402
from ncpp.machine import Machine, load_machine  # noqa: E402
from ncpp.machine.components import Table  # noqa: E402
from ncpp.motion.offsets import WorkOffsets  # noqa: E402
from ncpp.motion.segments import Arc, Line  # noqa: E402
from ncpp.pipeline import ErrorSource, process  # noqa: E402
from ncpp.simulate import ContourReport, SampledPath, contour_error, sample_events  # noqa: E402

SHARED = Path(os.environ.get("NCPP_SHARED", ROOT.parent / "shared"))
CORPUS = SHARED / "corpus/iso_gcode"
MACHINES = {name: ROOT / f"samples/machines/{name}.toml" for name in ("hr5b", "tl_tuotanto", "valmet")}
TOLERANCES_MM = (0.001, 0.002, 0.005)
MARGIN_MM = 1.0  # kept free at each end of travel: corrections and reversal steps

# Programs with arcs, helices, G18/G19, inch units; (label, path).
PROGRAMS_QUICK = [
    ("pocket (sample)", ROOT / "samples/programs/pocket.ngc"),
    ("cncjs arc-xz-plane", CORPUS / "cncjs/arc-xz-plane.gcode"),
    ("cncjs arc-yz-plane", CORPUS / "cncjs/arc-yz-plane.gcode"),
    ("cncjs helical-thread-milling (inch)", CORPUS / "cncjs/helical-thread-milling.gcode"),
    ("fusion_fanuc fusion-output (G18)", CORPUS / "fusion_fanuc/fusion-output.nc"),
    ("fusion_fanuc fusion-inch (G18, inch)", CORPUS / "fusion_fanuc/fusion-inch.nc"),
    ("linuxcnc arcspiral (inch)", CORPUS / "linuxcnc/arcspiral.ngc"),
    ("freecad_grbl platteyz helix", CORPUS / "freecad_grbl/platteyz-pass-3-helix.nc"),
    ("camotics botomata_bottom", CORPUS / "camotics/botomata_bottom.nc"),
]
PROGRAMS_FULL = PROGRAMS_QUICK + [
    ("linuxcnc stellabee1 (inch, G18)", CORPUS / "linuxcnc/large/stellabee1.ngc")
]

QUIET = Warnings(stream=open(os.devnull, "w"))


# -- models --------------------------------------------------------------------------------------


def without_reversal(machine: Machine) -> Machine:
    """The machine with every direction-dependent table replaced by the mean of its two directions."""
    comps = {}
    for name, comp in machine.components.items():
        if isinstance(comp, Table) and comp.values_minus is not None:
            mean = 0.5 * (np.asarray(comp.values) + np.asarray(comp.values_minus))
            comp = Table(comp.positions, mean, None, comp.interpolation)
        comps[name] = comp
    return machine.replace(components=comps)


def geometric(machine: Machine) -> Machine:
    """Repeatable geometry only: what a compensation model describes (no effects)."""
    return machine.replace(effects=())


def fitted_machine(true: Machine, noise: float = 0.3, seed: int = 7) -> Machine:
    """Fit a model from the laser and level files `true` would give, with `noise` µm / µrad.

    Per axis, 15 targets over the travel, two bidirectional runs: position,
    the two straightnesses, pitch and yaw by laser (optic 120 mm above the
    table), roll by electronic level; the other axes at mid-travel.  The fit
    keeps `true`'s structure (chain, offsets, references) but no errors."""
    from ncpp.identify import fit_machine
    from ncpp.instruments.forward import ANGLE_COMPONENTS, predict_laser, predict_level

    middle = {a: 0.5 * sum(true.limits[a]) for a in "XYZ"}
    files = []
    rng = np.random.default_rng(seed)
    for axis in "XYZ":
        lo, hi = true.limits[axis]
        targets = np.linspace(lo + 5.0, hi - 5.0, 15)
        fixed = {a: v for a, v in middle.items() if a != axis}
        quantities = ["position"] + [f"straightness_{d.lower()}" for d in "XYZ" if d != axis]
        quantities += [q for (a, q) in ANGLE_COMPONENTS if a == axis and q != "roll"]
        for q in quantities:
            files.append(
                predict_laser(
                    true,
                    axis,
                    q,
                    targets,
                    fixed=fixed,
                    offset_mm=(0, 0, 120),
                    runs=2,
                    noise_um=noise,
                    seed=int(rng.integers(1 << 30)),
                )
            )
        files.append(
            predict_level(
                true,
                axis,
                targets,
                quantity="roll",
                fixed=fixed,
                noise_um=noise,
                seed=int(rng.integers(1 << 30)),
            )
        )
    return fit_machine(files, base=true.without_errors(), name=f"{true.name} (fitted)")


@cache
def machine(name: str) -> Machine:
    return load_machine(MACHINES[name])


def source_for(model: Machine, label: str = "model") -> ErrorSource:
    return ErrorSource(model, label, "0" * 16, model.max_correction_mm, dict(model.limits))


# -- programs ------------------------------------------------------------------------------------


def events_of(data: bytes, name: str, offsets: WorkOffsets | None = None) -> list:
    from ncpp.motion import interpret
    from ncpp.program.parser import parse_stream

    return list(interpret(parse_stream(io.BytesIO(data), name), file=name, warnings=QUIET, offsets=offsets))


def placement(path: SampledPath, model: Machine) -> np.ndarray | None:
    """Work offset (mm) that centres the program's bounding box in the travel; None if it does not fit."""
    if len(path.points) == 0:
        return None
    lo_p, hi_p = path.points.min(axis=0), path.points.max(axis=0)
    lo_m = np.array([model.limits[a][0] for a in "XYZ"])
    hi_m = np.array([model.limits[a][1] for a in "XYZ"])
    if np.any(hi_p - lo_p > hi_m - lo_m - 2 * MARGIN_MM):
        return None
    return np.round((lo_m + hi_m) / 2 - (lo_p + hi_p) / 2, 3)


def compensate(
    data: bytes, source: ErrorSource, tolerance: float, name: str, offsets: WorkOffsets
) -> tuple[bytes, int, int, float]:
    """Compensated program text, lines in, lines out, seconds."""
    out = io.BytesIO()
    start = time.perf_counter()
    stats = process(
        io.BytesIO(data), out, file=name, source=source, tolerance=tolerance, warnings=QUIET, offsets=offsets
    )
    return out.getvalue(), stats.lines_in, stats.lines_out, time.perf_counter() - start


def answerable(events: list) -> list:
    """The moves compensation answers for: not those it leaves as programmed, with a warning
    (`fixed`: canned cycles, loops and subroutines, and the moves under cutter compensation,
    which the control offsets by the tool radius), nor, in G91, the moves after a cycle, loop
    or subroutine."""
    from ncpp.motion.segments import COMP

    out = []
    for event in events:
        fixed = event.fixed if type(event) is Line or type(event) is Arc else ""
        if fixed and fixed != COMP and not event.context.absolute:
            break  # (`pipeline.warn_fixed`: from there on the program passes through)
        if not fixed:
            out.append(event)
    return out


@dataclass
class Run:
    """One program on one machine: nominal path (the moves compensation answers for, `answerable`),
    placement, and how many moves it leaves as programmed."""

    label: str
    data: bytes
    offset: np.ndarray
    nominal: SampledPath
    left: int = 0


def with_start_block(data: bytes, name: str) -> bytes:
    """The program with `G0 X0 Y0 Z0` first when it feeds before positioning every axis.

    The interpreter (and so the simulation) starts such an axis at program
    zero, but a control starts it wherever it stands, so the writer never adds
    a word for an axis the program has not positioned: its error could not be
    compensated.  The start block makes the program say what was assumed."""
    seen: set[str] = set()
    for event in events_of(data, name):
        if type(event) is Arc or (type(event) is Line and not event.rapid):
            if seen >= set("XYZ"):
                return data
            break
        seen |= {w.letter for w in event.block.words()} & set("XYZ")
    head, sep, rest = data.partition(b"\n")
    start = b"G0 X0 Y0 Z0 (benchmark: start at program zero)\n"
    return head + sep + start + rest if head.strip().startswith(b"%") else start + data


def prepare(label: str, path: Path, model: Machine) -> Run | None:
    data = with_start_block(path.read_bytes(), str(path))
    at_zero = sample_events(events_of(data, str(path)))
    offset = placement(at_zero, model)
    if offset is None:
        return None
    events = events_of(data, str(path), WorkOffsets.at(offset))
    kept = answerable(events)
    left = sum(1 for e in events if type(e) in (Line, Arc)) - sum(1 for e in kept if type(e) in (Line, Arc))
    return Run(label, data, offset, sample_events(kept), left)


def simulate(run: Run, model: Machine, program: bytes | None = None) -> ContourReport:
    """Contour error of `program` (default: the original) against the nominal path, on `model` (geometry)."""
    commanded = (
        run.nominal
        if program is None
        else sample_events(answerable(events_of(program, run.label, WorkOffsets.at(run.offset))))
    )
    return contour_error(model, commanded, run.nominal, feed_effects=False)


def evaluate(
    run: Run, truth: Machine, compensation_model: Machine, tolerances=TOLERANCES_MM
) -> dict[str, Any]:
    """Before/after figures of one program: compensated with one model, run on another."""
    before = simulate(run, truth)
    source = source_for(compensation_model)
    result: dict[str, Any] = {
        "before_max_um": before.max_um,
        "before_rms_um": before.rms_um,
        "offset_mm": run.offset.tolist(),
        "after": {},
    }
    for tol in tolerances:
        text, lines_in, lines_out, seconds = compensate(
            run.data, source, tol, run.label, WorkOffsets.at(run.offset)
        )
        after = simulate(run, truth, text)
        result["after"][f"{tol * 1000:g}"] = {
            "max_um": after.max_um,
            "rms_um": after.rms_um,
            "worst_line": after.worst_line,
            "factor": before.max_um / max(after.max_um, 1e-9),
            "lines_in": lines_in,
            "lines_out": lines_out,
            "growth": lines_out / max(lines_in, 1),
            "seconds": seconds,
            "within": after.max_um <= tol * 1000 + 0.5,
        }
    return result


# -- the benchmark section -----------------------------------------------------------------------


def cases(true: Machine, quick: bool, fitted: bool) -> list[tuple[str, Machine, Machine]]:
    """(name, machine the program runs on, model it is compensated with)."""
    geometry = geometric(true)
    out = [("exact", geometry, geometry)]
    clean = without_reversal(geometry)
    if clean != geometry:
        out.append(("exact, no reversal", clean, clean))
    if fitted:
        out.append(("fitted (noise 0.3)", geometry, fitted_machine(true)))
    return out


def programs_for(quick: bool, machine_name: str) -> list[tuple[str, Path]]:
    if not quick:
        return PROGRAMS_FULL if machine_name == "hr5b" else PROGRAMS_QUICK
    return [p for p in PROGRAMS_QUICK if "arcspiral" not in p[0] and "botomata" not in p[0]]


def accuracy(ctx):
    import run as bench

    rows, data, notes = [], {}, []
    for name in MACHINES:
        true = machine(name)
        # the fitted case costs a fit; quick runs it on one machine
        for case, truth, model in cases(true, ctx.quick, fitted=not ctx.quick or name == "hr5b"):
            for label, path in programs_for(ctx.quick, name):
                run = prepare(label, path, true)
                key = f"{name} / {case} / {label}"
                if run is None:
                    data[key] = {"skipped": "does not fit in the travel"}
                    if case == "exact":
                        notes.append(f"{label} does not fit in the {name} travel: skipped")
                    continue
                r = data[key] = evaluate(run, truth, model)
                r["moves_left_as_programmed"] = run.left
                left = f"{label}: {run.left} moves left as programmed (cutter compensation, canned cycles, loops) are not in its figures"
                if run.left and left not in notes:
                    notes.append(left)
                after = r["after"]
                rows.append(
                    [
                        name,
                        case,
                        label,
                        f"{r['before_max_um']:.2f} / {r['before_rms_um']:.2f}",
                        " | ".join(f"{a['max_um']:.2f}" for a in after.values()),
                        f"{after['1']['rms_um']:.2f}",
                        f"{after['1']['factor']:.0f}x",
                        " | ".join(f"{a['growth']:.2f}" for a in after.values()),
                        ""
                        if case.startswith("fitted")
                        else (
                            "yes"
                            if all(a["within"] for a in after.values())
                            else "NO: " + ",".join(k for k, a in after.items() if not a["within"])
                        ),
                    ]
                )
    columns = [
        "machine",
        "model",
        "program",
        "before max / rms µm",
        "after max µm @1|2|5",
        "after rms @1",
        "factor @1",
        "out/in @1|2|5",
        "≤ tol+0.5 µm",
    ]
    notes.append(
        "contour error: distance of the simulated tool path (geometry, no effects) from the nominal path, feed moves"
    )
    return bench.Section(
        "Accuracy: contour error before / after compensation (virtual machine)", columns, rows, data, notes
    )


if __name__ == "__main__":
    import run as bench

    sys.exit(bench.main(["--only", "accuracy", *sys.argv[1:]]))
