"""Wrong function calls and formulas are located errors, never a traceback; FN blocks are read."""

from __future__ import annotations

import pytest


@pytest.mark.parametrize(
    "call, message",
    [
        ("SIN()", "SIN takes 1 argument, not 0"),
        ("SIN(1,2)", "SIN takes 1 argument, not 2"),
        ("ATAN2(1)", "ATAN2 takes 2 arguments, not 1"),
        ("MINVAL()", "MINVAL takes 2 arguments, not 0"),
        ("ABS()", "ABS takes 1 argument, not 0"),
        ("MAXVAL(1,2,3)", "MAXVAL takes 2 arguments, not 3"),
    ],
)
def test_a_sinumerik_function_of_the_wrong_arity_is_a_located_error(ncpp, tmp_path, call, message):
    program = tmp_path / "f.mpf"
    program.write_text(f"N10 G0 X0\nN20 R1={call}\nN30 G1 X=R1 F100\nM30\n")
    done = ncpp("motion", str(program))
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert done.stderr.decode().strip() == f"{program}:2:5: {message}"


def test_maxval_of_two_is_evaluated(ncpp, tmp_path):
    program = tmp_path / "f.mpf"
    program.write_text("N10 R1=MAXVAL(3,7)\nN20 G1 X=R1 F100\nM30\n")
    done = ncpp("motion", str(program))
    assert done.returncode == 0, done.stderr
    assert "7" in done.stdout.decode()


def test_a_negative_base_to_a_fractional_power_is_a_located_error(ncpp, tmp_path):
    program = tmp_path / "p.h"
    program.write_text("0 BEGIN PGM P MM\n1 Q1 = -8 ^ 0,5\n2 L X+Q1 F100\n3 END PGM P MM\n")
    done = ncpp("motion", str(program))
    assert done.returncode == 2 and b"Traceback" not in done.stderr
    assert done.stderr.decode().strip() == f"{program}:2:3: negative number to a non-integer power"


@pytest.mark.parametrize(
    "body",
    [
        "FN 4: Q1 = +6 DIV +2",
        "FN 5: Q1 = SQRT +4",
        "FN 6: Q1 = SIN +30",
        "FN 8: Q1 = +3 LEN +4",
        "FN 13: Q1 = +1 ANG +1",
        "FN 0: Q1 = +5",
    ],
)
def test_fn_functions_of_a_valid_tnc_program_are_read(ncpp, tmp_path, body):
    """(TNC 640 Klartext manual, Q parameter programming: FN 4 DIV, FN 5 SQRT, FN 6 SIN, FN 8 LEN, FN 13 ANG)"""
    text = f"0 BEGIN PGM P MM\n1 {body}\n2 L X+1 F100\n3 END PGM P MM\n"
    program = tmp_path / "p.h"
    program.write_text(text)
    done = ncpp("motion", str(program))
    assert done.returncode == 0, done.stderr
    said = done.stderr.decode()
    assert "unexpected" not in said and "cannot read" not in said  # read, if not yet followed
