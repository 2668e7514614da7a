# ncpp post processor for the FreeCAD Path / CAM workbench.
#
# Install: copy this file into FreeCAD's macro directory (Edit > Preferences >
# General > Macro > "Macro path", e.g. ~/.local/share/FreeCAD/Macro or
# ~/.FreeCAD/Macro); choose the post processor "ncpp" in the Job.
#
# It posts through one of FreeCAD's own posts (linuxcnc_post, or --base NAME) and
# runs the result through ncpp's compensation (the `ncpp` command of your ncpp install,
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
#   --base NAME           FreeCAD's post to wrap: linuxcnc (default), grbl, fanuc,
#                         mach3_mach4 or centroid
#   --no-guard            leave out the placement guard (the program's check that
#                         the control's G54 is the one given with --work-offset)
# Any other argument goes to that post (e.g. --no-comments, --precision 4).
# `ncpp install-freecad-post` copies this file into the macro directory.
#
# The ncpp program is found from the user's side only, never from the Job's arguments
# (they are saved in the .FCStd, and a shared document must not choose a program to run):
# $NCPP, else the FreeCAD parameter BaseApp/Preferences/Mod/ncpp "Program" (Tools >
# Edit parameters), else `ncpp` on PATH.
#
# ncpp's summary goes to FreeCAD's Report view as a message, its warnings as
# warnings and a failure as an error, each naming the line of the program
# linuxcnc_post made (with its text).
#
# FreeCAD 0.20/0.21 call the module function export(); FreeCAD 1.x looks for
# the class named after the file (`Ncpp`) and calls its export().

import argparse
import importlib
import importlib.util
import os
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

TOOLTIP = """Posts through FreeCAD's LinuxCNC post (or --base NAME), then compensates the program
for the machine's geometric errors with ncpp (header names the machine file)."""

parser = argparse.ArgumentParser(prog="ncpp", add_help=False)
parser.add_argument("--machine", help="machine file (default: $NCPP_MACHINE or the ncpp config)")
parser.add_argument("--from", dest="from_file", help="compensate from one measurement file")
parser.add_argument("--tolerance", help="allowed path deviation in mm")
parser.add_argument(
    "--work-offset",
    action="append",
    default=[],
    help="[G5x=]X,Y,Z machine position of a fixture's zero, mm (repeat)",
)
parser.add_argument("--var-file", help="LinuxCNC parameter file holding the zeros")
parser.add_argument("--tool-table", help="LinuxCNC tool table: the lengths the program's G43 applies")
parser.add_argument("--var-units", help="units of --var-file and --tool-table: mm or inch")
parser.add_argument("--ncpp", help="refused: ncpp is found from $NCPP, the FreeCAD parameter or PATH")
# FreeCAD's own posts this one can wrap: all write ISO G code that the ncpp filter reads
BASES = ("linuxcnc", "grbl", "fanuc", "mach3_mach4", "centroid")
# The ncpp dialect a base post's program is read in, where it is not LinuxCNC's (grbl takes
# K in a G17 arc, which FreeCAD's grbl post writes)
BASE_DIALECTS = {"grbl": "grbl"}
parser.add_argument("--base", default="linuxcnc", help=f"FreeCAD's post to wrap: {', '.join(BASES)}")
parser.add_argument("--no-guard", action="store_true", help="no placement guard at the program's start")

TOOLTIP_ARGS = parser.format_help() + "\nOther arguments are passed to the --base post (linuxcnc_post).\n"


def _base_post(name):
    """A fresh copy of FreeCAD's `name`_post.  Such a post keeps its options in module
    globals that only its flags change (--no-comments, --inches, ... stay set
    for the rest of the session), so each post starts from a new module."""
    if name not in BASES:
        raise RuntimeError(f"ncpp_post: --base {name}: expected one of {', '.join(BASES)}")
    try:  # FreeCAD 1.x; after 1.0 the script post with export() is NAME_legacy_post
        base = importlib.import_module(f"Path.Post.scripts.{name}_post")
        if not hasattr(base, "export"):
            base = importlib.import_module(f"Path.Post.scripts.{name}_legacy_post")
    except ImportError:  # FreeCAD 0.19-0.21 (Path is only the C++ module)
        base = importlib.import_module(f"PathScripts.post.{name}_post")
    spec = importlib.util.spec_from_file_location(base.__name__, base.__file__)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


PARAMETERS = "User parameter:BaseApp/Preferences/Mod/ncpp"


def _preferred_program():
    """The ncpp program the user set in FreeCAD's parameters ("" when none, or outside FreeCAD)."""
    try:
        import FreeCAD
    except ImportError:
        return ""
    return FreeCAD.ParamGet(PARAMETERS).GetString("Program", "")


def _ncpp_command(options):
    if options.ncpp:
        raise RuntimeError(
            "ncpp_post: --ncpp in the Job's arguments is refused (a shared document would choose the "
            f"program to run): set NCPP, or the parameter Program in {PARAMETERS}"
        )
    found = os.environ.get("NCPP") or _preferred_program() or shutil.which("ncpp")
    if not found:
        raise RuntimeError(
            f"ncpp_post: the ncpp program was not found; set NCPP, or Program in {PARAMETERS}, "
            "or put ncpp on PATH"
        )
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
    if options.base in BASE_DIALECTS:
        args += ["--dialect", BASE_DIALECTS[options.base]]
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
    return f"ncpp_post: line {number} of the posted program ({text}): " + message[found.end() :]


def _report(kind, text):
    """A line in FreeCAD's Report view (`FreeCAD.Console.PrintWarning`, ...); stderr outside FreeCAD."""
    try:
        import FreeCAD
    except ImportError:
        print(text, file=sys.stderr)
        return
    getattr(FreeCAD.Console, kind)(text + "\n")


def base_text(objectslist, argstring):
    """What FreeCAD's --base post makes of the objects, with ncpp's own arguments removed."""
    options, rest = parser.parse_known_args(shlex.split(argstring or ""))
    post = _base_post(options.base)
    with tempfile.TemporaryDirectory(prefix="ncpp_post") as folder:
        raw = os.path.join(folder, f"{options.base}.ngc")
        result = post.export(objectslist, raw, " ".join(shlex.quote(a) for a in rest + ["--no-show-editor"]))
        if os.path.exists(raw):
            with open(raw, encoding="latin-1") as f:
                return f.read()
        return result or ""


def export(objectslist, filename, argstring):
    """Legacy entry point (FreeCAD 0.19-0.21): post, compensate, write `filename`."""
    gcode = compensate_text(base_text(objectslist, argstring), argstring)
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
        """`ncpp` for FreeCAD 1.x: each output section posted by the --base post, then compensated."""

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
            """What the --base post writes: G20 (Inch) for --inches, else G21 (Metric)."""
            return "Inch" if "--inches" in shlex.split(self._argstring()) else "Metric"

        def _argstring(self):
            return getattr(self._job, "PostProcessorArgs", "") or ""  # no job in the Preferences dialog

        def export(self):
            argstring = self._argstring()
            posted = [(name, base_text(objects, argstring)) for name, objects in self._buildPostList()]
            return [(name, compensate_text(gcode, argstring)) for name, gcode in posted]
