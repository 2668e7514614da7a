"""A program ncpp compensated is refused a second compensation (and the LinuxCNC filter
loads it as it is), whatever its case, however many comments stand before the header,
in every dialect's comments."""

from __future__ import annotations

import io
import os

import pytest

from ncpp.errors import NcppError, Warnings
from ncpp.integrations.linuxcnc import already_compensated
from ncpp.pipeline import ErrorSource, process
from tests.writeback.conftest import PROGRAMS
from tests.writeback.conftest import SQUARE as MACHINE

QUIET = Warnings(stream=open(os.devnull, "w"))


def compensated(text: str, source: ErrorSource, dialect: str) -> str:
    out = io.BytesIO()
    process(io.BytesIO(text.encode()), out, source=source, dialect=dialect, warnings=QUIET)
    return out.getvalue().decode()


def with_comments(text: str, dialect: str, count: int = 29) -> str:
    """`count` comment lines before the header (after `%`, BEGIN PGM or the program's name)."""
    first, rest = text.split("\n", 1)
    comment = {"iso": "(a note)", "heidenhain": "; a note", "sinumerik": "; a note"}[dialect]
    return first + "\n" + "".join(comment + "\n" for _ in range(count)) + rest


@pytest.fixture(scope="module")
def source(tmp_path_factory):
    path = tmp_path_factory.mktemp("machine") / "square.toml"
    path.write_text(MACHINE)
    return ErrorSource.from_machine_file(str(path))


@pytest.mark.parametrize("dialect", list(PROGRAMS))
@pytest.mark.parametrize("change", ["as written", "upper case", "29 comments before", "500 comments before"])
def test_compensated_program_refused(source, tmp_path, dialect, change):
    text = compensated(PROGRAMS[dialect], source, dialect)
    assert text != PROGRAMS[dialect]
    if change == "upper case":
        text = text.upper()
    elif change.endswith("comments before"):
        text = with_comments(text, dialect, int(change.split()[0]))
    with pytest.raises(NcppError, match="already compensated"):
        compensated(text, source, dialect)
    path = tmp_path / {"iso": "p.ngc", "heidenhain": "p.h", "sinumerik": "p.mpf"}[dialect]
    path.write_text(text)
    assert already_compensated(str(path))


@pytest.mark.parametrize("dialect", list(PROGRAMS))
def test_program_not_compensated_is_compensated(source, tmp_path, dialect):
    text = with_comments(PROGRAMS[dialect], dialect, 40)
    assert compensated(text, source, dialect) != text
    path = tmp_path / {"iso": "p.ngc", "heidenhain": "p.h", "sinumerik": "p.mpf"}[dialect]
    path.write_text(text)
    assert not already_compensated(str(path))
