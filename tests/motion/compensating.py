"""Compensating a small program text on the HR5B sample machine, as the cycle and flow tests do."""

from __future__ import annotations

import functools
import io

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests.conftest import ROOT

PLACED = WorkOffsets.at((400.0, 350.0, 350.0))  # G54 in the middle of HR5B's travel


@functools.cache
def hr5b() -> ErrorSource:
    return ErrorSource.from_machine_file(str(ROOT / "samples/machines/hr5b.toml"))


def compensate(text: str, file: str, strict: bool = False, dialect: str | None = None) -> tuple[str, str]:
    """(the compensated program, the warnings) of `text`, read as `file` (in `dialect`: None, as
    its name and content tell)."""
    warned, out = io.StringIO(), io.BytesIO()
    process(
        io.BytesIO(text.encode()),
        out,
        file=file,
        source=hr5b(),
        warnings=Warnings(stream=warned, strict=strict),
        offsets=PLACED,
        dialect=dialect,
    )
    return out.getvalue().decode(), warned.getvalue()
