"""`ncpp simulate --machine M.toml PROGRAM [--reference ORIGINAL] [--json OUT] [--plot OUT.png]`.

Runs a program's motion on the modelled machine and reports the contour
error against the nominal path: the program itself, or with `--reference`
the original program a compensated one was made from.
"""

from __future__ import annotations

import argparse
import json
import math
from typing import TYPE_CHECKING

from ncpp.cli.compensate import add_placement_arguments, work_offsets
from ncpp.cli.io import add_dialect_argument
from ncpp.cli.options import between
from ncpp.errors import Location, NcppError, Warnings

if TYPE_CHECKING:
    from numpy.typing import NDArray

# Contour errors are microns: finer sampling shows nothing more, and costs memory by the path's length.
MIN_STEP_MM = 0.001


def step_mm(text: str) -> float:
    """--step: a finite number of mm, at least MIN_STEP_MM."""
    try:
        return between(MIN_STEP_MM, math.inf, "[)")(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(
            f"expected a number of mm from {MIN_STEP_MM} on, got {text!r}"
        ) from None


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "simulate", help="run a program on the modelled machine: contour error, ball-bar trace"
    )
    p.add_argument("program", help="NC program to run")
    p.add_argument(
        "--machine",
        metavar="M.toml",
        help="machine file (the virtual machine; default: $NCPP_MACHINE, then ./ncpp.toml "
        "or ~/.config/ncpp/config.toml)",
    )
    p.add_argument("--reference", metavar="ORIGINAL", help="nominal program (for a compensated PROGRAM)")
    add_placement_arguments(p)
    add_dialect_argument(p)
    p.add_argument(
        "--step",
        type=step_mm,
        default=0.5,
        metavar="MM",
        help=f"sample spacing along the path (default 0.5, at least {MIN_STEP_MM})",
    )
    p.add_argument("--json", metavar="OUT", help="write the figures as JSON")
    p.add_argument("--plot", metavar="OUT.png", help="plot the contour error (and circle traces)")
    p.set_defaults(func=run)


def program_events(path: str, warnings: Warnings, offsets=None, dialect: str | None = None) -> list:
    """The events of a program (its dialect detected unless given), placed on the machine by `offsets`;
    under cutter compensation that ncpp follows, the moves where the tool centre runs (`on_centre`)."""
    from ncpp.cli.motion import warn_off_path
    from ncpp.guard import without_guard
    from ncpp.motion.centre_path import on_centre
    from ncpp.pipeline import dialect_tools
    from ncpp.program.dialects import parse_program

    with open(path, "rb") as stream:
        name, blocks = parse_program(stream, path, dialect)
        interpret, _ = dialect_tools(name)
        events = on_centre(interpret(without_guard(blocks), file=path, warnings=warnings, offsets=offsets))
        return list(warn_off_path(events, warnings, path, "simulated as programmed", followed=True))


def run(args: argparse.Namespace) -> int:
    from ncpp.fileio import write_text_atomic
    from ncpp.machine import load_machine
    from ncpp.simulate import contour_error, sample_events

    machine = load_machine(machine_file(args.machine))
    warnings = Warnings()
    offsets = work_offsets(args)
    events = program_events(args.program, warnings, offsets, args.dialect)
    commanded = sample_events(events, args.step, args.program)
    nominal = (
        sample_events(
            program_events(args.reference, warnings, offsets, args.dialect), args.step, args.reference
        )
        if args.reference
        else commanded
    )
    warnings.finish()
    if len(commanded.points) == 0:
        raise NcppError(
            "the program makes no motion the interpreter could follow (a file of subroutines only runs where a program calls it)",
            Location(args.program),
        )
    check_travel(commanded, machine.limits, args.program, events)
    report = contour_error(machine, commanded, nominal)
    print(
        f"contour error: max {report.max_um:.2f} µm (line {report.worst_line}), rms {report.rms_um:.2f} µm over {report.samples} samples"
    )
    for c in report.circles:
        print(
            f"circle R{c['radius_mm']:g} in {c['plane']} at {c['centre_mm']}: circularity {c['circularity_um']:.2f} µm"
        )
    if args.json:
        write_text_atomic(args.json, json.dumps(report.as_dict(), indent=2) + "\n")
    if args.plot:
        plot_report(report, commanded, args.plot)
    return 0


def machine_file(given: str | None) -> str:
    """The machine file: `given`, else the one plain `ncpp` finds (`integrations/config.py`)."""
    from ncpp.integrations.config import find_settings

    settings = find_settings(given)
    if settings.machine is None:
        raise NcppError(
            "no machine file: give --machine M.toml, set $NCPP_MACHINE, "
            "or name one in ./ncpp.toml or ~/.config/ncpp/config.toml"
        )
    return settings.machine


def check_travel(path, limits, file: str, events: list, slack_mm: float = 1e-6) -> None:
    """Refuse a path (`simulate.SampledPath`) that leaves the machine's travel: the machine cannot
    run it, and its error tables end there.  The message names the first sample outside, of
    any axis: its line, and the column of its axis word among the path's `events`."""
    import numpy as np

    lo, hi = (np.array([limits.get(axis, (-math.inf, math.inf))[end] for axis in "XYZ"]) for end in (0, 1))
    outside = (path.points < lo - slack_mm) | (path.points > hi + slack_mm)
    outside &= _positioned(path, events)
    rows = np.flatnonzero(outside.any(axis=1))
    if rows.size:
        k = int(rows[0])
        n = int(np.flatnonzero(outside[k])[0])
        axis = "XYZ"[n]
        error = NcppError(f"the motion reaches {axis}{path.points[k, n]:.4f} mm, outside the {axis} travel [{lo[n]:g}, {hi[n]:g}] mm "
                          "(place the program with --work-offset or --var-file)", Location(file, int(path.line[k]), word=axis))  # fmt: skip
        error.locate(e.block for e in events)
        raise error


def _positioned(path, events: list) -> NDArray:
    """(n,3) whether each sample's axis stands where the program put it: the path starts at the
    interpreter's zero, but the control starts wherever the axes are, so an axis is known from the
    end of the first move whose block names it on (a travel that does not hold zero is no error)."""
    import numpy as np

    known = np.zeros(path.points.shape, dtype=bool)
    moves = [e for e in events if type(e).__name__ in ("Line", "Arc")]
    for n, axis in enumerate("XYZ"):
        line = next((e.block.line for e in moves if any(w.letter == axis for w in e.block.words())), None)
        rows = np.flatnonzero(path.line == line)
        if rows.size:
            run = np.flatnonzero(np.diff(rows) != 1)  # (the first run of the block's samples)
            known[rows[int(run[0]) if run.size else -1] :, n] = True
    return known


def plot_report(report, commanded, path: str) -> None:
    """The contour error along the program (feed moves, by distance along them), a map of the
    path coloured by it in the plane it spans most, and each full circle's trace."""
    import io

    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from ncpp.fileio import write_bytes_atomic

    fig = contour_figure(report, plt)
    buffer = io.BytesIO()
    fig.savefig(buffer, format="png", dpi=100)
    plt.close(fig)
    write_bytes_atomic(path, buffer.getvalue())


def contour_figure(report, plt):
    """The figure `plot_report` draws (pyplot passed in, its backend chosen)."""
    import numpy as np

    panels = 2 + len(report.circles)
    fig = plt.figure(figsize=(6 * panels, 5))
    along = fig.add_subplot(1, panels, 1)
    steps = np.linalg.norm(np.diff(report.path_mm, axis=0), axis=1)
    distance = np.concatenate([[0.0], np.cumsum(steps)])
    along.plot(distance, report.error_um, lw=0.8)
    worst = f"max {report.max_um:.2f} µm (line {report.worst_line})"
    along.set_title(f"contour error: {worst}, rms {report.rms_um:.2f} µm")
    along.set_xlabel("distance along the feed moves / mm")
    along.set_ylabel("contour error / µm")
    first, second = _widest_axes(report.path_mm)
    plan = fig.add_subplot(1, panels, 2)
    x, y = report.path_mm[:, first], report.path_mm[:, second]
    dots = plan.scatter(x, y, c=report.error_um, s=4, cmap="viridis")
    fig.colorbar(dots, ax=plan, label="contour error / µm")
    plan.set_aspect("equal", adjustable="datalim")
    plan.set_xlabel(f"{'XYZ'[first]} (machine) / mm")
    plan.set_ylabel(f"{'XYZ'[second]} (machine) / mm")
    plan.set_title("the path, coloured by contour error")
    for n, c in enumerate(report.circles, start=3):
        angle, dr = c["trace"]
        order = np.argsort(angle)
        polar = fig.add_subplot(1, panels, n, projection="polar")
        polar.plot(np.radians(angle[order]), dr[order], lw=1)
        polar.set_title(f"R{c['radius_mm']:g} {c['plane']}: circularity {c['circularity_um']:.2f} µm")
    fig.tight_layout()
    return fig


def _widest_axes(points) -> tuple[int, int]:
    """The two axes (indices, in XYZ order) the path spans most: the plane to draw it in."""
    import numpy as np

    spans = np.ptp(points, axis=0) if len(points) else np.zeros(3)
    first, second = sorted(np.argsort(spans)[-2:].tolist())
    return first, second
