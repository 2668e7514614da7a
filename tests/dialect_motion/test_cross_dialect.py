"""The same part in ISO, Heidenhain and Sinumerik compensates to the same tool path.

Lines, a quarter arc in centre form, a half circle in radius form (`R`, `CR`,
`CR=`), a full circle and a helical half turn (`CP IPA ... IZ` in Klartext),
with incremental words and a decimal comma on the way.  Each program goes
through `ncpp.pipeline.process` with the HR5B sample machine; each output is
read back with its own dialect's interpreter and sampled finely; the three
compensated paths must agree within 0.1 µm.
"""

from __future__ import annotations

import io

import numpy as np
import pytest

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, dialect_tools, process
from ncpp.program.dialects import parse_program
from ncpp.simulate import sample_events
from tests.conftest import ROOT

ISO = """G21 G90 G17
G0 X0 Y0 Z5
G1 Z-2 F300
G1 X40 Y0 F800
G3 X50 Y10 I0 J10
G1 X50 Y30
G3 X30 Y30 R10
G1 X0 Y30
G1 X0 Y0
G1 X20 Y15
G2 X20 Y15 I5 J0
G3 X30 Y15 Z-3 I5 J0
G0 Z5
M30
"""
HEIDENHAIN = """0  BEGIN PGM PART MM
1  TOOL CALL 1 Z S3000
2  L  X+0  Y+0  Z+5 R0 FMAX
3  L  Z-2 F300
4  L  X+40,0  Y+0 F800
5  CC  X+40  Y+10
6  C  X+50  Y+10 DR+
7  L  IY+20
8  CR  X+30  Y+30  R+10 DR+
9  L  X+0
10 L  Y+0
11 L  X+20  Y+15
12 CC  X+25  Y+15
13 C  X+20  Y+15 DR-
14 CP  IPA+180  IZ-1 DR+
15 L  Z+5 FMAX
16 END PGM PART MM
"""
SINUMERIK = """N10 G90 G17 G71
N20 G0 X0 Y0 Z5
N30 G1 Z-2 F300
N40 X40 Y0 F800
N50 G3 X50 Y10 I0 J10
N60 G1 X50 Y30
N70 G3 X30 Y30 CR=10
N80 G1 X=IC(-30)
N90 Y0
N100 X20 Y15
N110 G2 X20 Y15 I5 J0
N120 G3 X30 Y15 Z-3 I=AC(25) J=AC(15)
N130 G0 Z5
N140 M30
"""
PROGRAMS = {"iso": ISO, "heidenhain": HEIDENHAIN, "sinumerik": SINUMERIK}
WORK_OFFSET = (400.0, 350.0, 300.0)
STEP = 0.05  # mm between samples


@pytest.fixture(scope="module")
def source() -> ErrorSource:
    return ErrorSource.from_machine_file(str(ROOT / "samples" / "machines" / "hr5b.toml"))


def _path(text: str, dialect: str) -> np.ndarray:
    interpret, _ = dialect_tools(dialect)
    _, blocks = parse_program(io.BytesIO(text.encode("latin-1")), "part", dialect)
    return sample_events(interpret(blocks, file="part", strict=True), STEP).points


def _compensated(text: str, dialect: str, source: ErrorSource) -> str:
    """Compensated, every warning refused but the Heidenhain TOOL CALL's: ncpp is not told the
    TNC's tool table, so it places the tool at length 0, as the ISO and Sinumerik parts say."""
    out, said = io.BytesIO(), io.StringIO()
    process(io.BytesIO(text.encode("latin-1")), out, file="part", source=source,
            warnings=Warnings(stream=said), dialect=dialect, offsets=WorkOffsets.at(WORK_OFFSET))  # fmt: skip
    lines = said.getvalue().splitlines()
    if dialect == "heidenhain":
        assert len(lines) == 1 and lines[0].startswith(
            "part:2:4: warning: TOOL CALL applies a tool length"
        ), lines
    else:
        assert lines == []
    return out.getvalue().decode("latin-1")


def test_the_nominal_paths_agree() -> None:
    paths = {d: _path(t, d) for d, t in PROGRAMS.items()}
    for dialect in ("heidenhain", "sinumerik"):
        assert paths[dialect].shape == paths["iso"].shape
        assert np.abs(paths[dialect] - paths["iso"]).max() < 1e-9


def test_the_compensated_paths_agree_within_a_tenth_of_a_micron(source: ErrorSource) -> None:
    outputs = {d: _compensated(t, d, source) for d, t in PROGRAMS.items()}
    paths = {d: _path(outputs[d], d) for d in PROGRAMS}
    nominal = _path(ISO, "iso")
    # compensation really moved the path (by micrometres), so agreement is not trivial
    assert paths["iso"].shape != nominal.shape or np.abs(paths["iso"] - nominal).max() > 0.005
    for dialect in ("heidenhain", "sinumerik"):
        assert paths[dialect].shape == paths["iso"].shape, (dialect, outputs[dialect])
        deviation = np.abs(paths[dialect] - paths["iso"]).max()
        assert deviation < 1e-4, (dialect, deviation)


def test_headers_in_each_dialects_comment_syntax(source: ErrorSource) -> None:
    heidenhain = _compensated(HEIDENHAIN, "heidenhain", source).splitlines()
    assert heidenhain[0] == "0  BEGIN PGM PART MM"
    assert heidenhain[1].startswith("1 ; ncpp compensated for hr5b.toml")
    numbers = [int(line.split()[0]) for line in heidenhain]
    assert numbers == list(range(len(heidenhain)))  # renumbered consistently, inserted blocks included
    assert heidenhain[-1].split(None, 1)[1] == "END PGM PART MM"
    assert any(line.split()[1] == "CC" for line in heidenhain[2:])
    sinumerik = _compensated(SINUMERIK, "sinumerik", source).splitlines()
    assert sinumerik[0].startswith("; ncpp compensated for hr5b.toml")
    assert any("CR=" in line for line in sinumerik)


@pytest.mark.parametrize("dialect", ["heidenhain", "sinumerik"])
def test_refuses_to_compensate_twice(dialect: str, source: ErrorSource) -> None:
    from ncpp.errors import NcppError

    once = _compensated(PROGRAMS[dialect], dialect, source)
    with pytest.raises(NcppError, match="already compensated"):
        _compensated(once, dialect, source)


@pytest.mark.parametrize("dialect", ["heidenhain", "sinumerik"])
def test_no_passes_is_byte_identical(dialect: str) -> None:
    out = io.BytesIO()
    process(io.BytesIO(PROGRAMS[dialect].encode()), out, file="part")
    assert out.getvalue() == PROGRAMS[dialect].encode()
