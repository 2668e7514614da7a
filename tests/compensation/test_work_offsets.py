"""Work offsets place a program on the machine: each coordinate system G54-G59.3 at
the zero the control holds (--work-offset G5x=..., or LinuxCNC's parameter file),
G53 moves in machine coordinates.  A system nobody gave gets a warning naming the
line where it is first selected; --strict refuses it."""

import io
import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.motion.offsets import WorkOffsets, parse_zero
from ncpp.pipeline import ErrorSource, process
from ncpp.simulate import contour_error, sample_events
from tests.compensation.conftest import compensate, events_of, repeatable_machine

ROOT = Path(__file__).resolve().parents[2]
MACHINE = ROOT / "samples/machines/hr5b.toml"
PROGRAM = b"G21 G90 G54\nG0 X10 Y10 Z50\nG55\nG1 X20 F100\nG56 G1 X5\nG55 X1\nG59.1 X2\nM2\n"
G54 = (400.0, 350.0, 300.0)


def _warnings(
    program: bytes, offsets: WorkOffsets | None = None, strict: bool = False, source: bool = True
) -> str:
    said = io.StringIO()
    src = ErrorSource.from_machine_file(str(MACHINE)) if source else None
    process(
        io.BytesIO(program),
        io.BytesIO(),
        file="t.ngc",
        source=src,
        warnings=Warnings(strict, said),
        offsets=offsets or WorkOffsets.at(G54),
    )
    return said.getvalue()


def test_each_system_nobody_gave_is_named_once_where_it_is_first_selected():
    lines = _warnings(PROGRAM).splitlines()
    assert [line.split(": warning: ")[0] for line in lines] == ["t.ngc:3:1", "t.ngc:5:1", "t.ngc:7:1"]
    assert [line.split(": warning: ")[1].split()[0] for line in lines] == ["G55", "G56", "G59.1"]
    assert "--work-offset G55=X,Y,Z" in lines[0]


def test_systems_given_or_set_by_the_program_say_nothing():
    told = WorkOffsets.of(
        {"G54": G54, "G55": (500, 350, 300), "G56": (300, 350, 300), "G59.1": (100, 100, 300)}
    )
    assert _warnings(PROGRAM, told) == ""
    set_here = b"G10 L2 P2 X500 Y350 Z300\nG10 L2 P3 X300 Y350 Z300\nG10 L2 P7 X100 Y100 Z300\n"
    assert _warnings(set_here + PROGRAM) == ""
    assert "G55" in _warnings(b"G10 L2 P2 X500\n" + PROGRAM)  # Y and Z of G55 still unknown


def test_strict_mode_refuses_a_system_nobody_gave():
    with pytest.raises(NcppError, match="t.ngc:3:1: G55 selects a work offset ncpp is not told"):
        _warnings(PROGRAM, strict=True)


def test_passthrough_says_nothing():
    assert _warnings(PROGRAM, source=False) == ""


def _compensated_lines(program: bytes, offsets: WorkOffsets) -> list[str]:
    out = io.BytesIO()
    process(
        io.BytesIO(program),
        out,
        file="t.ngc",
        source=ErrorSource.from_machine_file(str(MACHINE)),
        offsets=offsets,
    )
    return out.getvalue().decode().splitlines()


def test_a_g53_move_is_written_in_machine_coordinates():
    program = b"G21 G90 G54\nG0 X10 Y10 Z5\nG53 G0 Z650\nG0 X20\nM2\n"
    lines = _compensated_lines(program, WorkOffsets.at(G54))
    g53 = next(line for line in lines if line.startswith("G53"))
    z = float(g53.split("Z")[1].split()[0])
    assert abs(z - 650.0) < 0.1 and z != 650.0  # machine Z, corrected by the machine's error there
    assert _warnings(program) == ""


def test_the_error_message_names_machine_coordinates_and_the_real_travel():
    with pytest.raises(
        NcppError, match=r"t.ngc:2:4: command X\d+\.\d+ mm is outside the X travel \[0, 800\] mm"
    ) as err:
        _compensated_lines(b"G21 G90\nG1 X900 F100\nM2\n", WorkOffsets.at(G54))  # to machine X1300
    assert 800 < float(str(err.value).split("command X")[1].split()[0]) <= 1300.1


POCKET = [
    line
    for line in (ROOT / "samples/programs/pocket.ngc").read_bytes().splitlines()
    if line.strip() not in (b"%", b"M2")
]
TWO_FIXTURES = b"\n".join(POCKET + [b"G55"] + POCKET[2:] + [b"M2", b""])  # the pocket at G54, then at G55
FIXTURES = WorkOffsets.of({"G54": (250.0, 300.0, 300.0), "G55": (550.0, 400.0, 250.0)})


def _contour_um(machine, program: bytes, nominal: bytes, offsets: WorkOffsets) -> float:
    return contour_error(
        machine,
        sample_events(events_of(program, offsets=offsets)),
        sample_events(events_of(nominal, offsets=offsets)),
        feed_effects=False,
    ).max_um


def test_two_fixtures_are_each_compensated_at_their_own_place():
    """The pocket twice, at G54 and at G55 300 mm apart: with both zeros given, the
    simulated contour error is within the tolerance + 0.5 µm on both."""
    machine = repeatable_machine(MACHINE)
    moves = [e for e in events_of(TWO_FIXTURES) if type(e).__name__ in ("Line", "Arc")]
    assert len(moves) == 2 * len(
        [e for e in events_of(b"\n".join(POCKET)) if type(e).__name__ in ("Line", "Arc")]
    )
    before = _contour_um(machine, TWO_FIXTURES, TWO_FIXTURES, FIXTURES)
    after = _contour_um(machine, compensate(TWO_FIXTURES, machine, FIXTURES), TWO_FIXTURES, FIXTURES)
    assert before > 20.0 and after <= 1.5, (before, after)
    # G55 not given: its zero is taken as the machine zero, where the pocket leaves the travel
    said = io.StringIO()
    only_g54 = WorkOffsets.at((250.0, 300.0, 300.0))
    with pytest.raises(NcppError, match="outside the . travel") as err:
        compensate(TWO_FIXTURES, machine, only_g54, warnings=Warnings(stream=said))
    g55_line = TWO_FIXTURES.splitlines().index(b"G55") + 1
    assert said.getvalue().startswith(
        f"<test>:{g55_line}:1: warning: G55 selects a work offset ncpp is not told"
    )
    assert err.value.where.line > g55_line


VAR_FILE = """\
5161\t0.000000
5163\t600.000000
5210\t0.000000
5211\t5.000000
5220\t2.000000
5221\t250.000000
5222\t300.000000
5223\t300.000000
5241\t550.000000
5242\t400.000000
5243\t250.000000
"""


def test_linuxcnc_parameter_file(tmp_path):
    path = tmp_path / "linuxcnc.var"
    path.write_text(VAR_FILE)
    offsets = WorkOffsets.from_var_file(path)
    assert offsets.zero(1) == (250.0, 300.0, 300.0) and offsets.zero(2) == (550.0, 400.0, 250.0)
    assert offsets.active == 2 and offsets.program_zero() == (550.0, 400.0, 250.0)
    assert offsets.g92 == (0.0, 0.0, 0.0)  # 5210 = 0: G92 not in effect
    assert offsets.g92_saved == (5.0, 0.0, 0.0)  # (what G92.3 applies)
    assert offsets.g28 == (0.0, 0.0, 600.0) and not offsets.told(3)
    inch = WorkOffsets.from_var_file(path, 25.4)
    assert inch.zero(2) == pytest.approx((550.0 * 25.4, 400.0 * 25.4, 250.0 * 25.4))
    path.write_text("5221 x\n")
    with pytest.raises(NcppError, match=r"linuxcnc.var:1:6: parameter 5221 has no number"):
        WorkOffsets.from_var_file(path)


def test_a_program_starts_in_the_system_the_control_has_in_effect(tmp_path):
    path = tmp_path / "linuxcnc.var"
    path.write_text(VAR_FILE)
    events = events_of(b"G21 G90\nG0 X10 Y10 Z5\nM2\n", offsets=WorkOffsets.from_var_file(path))
    assert events[1].context.to_machine(events[1].end) == pytest.approx((560.0, 410.0, 255.0))


def test_command_line_var_file_and_work_offsets_say_the_same(tmp_path):
    var = tmp_path / "linuxcnc.var"
    var.write_text(VAR_FILE.replace("5220\t2.000000", "5220\t1.000000"))
    program = tmp_path / "two.ngc"
    program.write_bytes(TWO_FIXTURES)

    def run(*placement: str) -> subprocess.CompletedProcess:
        command = [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            "--machine",
            str(MACHINE),
            str(program),
            *placement,
        ]
        return subprocess.run(
            command, capture_output=True, cwd=ROOT
        )  # ncpp is importable there from the tree too

    from_var = run("--var-file", str(var))
    given = run("--work-offset", "250,300,300", "--work-offset", "g55=550,400,250")
    assert from_var.returncode == 0 and b"warning" not in from_var.stderr, from_var.stderr
    assert from_var.stdout == given.stdout and b"warning" not in given.stderr
    overridden = run("--var-file", str(var), "--work-offset", "G55=550,400,251")
    assert overridden.stdout != from_var.stdout
    bad = run("--work-offset", "G60=1,2,3")
    assert bad.returncode == 2 and b"not a work coordinate system" in bad.stderr


def test_parse_zero():
    assert parse_zero("1,2,3") == ("G54", (1.0, 2.0, 3.0))
    assert parse_zero("g59.3=-1,0,2.5") == ("G59.3", (-1.0, 0.0, 2.5))
    for bad in ("1,2", "G55=a,b,c", "G53=1,2,3", "G154P7=1e308,0,0", "0,-1000001,0"):  # (beyond any machine)
        with pytest.raises(ValueError):
            parse_zero(bad)


SINUMERIK = b"G54\nG0 X10 Y10 Z5\nG1 X20 F100\nG55\nG1 X30\nG500\nG1 X40\nM30\n"


def test_a_one_zero_dialect_names_another_system():
    said = io.StringIO()
    process(io.BytesIO(SINUMERIK), io.BytesIO(), file="t.mpf", source=ErrorSource.from_machine_file(str(MACHINE)),
            warnings=Warnings(stream=said), dialect="sinumerik", offsets=WorkOffsets.at(G54))  # fmt: skip
    lines = said.getvalue().splitlines()
    assert (
        lines[0].startswith("t.mpf:5:1: warning: a move under G55 (ncpp is told the zero of G54)")
        and len(lines) == 1
    )


# -- the oracle: LinuxCNC's rs274 started from the same parameter file ---------------------------

ORACLE_PROGRAM = b"""G21 G90
G0 X10 Y10 Z5
G1 X20 F100
G55
G1 Y30
G10 L2 P3 X-100 Y-50 Z-20
G56 G0 X1 Y2
G53 G0 Z0
G92 X0 Y0
G1 X5 Y5
G92.1
G28 X3
G54 G1 X7 Y8 Z9
M2
"""
ORACLE_VAR = "5161 1.0\n5162 2.0\n5163 3.0\n5220 2.0\n5221 10.0\n5222 20.0\n5223 -5.0\n5241 11.5\n5242 7.25\n5243 -2.0\n"


def test_placement_agrees_with_linuxcnc_started_from_the_same_parameter_file(tmp_path, capsys):
    """The stand-alone rs274 reads its parameter file in inches: G55 in effect at the start,
    G10 L2, G53, G92 and G28 from the file's G28 position all land where LinuxCNC puts them."""
    import re

    from tests.rs274 import calls_from, end_points

    var, program = tmp_path / "sim.var", tmp_path / "p.ngc"
    var.write_text(ORACLE_VAR)
    program.write_bytes(ORACLE_PROGRAM)
    offsets = WorkOffsets.from_var_file(var, 25.4)  # read first: rs274 writes the file back when it exits
    from ncpp.cli import main

    assert main(["motion", str(program), "--var-file", str(var), "--var-units", "inch"]) == 0
    listed = capsys.readouterr().out.splitlines()
    canon = calls_from(var, program)
    assert listed == re.findall(
        r"(?:STRAIGHT_TRAVERSE|STRAIGHT_FEED|ARC_FEED)\(.*\)", canon
    )  # `ncpp motion` says the same
    want = end_points(canon)
    events = [e for e in events_of(ORACLE_PROGRAM, offsets=offsets) if type(e).__name__ in ("Line", "Arc")]
    assert len(events) == len(want) == 9
    for event, point in zip(events, want):
        assert event.end == pytest.approx(point, abs=1e-4)
    # the zeros rs274 announces are those the events are placed with
    g5x = [tuple(float(v) for v in m.split(",")[1:4]) for m in re.findall(r"SET_G5X_OFFSET\((.*)\)", canon)]
    assert g5x[0] == pytest.approx((11.5 * 25.4, 7.25 * 25.4, -2.0 * 25.4))
    assert events[0].context.offset == pytest.approx(g5x[0])


def test_a_missing_parameter_file_is_a_located_error(tmp_path):
    with pytest.raises(NcppError, match=r"nowhere.var: cannot read the parameter file"):
        WorkOffsets.from_var_file(tmp_path / "nowhere.var")


def test_one_zero_named_alone_is_the_system_in_effect_at_the_start():
    """`--work-offset G55=...` alone: the program runs in G55 until it selects another (a
    Sinumerik or Klartext program's one zero is it); with G54 named too, G54 is in effect."""
    from ncpp.motion.offsets import WorkOffsets

    alone = WorkOffsets.given({"G55": (400.0, 350.0, 300.0)})
    assert alone.active == 2 and alone.program_zero() == (400.0, 350.0, 300.0)
    both = WorkOffsets.given({"G54": (1.0, 2.0, 3.0), "G55": (400.0, 350.0, 300.0)})
    assert both.active == 1 and both.program_zero() == (1.0, 2.0, 3.0)
