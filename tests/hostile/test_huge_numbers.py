"""A number past a float's range on the way (a tool 1e308 mm long) is refused with its line, and
nothing else is said: no numpy warning leaks out before the refusal."""

from __future__ import annotations

import pytest

from tests.conftest import SHARED

MACHINE = SHARED / "machines/wide.toml"

CASES = {
    "linuxcnc": ("tool.tbl", "T1 P1 Z1e308 D0 ;\n", "tl.ngc",
                 "G21 G17 G90 F200\nT1 M6\nG43 H1\nG0 X0 Y0 Z5\nG1 X10 Y10\nM2\n", 4, 10),
    "klartext": ("TOOL.T", "BEGIN TOOL    .T       MM\nT    NAME             L          R          DL      DR\n"
                 "1    HUGE             +1e308     +5,000     +0,000  +0,000\n[END]\n", "t.h",
                 "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L X+0 Y+0 Z+5 R0 FMAX\n3 L X+10 Y+10 R0 F200\n"
                 "4 END PGM T MM\n", 3, 13),
    "sinumerik": ("_N_TO_INI", "$TC_DP1[1,1]=120\n$TC_DP3[1,1]=1e308\n", "t.mpf",
                  "G17 G90 G71\nT1 D1\nM6\nG0 X0 Y0 Z5\nG1 X10 Y10 F200\nM30\n", 4, 10),
}  # fmt: skip


@pytest.mark.skipif(not MACHINE.exists(), reason="no shared machine file")
@pytest.mark.parametrize("verify", [(), ("--no-verify",)], ids=["verified", "unverified"])
@pytest.mark.parametrize("case", sorted(CASES))
def test_a_tool_1e308_mm_long_is_refused_without_a_numpy_warning(ncpp, tmp_path, case, verify):
    table_name, table, program_name, program, line, column = CASES[case]
    (tmp_path / table_name).write_text(table)
    (tmp_path / program_name).write_text(program)
    done = ncpp("compensate", "--machine", str(MACHINE), "--tool-table", str(tmp_path / table_name),
                str(tmp_path / program_name), "-o", str(tmp_path / "out"), *verify)  # fmt: skip
    said = done.stderr.decode()
    assert done.returncode == 2
    # (the tool's length puts the tool tip's command past any travel: told in powers of ten)
    told = f"{tmp_path / program_name}:{line}:{column}: command Z1e+308 mm is outside the Z travel [-40000, 40000] mm"
    assert told in said, said
    assert "RuntimeWarning" not in said and "Traceback" not in said, said
    assert not (tmp_path / "out").exists()
