"""The additional work offsets of Fanuc (`G54.1 P1`-`P48`) and Haas (`G154 P1`-`P99`): where ncpp
is told their zeros (`--work-offset G54.1P2=X,Y,Z`, `G154P2=`, or a parameter file's #7001... and
#14001..., as the controls' macro variables hold them), a program that switches to one is
compensated at the machine positions it takes there, as under G55 with the same zero.

Judged by LinuxCNC's rs274 running ncpp's output (the additional offset's line written as G55,
rs274's zeros all 0, so its coordinates are the program's) and a machine written here by hand
(`square`: scale errors and squareness), each end point placed by the zero of the system it runs
in: not by ncpp's interpreter or model."""

from __future__ import annotations

import io
import re

import numpy as np
import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets, parse_zero
from ncpp.pipeline import ErrorSource, process
from tests import rs274
from tests.writeback.test_compensated_holes import MACHINE, square

G54 = (100.0, 50.0, -200.0)
P2 = (-400.0, 300.0, -100.0)  # the additional work offset 2, 500 mm away in X
# (the code that selects additional offset 2, the dialect)
FLAVOURS = [("G54.1 P2", "fanuc"), ("G154 P2", "haas")]
# the other names the controls give additional offset 2: Fanuc's `G54 P2` (operator's manual,
# "Additional workpiece coordinate systems"), Haas's G111 (G110-G129 are G154 P1-P20)
OTHER_NAMES = [("G54 P2", "fanuc", "G54.1 P2"), ("G111", "haas", "G154 P2")]
SQUARE = [(0, 0), (60, 0), (60, 40), (0, 40), (0, 0)]
CALL = re.compile(r"(STRAIGHT_TRAVERSE|STRAIGHT_FEED|SET_G5X_OFFSET)\(([^)]*)\)")


def program(select: str) -> str:
    """A square cut at G54, at additional offset 2, at G54 again."""
    cut = "".join(f"G1 X{x} Y{y} F300\n" for x, y in SQUARE[1:])
    part = f"G0 X0 Y0 Z5\nG1 Z-2 F100\n{cut}G0 Z5\n"
    return f"G21 G90 G17 G54\n{part}{select}\n{part}G54\n{part}M30\n"


def compensated(text: str, dialect: str, offsets: WorkOffsets, tmp_path) -> str:
    machine = tmp_path / "machine.toml"
    machine.write_text(MACHINE)
    out = io.BytesIO()
    said = io.StringIO()
    process(io.BytesIO(text.encode()), out, file="p.nc", source=ErrorSource.from_machine_file(str(machine)),
            warnings=Warnings(stream=said), dialect=dialect, offsets=offsets)  # fmt: skip
    assert "warning" not in said.getvalue(), said.getvalue()
    return out.getvalue().decode()


def machine_ends(written: str, select: str, tmp_path) -> np.ndarray:
    """The end points of `written`'s moves as rs274 runs it (the additional offset's line as G55,
    every zero 0), each placed at the zero of the system rs274 says it runs in (SET_G5X_OFFSET)."""
    path = tmp_path / "run.ngc"
    path.write_text(written.replace(select, "G55").replace("M30", "M2"))
    done = rs274.run(path, digits=7)
    assert done.returncode == 0 and rs274.ran(done), done.stderr
    zero, ends = np.array(G54), []
    for name, args in CALL.findall(done.stdout):
        values = [float(v) for v in args.split(",")]
        if name == "SET_G5X_OFFSET":
            zero = np.array({1: G54, 2: P2}[int(values[0])])
        else:
            ends.append(np.array(values[:3]) + zero)
    return np.array(ends)


def missed_um(landed: np.ndarray, wanted: np.ndarray) -> float:
    """The farthest any landed point is from the nearest wanted one, or any wanted one from the
    nearest landed one, µm (ncpp may add a step where the zero changes: onto a wanted point)."""
    apart = np.linalg.norm(landed[:, None, :] - wanted[None, :, :], axis=2)
    return float(max(apart.min(axis=1).max(), apart.min(axis=0).max()) * 1000)


@pytest.mark.parametrize("select, dialect", FLAVOURS + [name[:2] for name in OTHER_NAMES])
def test_each_move_is_compensated_where_its_system_puts_it(tmp_path, select, dialect):
    """G54 -> additional offset 2 -> G54: within 0.5 µm of every programmed point, where the
    program as written misses by microns."""
    offsets = WorkOffsets.of({"G54": G54, select.replace(" ", ""): P2})
    written = compensated(program(select), dialect, offsets, tmp_path)
    assert select in written
    wanted = machine_ends(program(select), select, tmp_path)
    assert missed_um(square(wanted, np.ones(3)), wanted) > 10.0  # the program as written
    assert missed_um(square(machine_ends(written, select, tmp_path), np.ones(3)), wanted) < 0.5


@pytest.mark.parametrize("select, dialect, said", [(*f, f[0]) for f in FLAVOURS] + OTHER_NAMES)
def test_an_additional_offset_is_compensated_as_g55_with_the_same_zero(tmp_path, select, dialect, said):
    as_g55 = compensated(program("G55"), dialect, WorkOffsets.of({"G54": G54, "G55": P2}), tmp_path)
    told = WorkOffsets.of({"G54": G54, select.replace(" ", ""): P2})
    additional = compensated(program(select), dialect, told, tmp_path)
    assert f"{said} X-400 Y300 Z-100" in additional  # (the header says the zero)
    body = additional[additional.index("G21 G90") :]
    assert body == as_g55[as_g55.index("G21 G90") :].replace("G55\n", select + "\n")


@pytest.mark.parametrize(
    "variables, select, dialect",
    [
        ("7021 -400\n7022 300\n7023 -100\n", "G54.1 P2", "fanuc"),
        ("14021 -400\n14022 300\n14023 -100\n", "G154 P2", "haas"),
        ("7021 -400\n7022 300\n7023 -100\n", "G154 P2", "haas"),  # (Haas's P1-P20 are also #7001...)
    ],
)
def test_a_parameter_file_gives_the_zeros_as_the_controls_variables_hold_them(
    tmp_path, variables, select, dialect
):
    """Fanuc: #7001-#7003 X Y Z of G54.1 P1, 20 per offset; Haas: #14001-#14003 of G154 P1."""
    var = tmp_path / "control.var"
    var.write_text("5221 100\n5222 50\n5223 -200\n" + variables)
    from_file = compensated(program(select), dialect, WorkOffsets.given({}, var), tmp_path)
    told = compensated(program(select), dialect, WorkOffsets.of({"G54": G54, select.replace(" ", ""): P2}),
                       tmp_path)  # fmt: skip
    assert from_file == told
    inch = WorkOffsets.from_var_file(var, 25.4)
    assert inch.zero(inch.told_additional()[0]) == pytest.approx(tuple(v * 25.4 for v in P2))


def test_an_offset_given_twice_in_a_parameter_file_must_agree(tmp_path):
    var = tmp_path / "control.var"
    var.write_text("7021 -400\n14021 -400\n14022 1\n")
    with pytest.raises(NcppError, match="#7021 and #14021 both give additional work offset P2, and differ"):
        WorkOffsets.from_var_file(var)


def test_an_offset_not_told_stays_out_of_scope(tmp_path):
    """Only P2 told: P3 ends interpretation with the warning that says how to tell it."""
    with pytest.raises(AssertionError, match="p.nc:9:1: warning: G54.1 P3 .an additional work offset ncpp is "
                       "not told: give --work-offset G54.1P3=X,Y,Z or --var-file"):  # fmt: skip
        compensated(program("G54.1 P3"), "fanuc", WorkOffsets.of({"G54": G54, "G54.1P2": P2}), tmp_path)


def test_parse_names_the_additional_offsets():
    assert parse_zero("g54.1p3=1,2,3") == ("G54.1P3", (1.0, 2.0, 3.0))
    assert parse_zero("G154 P99=1,2,3")[0] == "G154 P99"
    assert WorkOffsets.of({"G54P3": (1, 2, 3), "G129": (4, 5, 6)}).told_additional() == [103, 120]
    assert WorkOffsets.of({"G54.1P3": (1, 2, 3)}).zero(WorkOffsets.of({"G154P3": (1, 2, 3)}).told_additional()[0]) == (
        1.0, 2.0, 3.0)  # fmt: skip
    bad_names = ("G54.1P49", "G154P100", "G54.1", "G154P0", "G130", "G110P1")
    for bad in (f"{name}=1,2,3" for name in bad_names):
        with pytest.raises(ValueError, match="not a work coordinate system"):
            parse_zero(bad)


@pytest.mark.parametrize("select, dialect", FLAVOURS)
def test_a_zero_the_program_sets_with_g10_l20_is_compensated_as_one_told(tmp_path, select, dialect):
    """Fanuc's and Haas's `G10 L20 P2 X.. Y.. Z..` sets additional offset 2's zero (Fanuc 0i-MF
    operator's manual, "Additional workpiece coordinate systems"; Haas "Programmable Offsets"): the
    program compensates as it does with the zero told, whose moves rs274 judges above."""
    told = compensated(program(select), dialect, WorkOffsets.of({"G54": G54, select.replace(" ", ""): P2}),
                       tmp_path)  # fmt: skip
    setting = "G10 L20 P2 X{:g} Y{:g} Z{:g}\n".format(*P2)
    own = compensated(setting + program(select), dialect, WorkOffsets.of({"G54": G54}), tmp_path)
    assert own[: own.index("G21 G90")].endswith(")\n" + setting)  # (after the header, as it was)
    assert own[own.index("G21 G90") :] == told[told.index("G21 G90") :]
