"""A number a float cannot hold (`X999...9`, `EXP[1000]`, `nan` in a parameter file or on
the command line) is refused with the file and line, or as a bad option: never an output
with `Xnan` or `Xinf` in it, never a traceback."""

import io
from pathlib import Path

import numpy as np
import pytest

from ncpp.cldata.reader import read_cldata
from ncpp.cli import main
from ncpp.errors import NcppError
from ncpp.motion.offsets import parse_zero, read_var_file
from ncpp.motion.tools import read_tool_lines
from ncpp.passes.geometry import compensate
from ncpp.pipeline import ErrorSource, dialect_tools, make_context
from ncpp.program.dialects import parse_program
from tests.compensation.conftest import QUIET

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples/machines/hr5b.toml"
POCKET = ROOT / "samples/programs/pocket.ngc"
TOO_LONG = "9" * 400  # more digits than a float holds: float() reads infinity


def _motion(text: str, file: str) -> list:
    name, blocks = parse_program(io.BytesIO(text.encode()), file, None)
    interpreter, _ = dialect_tools(name)
    return list(interpreter(blocks, file=file, warnings=QUIET))


@pytest.mark.parametrize(
    "text, file, where, message",
    [
        # (an ISO line cannot hold such a number: rs274 refuses it as "Command too long" too)
        (f"G21 G90\nG1 X{TOO_LONG} F100\nM2\n", "p.ngc", "p.ngc:2:257", "block too long"),
        (f"N1 G1 X{TOO_LONG} F100\nM30\n", "p.mpf", "p.mpf:1:7", "number out of range"),
        ("G21 G90\nG1 X[EXP[1000]] F100\nM2\n", "p.ngc", "p.ngc:2:4", "Number out of range"),
        ("G21 G90\nG1 X[10**400] F100\nM2\n", "p.ngc", "p.ngc:2:4", "Number out of range"),
        (
            "G21 G90\nG1 X[1" + "0" * 200 + "*1" + "0" * 200 + "] F100\nM2\n",
            "p.ngc",
            "p.ngc:2:257",
            "block too long",
        ),
        (
            "G21 G90\nG1 X" + "[" * 800 + "1" + "]" * 800 + " F100\nM2\n",
            "p.ngc",
            "p.ngc:2:257",
            "block too long",
        ),
        (
            "N1 R1=" + "(" * 200 + "1" + ")" * 200 + "\nM30\n",
            "p.mpf",
            "p.mpf:1:135",
            "nested deeper than 128",
        ),
        (
            "BEGIN PGM X MM\nQ1 = 10 ^ 400\nL X+Q1 Y+0 R0 FMAX\nEND PGM X MM\n",
            "p.h",
            "p.h:2:1",
            "number out of range",
        ),
        (
            f"BEGIN PGM X MM\nL X+{TOO_LONG} Y+0 R0 FMAX\nEND PGM X MM\n",
            "p.h",
            "p.h:2:3",
            "number out of range",
        ),
    ],
)
def test_a_number_out_of_range_is_refused_where_it_stands(text, file, where, message):
    with pytest.raises(NcppError) as err:
        _motion(text, file)
    assert str(err.value).startswith(where) and message in str(err.value)


def test_a_long_line_of_ordinary_numbers_is_read():
    line = "N1 G1 X1.5 Y2.5 F100 ;" + "x" * 400  # (a Sinumerik block holds 512 characters)
    assert len(_motion(f"{line}\nM30\n", "p.mpf")) >= 1


def test_a_point_that_is_not_a_number_is_refused_by_the_compensation_itself():
    ctx = make_context(ErrorSource.from_machine_file(str(MACHINE)), 0.001, QUIET, "p.ngc")
    points = np.array([[10.0, 20.0, 0.0], [np.nan, 20.0, 0.0]])
    with pytest.raises(NcppError, match=r"p\.ngc:7:1: the program point is not a finite number"):
        compensate(points, np.tile([400.0, 350.0, 300.0], (2, 1)), np.ones(2), np.array([6, 7]), ctx)


@pytest.mark.parametrize("zero", ["nan,350,300", "400,inf,300", "400,350,-inf"])
def test_a_work_offset_that_is_not_a_number_is_a_bad_option(zero, capsys):
    with pytest.raises(ValueError, match="three finite numbers"):
        parse_zero(zero)
    with pytest.raises(SystemExit) as done:
        main(["compensate", "--machine", str(MACHINE), "--work-offset", zero, str(POCKET)])
    assert done.value.code == 2 and "argument --work-offset" in capsys.readouterr().err


@pytest.mark.parametrize("command", ["compensate", "post"])
@pytest.mark.parametrize("tolerance", ["0", "-1", "nan", "inf", "abc"])
def test_a_tolerance_that_is_not_a_positive_number_is_a_bad_option(command, tolerance, capsys):
    with pytest.raises(SystemExit) as done:
        main([command, "--machine", str(MACHINE), "--tolerance", tolerance, str(POCKET)])
    assert (
        done.value.code == 2
        and f"argument --tolerance: expected a positive number of mm, got '{tolerance}'"
        in capsys.readouterr().err
    )


@pytest.mark.parametrize("step", ["0", "-1", "nan", "inf", "1e-9"])
def test_a_simulation_step_that_is_not_a_number_of_mm_is_a_bad_option(step, capsys):
    with pytest.raises(SystemExit) as done:
        main(["simulate", "--machine", str(MACHINE), "--step", step, str(POCKET)])
    assert done.value.code == 2 and "argument --step" in capsys.readouterr().err


def test_a_parameter_file_value_that_is_not_a_number_is_refused(tmp_path):
    var = tmp_path / "linuxcnc.var"
    var.write_text("5220 1.000000\n5221 nan\n")
    with pytest.raises(NcppError, match=r"linuxcnc\.var:2:6: parameter 5221 is not a finite number"):
        read_var_file(var)


@pytest.mark.parametrize("length", ["nan", "inf", "1e400"])
def test_a_tool_length_that_is_not_a_number_is_refused(tmp_path, length):
    with pytest.raises(NcppError, match=r"tool\.tbl:1:\d+: expected a finite number"):
        read_tool_lines([f"T1 P1 Z{length} D3.0"], "tool.tbl", 1.0)


def test_a_cl_record_with_a_number_out_of_range_is_refused():
    records = read_cldata(io.StringIO(f"UNITS / MM\nFEDRAT / 100\nGOTO / {TOO_LONG}, 0, 0\nFINI\n"), "p.cl")
    with pytest.raises(NcppError, match=r"p\.cl:3:8: number out of range in this CL record"):
        list(records)


def test_a_tolerance_of_1e_300_subdivides_as_finely_as_1e_30(tmp_path, capsys, recwarn):
    """The piece count's ratio was inf and cast to a negative int (a numpy warning, then 1 piece)."""
    outputs = []
    for tolerance in ("1e-30", "1e-300"):
        out = tmp_path / f"{tolerance}.ngc"
        argv = [
            "compensate",
            "--machine",
            str(MACHINE),
            "--work-offset",
            "400,350,300",
            "--tolerance",
            tolerance,
        ]
        assert main([*argv, str(POCKET), "-o", str(out)]) == 0
        outputs.append(out.read_bytes().splitlines()[2:])  # after the header, which names the tolerance
    assert outputs[0] == outputs[1] and len(outputs[0]) > 90_000
    assert not [w for w in recwarn if issubclass(w.category, RuntimeWarning)]
