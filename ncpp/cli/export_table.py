"""`ncpp export-table --machine M.toml --axis X --format F [-o FILE]`: controller tables.

Writes the positioning error of one axis as a controller's own compensation
table: its E<axis><axis> component (with reversal where the table is direction
dependent) plus the machine file's [[effects]] of kind `scale` and `cyclic` on
that axis, either alone where the file gives only one.  Not `backlash` (a
control has its own parameter for it) nor the effects that move other axes.
Formats:

  linuxcnc    COMP_FILE for [JOINT_n] (--type 0: nominal, actual forward,
              actual reverse; --type 1: nominal and the trims), <= 256 entries
  fanuc       pitch error compensation parameter tape (3620-3624, 1851)
  sinumerik   $AA_ENC_COMP leadscrew table, $AN_CEC tables for reversal and
              the axis's straightness components
  heidenhain  nonlinear axis error compensation table (*.COM)

What had to be resampled or clipped to meet the controller's limits is
printed on stderr and written into the file as a comment.
"""

from __future__ import annotations

import argparse
import sys

from ncpp.cli.options import finite, positive


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "export-table",
        help="write an axis's positioning error (EXX ..., scale and cyclic effects) as a controller table",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--machine", required=True, metavar="M.toml", help="machine file")
    parser.add_argument(
        "--axis", required=True, choices=("X", "Y", "Z", "x", "y", "z"), help="axis to tabulate"
    )
    parser.add_argument("--format", required=True, choices=("linuxcnc", "fanuc", "sinumerik", "heidenhain"))
    parser.add_argument("-o", "--output", metavar="FILE", help="output file (default: stdout)")
    parser.add_argument("--spacing", type=positive, metavar="MM", help="distance between table points")
    parser.add_argument(
        "--type", type=int, choices=(0, 1), default=0, help="LinuxCNC COMP_FILE_TYPE (default 0)"
    )
    parser.add_argument(
        "--reference", type=finite, metavar="MM",
        help="reference position: FANUC's zero-correction point (default 0); SINUMERIK shifts its table to 0 there",
    )  # fmt: skip
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    from ncpp.errors import Location, NcppError
    from ncpp.export import export_table
    from ncpp.fileio import write_text_atomic
    from ncpp.machine import load_machine

    machine = load_machine(args.machine)
    try:
        text, notes = export_table(
            machine,
            args.axis.upper(),
            args.format,
            spacing=args.spacing,
            comp_type=args.type,
            reference=args.reference,
        )
    except NcppError as err:  # what the machine file lacks or holds: name it (not <stdin>)
        if err.where != Location():
            raise
        raise NcppError(err.message, Location(args.machine)) from None
    for note in notes:
        print(f"ncpp export-table: {note}", file=sys.stderr)
    if args.output:
        write_text_atomic(args.output, text)
    else:
        sys.stdout.write(text)
    return 0
