"""M codes a control is set up to switch its kinematics with (a LinuxCNC remap such as the
impeller's M428) are refused when the machine file names them, like G43.4: the programmed
X Y Z are then the tool tip's, which ncpp's model of the linear axes does not place."""

from __future__ import annotations

import io

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.machine import load_machine
from ncpp.machine.io import save_machine
from ncpp.pipeline import ErrorSource, process
from tests.conftest import SHARED

WIDE = SHARED / "machines" / "wide.toml"
PROGRAM = b"G21 G90\nG0 X0 Y0 Z0\nG1 X5 F100\nM428\nG1 X10 F100\nM2\n"

pytestmark = pytest.mark.skipif(not WIDE.exists(), reason="no shared machine file")


def machine_file(tmp_path, codes: str | None):
    text = WIDE.read_text()
    if codes is not None:
        text = text.replace(
            "max_correction_mm = 0.5", f"max_correction_mm = 0.5\nkinematics_m_codes = {codes}"
        )
    path = tmp_path / "m.toml"
    path.write_text(text)
    return path


def compensate(path) -> bytes:
    out = io.BytesIO()
    process(io.BytesIO(PROGRAM), out, file="p.ngc", source=ErrorSource.from_machine_file(str(path)),
            warnings=Warnings(stream=io.StringIO()))  # fmt: skip
    return out.getvalue()


def test_an_m_code_the_machine_file_names_is_refused_at_its_word(tmp_path):
    with pytest.raises(NcppError) as caught:
        compensate(machine_file(tmp_path, "[428, 429]"))
    assert (
        str(caught.value.where) == "p.ngc:4:1"
        and "M428 turns tool-centre-point control on" in caught.value.message
    )


def test_without_the_key_the_m_code_is_the_controls_own(tmp_path):
    assert b"M428" in compensate(machine_file(tmp_path, None))


def test_the_key_is_read_checked_and_written_back(tmp_path):
    path = machine_file(tmp_path, "[428]")
    machine = load_machine(str(path))
    assert machine.kinematics_m_codes == (428,)
    save_machine(machine, tmp_path / "again.toml")
    assert load_machine(str(tmp_path / "again.toml")).kinematics_m_codes == (428,)
    with pytest.raises(NcppError, match="kinematics_m_codes must be a list of M numbers"):
        load_machine(str(machine_file(tmp_path, '"M428"')))
