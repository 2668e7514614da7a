# ncpp post processor for the FreeCAD Path / CAM workbench.
#
# Install: copy this file into FreeCAD's macro directory (Edit > Preferences >
# General > Macro > "Macro path", e.g. ~/.local/share/FreeCAD/Macro or
# ~/.FreeCAD/Macro); choose the post processor "ncpp" in the Job.
#
# It posts through FreeCAD's own LinuxCNC post (linuxcnc_post) and runs the
# result through ncpp's compensation (the `ncpp` command of your ncpp install,
# run as a separate program: FreeCAD's embedded Python need not have ncpp).
# Arguments (the Job's "Post Processor Args"):
#   --machine M.toml      machine file (default: $NCPP_MACHINE, then the ncpp
#                         config files ./ncpp.toml, ~/.config/ncpp/config.toml)
#   --from FILE           compensate from one measurement file instead
#   --tolerance MM        allowed path deviation (default 0.001 or the config's)
#   --work-offset [G5x=]X,Y,Z  machine position of a fixture's zero (G54 without
#                         G5x=; repeat it for the Job's other fixtures G55...)
#   --var-file FILE       LinuxCNC parameter file holding the zeros (--var-units inch)
#   --tool-table FILE     LinuxCNC tool table: the lengths the program's G43 applies
#   --no-guard            leave out the placement guard (the program's check that
#                         the control's G54 is the one given with --work-offset)
#   --ncpp PATH           the ncpp program (default: $NCPP, then `ncpp` on PATH)
# Any other argument goes to linuxcnc_post (e.g. --no-comments, --precision 4).
#
# ncpp's summary goes to FreeCAD's Report view as a message, its warnings as
# warnings and a failure as an error, each naming the line of the program
# linuxcnc_post made (with its text).
#
# FreeCAD 0.20/0.21 call the module function export(); FreeCAD 1.x looks for
# the class named after the file (`Ncpp`) and calls its export().

import argparse
import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

TOOLTIP = """Posts through FreeCAD's LinuxCNC post, then compensates the program
for the machine's geometric errors with ncpp (header names the machine file)."""

parser = argparse.ArgumentParser(prog="ncpp", add_help=False)
parser.add_argument("--machine", help="machine file (default: $NCPP_MACHINE or the ncpp config)")
parser.add_argument("--from", dest="from_file", help="compensate from one measurement file")
parser.add_argument("--tolerance", help="allowed path deviation in mm")
parser.add_argument("--work-offset", action="append", default=[], help="[G5x=]X,Y,Z machine position of a fixture's zero, mm (repeat)")
parser.add_argument("--var-file", help="LinuxCNC parameter file holding the zeros")
parser.add_argument("--tool-table", help="LinuxCNC tool table: the lengths the program's G43 applies")
parser.add_argument("--var-units", help="units of --var-file and --tool-table: mm or inch")
parser.add_argument("--no-guard", action="store_true", help="no placement guard at the program's start")
parser.add_argument("--ncpp", help="the ncpp program (default: $NCPP, then ncpp on PATH)")

TOOLTIP_ARGS = parser.format_help() + "\nOther arguments are passed to linuxcnc_post.\n"


def _linuxcnc_post():
    """A fresh copy of FreeCAD's linuxcnc_post.  It keeps its options in module
    globals that only its flags change (--no-comments, --inches, ... stay set
    for the rest of the session), so each post starts from a new module."""
    try:  # FreeCAD 1.x
        from Path.Post.scripts import linuxcnc_post
    except ImportError:  # FreeCAD 0.19-0.21 (Path is only the C++ module)
        from PathScripts.post import linuxcnc_post
    spec = importlib.util.spec_from_file_location(linuxcnc_post.__name__, linuxcnc_post.__file__)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _ncpp_command(options):
    found = options.ncpp or os.environ.get("NCPP") or shutil.which("ncpp")
    if not found:
        raise RuntimeError("ncpp_post: the ncpp program was not found; give --ncpp PATH or set NCPP")
    return shlex.split(found) if " " in found and not os.path.exists(found) else [found]


def _ncpp_arguments(options):
    args = []
    for flag, value in (("--machine", options.machine), ("--from", options.from_file), ("--tolerance", options.tolerance),
                        ("--var-file", options.var_file), ("--tool-table", options.tool_table), ("--var-units", options.var_units)):  # fmt: skip
        if value:
            args += [flag, value]
    for zero in options.work_offset:
        args += ["--work-offset", zero]
    if options.no_guard:
        args.append("--no-guard")
    return args


def compensate_text(gcode, argstring):
    """The LinuxCNC program `gcode` compensated by the ncpp command (the plain
    filter: machine file from the arguments, $NCPP_MACHINE or the config)."""
    options, _ = parser.parse_known_args(shlex.split(argstring or ""))
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONHOME",)}  # FreeCAD's, not ncpp's
    proc = subprocess.run(
        _ncpp_command(options) + _ncpp_arguments(options),
        input=gcode.encode("latin-1", errors="replace"),
        capture_output=True,
        env=env,
    )
    told = [_posted_line(line, gcode) for line in proc.stderr.decode("utf-8", errors="replace").splitlines()]
    if proc.returncode != 0:
        _report("PrintError", "ncpp_post: ncpp failed:\n" + "\n".join(told))
        raise RuntimeError("ncpp_post: ncpp failed:\n" + "\n".join(told))
    for line in told:
        _report("PrintWarning" if ": warning: " in line else "PrintMessage", line)
    return proc.stdout.decode("latin-1")


_STDIN_PLACE = re.compile(r"^<stdin>:(\d+)(?::\d+)?: ")


def _posted_line(message, gcode):
    """ncpp's `<stdin>:LINE:COL: ...` as the line of the posted program, with its text."""
    found = _STDIN_PLACE.match(message)
    if not found:
        return message
    number = int(found.group(1))
    lines = gcode.splitlines()
    text = lines[number - 1].strip() if 0 < number <= len(lines) else ""
    return f"ncpp_post: line {number} of the posted program ({text}): " + message[found.end():]


def _report(kind, text):
    """A line in FreeCAD's Report view (`FreeCAD.Console.PrintWarning`, ...); stderr outside FreeCAD."""
    try:
        import FreeCAD
    except ImportError:
        print(text, file=sys.stderr)
        return
    getattr(FreeCAD.Console, kind)(text + "\n")


def linuxcnc_text(objectslist, argstring):
    """What FreeCAD's LinuxCNC post makes of the objects, with ncpp's own arguments removed."""
    _, rest = parser.parse_known_args(shlex.split(argstring or ""))
    post = _linuxcnc_post()
    with tempfile.TemporaryDirectory(prefix="ncpp_post") as folder:
        raw = os.path.join(folder, "linuxcnc.ngc")
        result = post.export(objectslist, raw, " ".join(shlex.quote(a) for a in rest + ["--no-show-editor"]))
        if os.path.exists(raw):
            with open(raw, encoding="latin-1") as f:
                return f.read()
        return result or ""


def export(objectslist, filename, argstring):
    """Legacy entry point (FreeCAD 0.19-0.21): post, compensate, write `filename`."""
    gcode = compensate_text(linuxcnc_text(objectslist, argstring), argstring)
    if filename != "-":
        with open(filename, "w", encoding="latin-1", newline="") as f:
            f.write(gcode)
    return gcode


try:  # FreeCAD 1.x: class-based post processors; absent on 0.20, where this file still loads.
    from Path.Post.Processor import PostProcessor as _PostProcessor
except ImportError:
    _PostProcessor = None

if _PostProcessor is not None:

    class Ncpp(_PostProcessor):
        """`ncpp` for FreeCAD 1.x: each output section posted by linuxcnc_post, then compensated."""

        def __init__(self, job):
            super().__init__(job, tooltip=TOOLTIP, tooltipargs=TOOLTIP_ARGS, units=None)  # the units property

        @property
        def tooltip(self):
            return TOOLTIP

        @property
        def tooltipArgs(self):
            return TOOLTIP_ARGS

        @property
        def units(self):
            """What linuxcnc_post writes: G20 (Inch) for --inches, else G21 (Metric)."""
            return "Inch" if "--inches" in shlex.split(self._argstring()) else "Metric"

        def _argstring(self):
            return getattr(self._job, "PostProcessorArgs", "") or ""  # no job in the Preferences dialog

        def export(self):
            argstring = self._argstring()
            return [(name, compensate_text(linuxcnc_text(objects, argstring), argstring)) for name, objects in self._buildPostList()]
