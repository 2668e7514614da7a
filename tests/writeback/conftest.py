"""Helpers for the write-back tests: compensate a program file with ncpp's CLI entry point."""

from __future__ import annotations

import io
import os
from pathlib import Path

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process


def compensate_file(program: Path, machine_toml: str, folder: Path, offsets: WorkOffsets | None = None,
                    warnings: Warnings | None = None, **options) -> Path:  # fmt: skip
    """`program` compensated for the machine file `machine_toml` (its text), written beside it."""
    machine = folder / "machine.toml"
    machine.write_text(machine_toml)
    out = io.BytesIO()
    with open(program, "rb") as stream:
        process(stream, out, file=str(program), source=ErrorSource.from_machine_file(str(machine)),
                warnings=warnings or Warnings(stream=open(os.devnull, "w")), offsets=offsets, **options)  # fmt: skip
    output = program.with_name(program.stem + "-compensated" + program.suffix)
    output.write_bytes(out.getvalue())
    return output
