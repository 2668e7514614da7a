"""`ncpp diagnose --machine MODEL.toml MEASURED... [--json REPORT] [--plot GAP.png] [-o UPDATED.toml]`

Simulates every measurement file (ball bar, laser, comparator) from the
model with the file's own set-up, says where measurement and simulation
disagree, then adds, one at a time, the missing effect of the effect table
(scale/thermal growth, backlash, lateral play, reversal spike, servo
mismatch, squareness, straightness, cyclic, angular) that explains most of the
gap, as long as it is statistically significant against the noise level.
Set-up offsets (ball-bar centre and length, laser zero per run) are always
fitted and never reported.  Candidates the data cannot tell apart are
reported as ambiguous.

--json writes the report of shared/spec/measurement-files.md; -o writes the
model with the new effects in [[effects]] (both name their input files relative
to themselves, or by name and sha256 when far off); --plot draws the gap per step and
the residual traces before and after.
"""

from __future__ import annotations

import argparse

from ncpp.cli.options import between


def register(subparsers: argparse._SubParsersAction) -> None:
    parser = subparsers.add_parser(
        "diagnose",
        help="name, fit and add the effect the model lacks to match measurements",
        description=__doc__,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    parser.add_argument("--machine", required=True, metavar="MODEL.toml", help="the machine model to check")
    parser.add_argument("files", nargs="+", metavar="MEASURED", help="ballbar, laser and comparator files")
    parser.add_argument("--json", metavar="REPORT", help="write the diagnosis report (JSON)")
    parser.add_argument("--plot", metavar="GAP.png", help="plot the gap per step and the residuals")
    parser.add_argument("-o", "--output", metavar="UPDATED.toml", help="write the model with the new effects")
    parser.add_argument("--alpha", type=between(0.0, 1.0, "()"), default=1e-3,
                        help="family-wise false-alarm probability of adding an effect (default 1e-3)")  # fmt: skip
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    import json

    from ncpp.diagnose import diagnose
    from ncpp.diagnose.report import account, plot_gap
    from ncpp.fileio import portable_name, rebased_name, write_text_atomic
    from ncpp.instruments.files import read_measurement
    from ncpp.machine import load_machine, save_machine

    machine = load_machine(args.machine)
    measurements = [read_measurement(p) for p in args.files]
    result = diagnose(machine, measurements, alpha=args.alpha)
    print(account(result))
    if args.output:
        sources = ", ".join(portable_name(p, args.output) for p in args.files)
        meta = {**result.base.meta, "diagnosed_from": sources}
        fitted = meta.get("fitted")
        if isinstance(fitted, dict):  # named relative to the model read, renamed for the one written
            meta["fitted"] = {k: rebased_name(str(v), args.machine, args.output) for k, v in fitted.items()}
        save_machine(result.updated.replace(meta=meta), args.output)
    print(_model_written(args.output, None))
    if args.json:
        model = _model_written(args.output, args.json)
        write_text_atomic(args.json, json.dumps(result.report(model), indent=2, ensure_ascii=False) + "\n")
    if args.plot:
        plot_gap(result, args.plot)
    return 0


def _model_written(output: str | None, report: str | None) -> str:
    """What became of the updated model, naming it as seen from `report` (None: as given)."""
    from ncpp.fileio import portable_name

    if not output:
        return "no updated machine file written (no -o)"
    return f"updated machine file written to {portable_name(output, report) if report else output}"
