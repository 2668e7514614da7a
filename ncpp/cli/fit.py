"""`ncpp fit FILES... -o M.toml`: a machine file from laser, comparator, level and ball-bar files.

Each file gives one error component as a table over its axis (a comparator
two: linear and transverse): laser position on X → EXX, straightness_y on X →
EYX, pitch/yaw/roll → the axis's angular component (or the file's
`component:`), level roll/pitch likewise.  The Abbe contribution of each
file's optic offset is removed with the angular components the other files
give (see ncpp.identify.fit).  Per-direction tables are written where the
reversal is significant (--reversal-threshold, µm).

The chain, offsets, reference points, limits, squareness and effects come
from --base M0.toml; without it from --chain (default XYFZ) with zero
offsets.  Components no file gives keep the base's values.

    ncpp fit laser_*.csv level_*.csv --chain XZFY -o fitted.toml

Ball-bar files (several planes, radii, heights, both directions, alone or
with the others) are fitted by regularised least squares (ncpp.identify.
ballbar): each component of the axes the circles move as a table of --knots
values over the tested range with a second-difference penalty (weight by
generalized cross-validation, or --smoothing), the squarenesses, and per file
the bar's length and centre offsets (set-up, not reported).  Components the
other files give are held.  The account lists every value ± its standard
uncertainty and the combinations the files cannot separate (left at the
minimum-norm choice, not invented):

    ncpp fit bb_*.csv --base structure.toml -o fitted.toml

[meta.fitted] names each file by its path relative to the machine file, or,
where that climbs more than two folders up, by its name and sha256: the file
means the same on another computer.
"""

from __future__ import annotations

import argparse

from ncpp.cli.options import at_least, non_negative, positive


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "fit",
        help="build a machine file from laser / comparator / level / ball-bar files",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "files", nargs="+", metavar="FILE", help="laser, comparator, level and ball-bar files"
    )
    parser.add_argument("-o", "--output", required=True, metavar="M.toml")
    parser.add_argument(
        "--chain", help="kinematic chain, workpiece to tool (e.g. XZFY; default XYFZ or the base's)"
    )
    parser.add_argument(
        "--base", metavar="M0.toml", help="machine file whose structure and other errors are kept"
    )
    parser.add_argument("--name", help="machine name")
    parser.add_argument("--interpolation", default="smooth", choices=("smooth", "linear"))
    parser.add_argument(
        "--reversal-threshold",
        type=non_negative,
        default=0.5,
        metavar="UM",
        help="per-direction tables above this reversal (default 0.5 µm)",
    )
    parser.add_argument(
        "--knots", type=at_least(2), default=9, help="ball bar: values per fitted table (default 9)"
    )
    parser.add_argument(
        "--smoothing", type=positive, metavar="LAMBDA", help="ball bar: penalty weight (default: by GCV)"
    )
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ncpp.errors import Location, NcppError
    from ncpp.fileio import portable_name
    from ncpp.identify import account, fit_residuals, identify
    from ncpp.instruments.files import read_measurement
    from ncpp.machine import load_machine, save_machine

    measurements = [read_measurement(p) for p in args.files]
    base = load_machine(args.base) if args.base else None
    try:
        machine, ballbar = identify(
            measurements, base=base, chain=args.chain, name=args.name, interpolation=args.interpolation,
            reversal_threshold=args.reversal_threshold, knots=args.knots, smoothing=args.smoothing,
            names={p: portable_name(p, args.output) for p in args.files},
        )  # fmt: skip
    except ValueError as err:
        raise NcppError(str(err), Location("ncpp fit")) from None
    save_machine(machine, args.output)
    residuals = fit_residuals(machine, measurements)
    print(
        f"{args.output}: {machine.name}, chain {machine.chain}, {len(machine.meta.get('fitted', {}))} component(s) fitted"
    )
    for name, source in machine.meta.get("fitted", {}).items():
        if name not in residuals:
            continue
        table = machine.component(name)
        kind = "± tables" if getattr(table, "directional", False) else "table"
        print(f"  {name:<4} {kind:<9} from {source}  (max residual {residuals[name]:.3g})")
    if ballbar is not None:
        print(account(ballbar))
    return 0
