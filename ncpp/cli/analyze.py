"""`ncpp analyze FILE... [--json OUT] [--plot OUT.png]`: the standard evaluation.

The instrument comes from each file's metadata: laser position and comparator
files are evaluated to ISO 230-2, straightness and angle files to ISO 230-1,
level files as a profile, ball-bar, cutting and circular grid files to
ISO 230-4 with the ball-bar diagnosis (see ncpp.instruments.analysis).

`--json OUT` writes the figures under their standard symbols (µm unless the
name says otherwise; null where a file cannot give a figure).  One file gives
one object; several files give a list of objects in the order given.  Each
object also holds `file`, `instrument` and `standard`.

`--plot OUT.png` draws one panel per file into one PNG.
"""

from __future__ import annotations

import argparse

from ncpp.cli.options import between


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "analyze",
        help="evaluate measurement files (ISO 230-2, ISO 230-4, ball-bar diagnosis)",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument(
        "files",
        nargs="+",
        metavar="FILE",
        help="measurement files (laser, comparator, level, ballbar, grid, cutting)",
    )
    parser.add_argument("--json", metavar="OUT", help="write the figures as JSON")
    parser.add_argument("--plot", metavar="OUT.png", help="draw the standard plots into a PNG")
    parser.add_argument(
        "--spike-width", type=spike_width, default=3.0, metavar="DEG",
        help="decay angle of the reversal-spike shape in the ball-bar diagnosis (default 3 deg; "
        "the spike must die out before the axis reverses again)",
    )  # fmt: skip
    parser.set_defaults(func=run)


def spike_width(text: str) -> float:
    from ncpp.instruments.iso230_4 import MAX_SPIKE_WIDTH_DEG  # (numpy: only when the option is given)

    return between(0.0, MAX_SPIKE_WIDTH_DEG, "(]")(text)


def run(args: argparse.Namespace) -> int:
    import json

    from ncpp.fileio import portable_name, write_text_atomic
    from ncpp.instruments.analysis import analyze, format_report
    from ncpp.instruments.files import read_measurement

    analyses = [analyze(read_measurement(path), args.spike_width) for path in args.files]
    print("\n\n".join(format_report(a) for a in analyses))
    if args.json:
        records = [
            {
                "file": portable_name(a.measurement.source, args.json),
                "instrument": a.measurement.instrument,
                "standard": a.standard,
                **a.figures,
            }  # fmt: skip
            for a in analyses
        ]
        payload = records[0] if len(records) == 1 else records
        write_text_atomic(args.json, json.dumps(payload, indent=2, ensure_ascii=False) + "\n")
    if args.plot:
        from ncpp.instruments.plots import plot_analyses

        plot_analyses(analyses, args.plot)
    return 0
