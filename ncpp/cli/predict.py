"""`ncpp predict`: what an instrument would read, as a measurement file.

From a machine file:

    ncpp predict --machine m.toml --instrument ballbar --plane XY --radius 150 \\
        --center 400,350,350 --feed 1000 -o bb.csv --plot bb.png
    ncpp predict --machine m.toml --instrument laser --axis X --quantity position \\
        --targets 0:800:50 --runs 5 --fixed "Y=350 Z=350" --offset 0,0,120 -o x.csv

From measurements (M. Rahman, *Modeling and measurement of multi-axis machine tools
to improve positioning accuracy in a software way*, University of Oulu, 2004, section
4.8.4: laser → ball bar, laser → comparator, comparator → ball bar): the files are
first fitted into a machine (as `ncpp fit` does, chain and offsets from --chain /
--base), then the wanted instrument is predicted from it:

    ncpp predict --from laser_*.csv level_*.csv --chain XZFY --instrument ballbar ... -o bb.csv

Instruments and their set-up options: laser (--axis --quantity --targets
--runs --unidirectional --fixed --offset --feed), comparator (--axis
--transverse --targets ...), level (--axis --quantity roll|pitch --targets
--member --fixed), ballbar (--plane --radius --center --feed --direction
--start --overshoot --step --offset), grid (--path circle|square --plane
--radius (half side of a square) --center --direction --step), cutting
(--plane --radius --center --feed --direction).  --noise adds normal noise
(µm, µrad or µm/m) with --seed.  --no-effects leaves out the machine's
non-geometric effects (a static, "cold" prediction).
"""

from __future__ import annotations

import argparse
import math

from ncpp.cli.options import at_least, between, finite, non_negative, positive

INSTRUMENTS = ("ballbar", "laser", "comparator", "level", "grid", "cutting")


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "predict",
        help="predict an instrument's reading from a machine file or from other measurements",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    source = parser.add_mutually_exclusive_group(required=True)
    source.add_argument("--machine", metavar="M.toml", help="machine file")
    source.add_argument(
        "--from",
        dest="sources",
        nargs="+",
        metavar="FILE",
        help="laser / comparator / level / ball-bar files to fit first (ncpp fit)",
    )
    parser.add_argument("--chain", help="chain for --from when there is no --base (default XYFZ)")
    parser.add_argument("--base", metavar="M0.toml", help="machine whose structure --from keeps")
    parser.add_argument("--save-machine", metavar="M.toml", help="with --from: also write the fitted machine")
    parser.add_argument("--instrument", required=True, choices=INSTRUMENTS)
    parser.add_argument("-o", "--output", required=True, metavar="OUT.csv")
    parser.add_argument("--plot", metavar="OUT.png", help="draw the standard plot of the prediction")
    g = parser.add_argument_group("set-up")
    g.add_argument("--plane", default="XY", type=str.upper, choices=("XY", "YZ", "ZX"))
    g.add_argument("--radius", type=radius_mm, help="mm (default ballbar 150, grid 100, cutting 50)")
    g.add_argument("--center", metavar="X,Y,Z", help="centre, command mm (default: middle of the travel)")
    g.add_argument("--feed", type=positive, help="mm/min (default 1000; cutting 500)")
    g.add_argument(
        "--direction",
        type=str.upper,
        choices=("CW", "CCW", "BOTH"),
        help="circular tests (ballbar default BOTH)",
    )
    g.add_argument("--start", type=finite, default=0.0, metavar="DEG", help="start angle of the data arc")
    g.add_argument(
        "--overshoot",
        type=between(0.0, 360.0),
        default=45.0,
        metavar="DEG",
        help="feed-in/feed-out arc, 0 to 360 (default 45)",
    )
    g.add_argument(
        "--step",
        type=positive,
        metavar="STEP",
        help="deg between circle points, at most 120 (ballbar 1, grid 2, cutting probes 2); mm for a square",
    )
    g.add_argument("--path", default="circle", choices=("circle", "square"), help="grid encoder path")
    g.add_argument("--axis", type=str.upper, default="X", choices=("X", "Y", "Z"))
    g.add_argument(
        "--quantity",
        default=None,
        help="laser: position|straightness_x|_y|_z|pitch|yaw|roll; level: roll|pitch",
    )
    g.add_argument("--component", help="laser angles: the ISO component the optics read (e.g. EBX)")
    g.add_argument(
        "--transverse", type=str.upper, choices=("X", "Y", "Z"), help="comparator transverse direction"
    )
    g.add_argument("--member", help="level: member it sits on (axis letter, work, tool)")
    g.add_argument(
        "--offset", default="0,0,0", metavar="x,y,z", help="functional point from the tool point, mm"
    )
    g.add_argument(
        "--fixed",
        default="",
        metavar='"Y=0 Z=0"',
        help="positions of the axes held still (default: middle of travel or 0)",
    )
    g.add_argument(
        "--targets",
        metavar="A:B:STEP | a,b,c",
        help="laser/comparator targets, level positions (default: the travel in 20 steps)",
    )
    g.add_argument("--runs", type=at_least(1), default=5, help="laser/comparator runs (default 5)")
    g.add_argument("--unidirectional", action="store_true", help="laser/comparator: + approach only")
    g.add_argument(
        "--noise", type=non_negative, default=0.0, help="standard deviation of added noise (file unit)"
    )
    g.add_argument("--seed", type=int, default=None)
    g.add_argument("--no-effects", action="store_true", help="leave out the non-geometric effects")
    g.add_argument(
        "--no-zero", action="store_true", help="laser/comparator: absolute readings, not zeroed at the first"
    )
    parser.set_defaults(func=run)


def radius_mm(text: str) -> float:
    from ncpp.machine.effects import LARGEST_LENGTH_MM  # (numpy: only when the option is given)

    return between(0.0, LARGEST_LENGTH_MM, "(]")(text)


def _vector(text: str, what: str):
    import numpy as np

    from ncpp.errors import Location, NcppError
    from ncpp.instruments.forward import check_extent

    try:
        values = [float(v) for v in text.replace(" ", ",").split(",") if v]
    except ValueError:
        raise NcppError(f"{what}: {text!r} is not x,y,z numbers", Location("ncpp predict")) from None
    if len(values) != 3:
        raise NcppError(f"{what} needs three numbers x,y,z, got {text!r}", Location("ncpp predict"))
    try:
        check_extent(values, what)
    except ValueError as err:
        raise NcppError(str(err), Location("ncpp predict")) from None
    return np.array(values)


def parse_targets(text: str):
    """`0:1000:50` (inclusive) or `0,100,250` → array of positions."""
    import numpy as np

    from ncpp.errors import Location, NcppError
    from ncpp.instruments.forward import MAX_READINGS
    from ncpp.machine.effects import LARGEST_LENGTH_MM

    where = Location("ncpp predict")
    try:
        if ":" in text:
            a, b, step = (float(v) for v in text.split(":"))
            if not (
                abs(a) <= LARGEST_LENGTH_MM and abs(b) <= LARGEST_LENGTH_MM and 0 < step < math.inf and a <= b
            ):
                raise ValueError
            count = math.floor((b - a) / step + 1e-9) + 1
            if count > MAX_READINGS:  # before the array is made
                raise NcppError(f"--targets {text}: {count:,} targets; at most {MAX_READINGS:,}", where)
            targets = a + step * np.arange(count)
        else:
            targets = np.array(sorted(float(v) for v in text.split(",") if v.strip()))
            if not np.all(np.abs(targets) <= LARGEST_LENGTH_MM):
                raise ValueError
    except ValueError:
        raise NcppError(
            f"--targets: expected A:B:STEP (A <= B, STEP > 0) or a,b,c, within ±{LARGEST_LENGTH_MM:g} mm, got {text!r}",
            where,
        ) from None
    if np.any(np.diff(np.unique(targets)) < 1e-3):  # ISO 230-2 matches targets to 1 µm
        raise NcppError(f"--targets {text}: targets closer than 1 µm are one target", where)
    return targets


def _middle(machine, axis: str) -> float:
    lo, hi = machine.limits[axis]
    return 0.5 * (lo + hi) if math.isfinite(lo) and math.isfinite(hi) else 0.0


def setup_from_args(args: argparse.Namespace, machine) -> dict[str, object]:
    """Keyword arguments of the predict_<instrument> function from the command line."""
    import numpy as np

    from ncpp.errors import Location, NcppError
    from ncpp.instruments.forward import parse_fixed

    inst = args.instrument
    offset = _vector(args.offset, "--offset")
    centre = (
        _vector(args.center, "--center") if args.center else np.array([_middle(machine, a) for a in "XYZ"])
    )
    try:
        fixed = parse_fixed(args.fixed)
    except ValueError as err:
        raise NcppError(f"--fixed: {err}", Location("ncpp predict")) from None
    noise = {"noise_um": args.noise, "seed": args.seed}
    if inst in ("laser", "comparator", "level"):
        axis = args.axis
        fixed = {a: fixed.get(a, _middle(machine, a)) for a in "XYZ" if a != axis}
        if args.targets:
            targets = parse_targets(args.targets)
        else:
            lo, hi = machine.limits[axis]
            if not (math.isfinite(lo) and math.isfinite(hi)):
                raise NcppError(
                    f"--targets is needed: the machine file gives no travel for {axis}",
                    Location("ncpp predict"),
                )
            targets = np.linspace(lo, hi, 21)
        if inst == "level":
            return {
                "axis": axis,
                "positions": targets,
                "quantity": args.quantity or "roll",
                "member": args.member,
                "fixed": fixed,
                **noise,
            }
        cycle = {
            "axis": axis, "targets": targets, "fixed": fixed, "offset_mm": offset, "runs": args.runs,
            "bidirectional": not args.unidirectional, "feed_mm_min": args.feed or 1000.0,
            "zero": not args.no_zero, "effects": not args.no_effects, **noise,
        }  # fmt: skip
        if inst == "laser":
            return {**cycle, "quantity": args.quantity or "position", "component": args.component}
        return {**cycle, "transverse": args.transverse}
    directions = {"BOTH": ("CCW", "CW"), "CW": ("CW",), "CCW": ("CCW",)}
    common = {
        "plane": args.plane,
        "center_mm": centre,
        "offset_mm": offset,
        "effects": not args.no_effects,
        **noise,
    }
    if inst == "ballbar":
        return {
            **common, "radius_mm": args.radius or 150.0, "feed_mm_min": args.feed or 1000.0,
            "directions": directions[args.direction or "BOTH"], "start_deg": args.start,
            "overshoot_deg": args.overshoot, "step_deg": _circle_step(args, 1.0),
        }  # fmt: skip
    if inst == "grid":
        step = (
            {"step_mm": args.step or 5.0} if args.path == "square" else {"step_deg": _circle_step(args, 2.0)}
        )
        return {
            **common, "path": args.path, "radius_mm": args.radius or 100.0, "feed_mm_min": args.feed or 1000.0,
            "directions": directions[args.direction or "CCW"], "start_deg": args.start, "overshoot_deg": args.overshoot, **step,
        }  # fmt: skip
    if args.direction == "BOTH":
        raise NcppError("a cutting test cuts one direction: --direction CW or CCW", Location("ncpp predict"))
    return {
        **common, "radius_mm": args.radius or 50.0, "feed_mm_min": args.feed or 500.0,
        "direction": args.direction or "CCW", "probe_step_deg": _circle_step(args, 2.0),
    }  # fmt: skip


def _circle_step(args: argparse.Namespace, default: float) -> float:
    """--step of a circular test (deg), or its default."""
    from ncpp.errors import Location, NcppError
    from ncpp.instruments.forward import MAX_CIRCLE_STEP_DEG

    step = args.step or default
    if step > MAX_CIRCLE_STEP_DEG:
        raise NcppError(
            f"--step {step:g}: a circular test needs three points a revolution (step <= {MAX_CIRCLE_STEP_DEG:g} deg)",
            Location("ncpp predict"),
        )
    return step


def machine_from_args(args: argparse.Namespace):
    """The machine: the --machine file, or the --from files fitted (on --base / --chain)."""
    from ncpp.machine import load_machine

    if args.machine:
        return load_machine(args.machine)
    from ncpp.errors import Location, NcppError
    from ncpp.fileio import portable_name
    from ncpp.identify import fit_machine
    from ncpp.instruments.files import read_measurement

    base = load_machine(args.base) if args.base else None
    measurements = [read_measurement(p) for p in args.sources]
    try:
        names = {p: portable_name(p, args.save_machine) for p in args.sources} if args.save_machine else None
        return fit_machine(measurements, base=base, chain=args.chain, names=names)
    except ValueError as err:  # as `ncpp fit` reports it (a bad --chain)
        raise NcppError(str(err), Location("ncpp predict")) from None


def run(args: argparse.Namespace) -> int:
    from ncpp.errors import Location, NcppError
    from ncpp.instruments.files import read_measurement, write_measurement
    from ncpp.instruments.forward import predict

    machine = machine_from_args(args)
    if args.save_machine:
        if not args.sources:
            raise NcppError("--save-machine goes with --from", Location("ncpp predict"))
        from ncpp.machine import save_machine

        save_machine(machine, args.save_machine)
    try:
        measurement = predict(machine, args.instrument, **setup_from_args(args, machine))
    except ValueError as err:
        raise NcppError(str(err), Location("ncpp predict")) from None
    write_measurement(measurement, args.output)
    if args.plot:
        from ncpp.instruments.analysis import analyze
        from ncpp.instruments.plots import plot_analyses

        plot_analyses([analyze(read_measurement(args.output))], args.plot)
    return 0
