"""Helpers for the write-back tests: compensate a program file with ncpp's CLI entry point."""

from __future__ import annotations

import io
import os
from pathlib import Path

import numpy as np

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


def machine_file(name: str, errors: str, travel_mm: float = 1000.0) -> str:
    """A machine file of X Y Z with travels of +-`travel_mm` at zero offsets, named `name`, with
    `errors` (its [errors...] and [squareness] tables): the closed-form machines these tests judge by."""
    limits = "".join(f"{axis} = [{-travel_mm!r}, {travel_mm!r}]\n" for axis in "XYZ")
    head = (
        f'[machine]\nname = "{name}"\nchain = "XYFZ"\n[offsets]\ntool = [0.0, 0.0, 0.0]\nwork = [0.0, 0.0, 0.0]\n'
        f"[limits]\n{limits}"
    )
    return head + errors


def linear_errors(**per_mm: float) -> str:
    """[errors...] tables of components linear in their axis's position, µm per mm (`EXZ=0.1`:
    Z travelling carries X by 0.1 µm per mm of z), for `machine_file`."""
    return "".join(
        f'\n[errors.{name}]\nkind = "polynomial"\ncoefficients_um = [0.0, {slope!r}]\n'
        for name, slope in per_mm.items()
    )


def linearly_reached(command: np.ndarray, **per_mm: float) -> np.ndarray:
    """Where a machine of `linear_errors(**per_mm)` puts the tool for commands (n,3), machine mm: each
    axis off by the slopes times the positions of the axes that carry it (worked out by hand)."""
    reached = command.copy()
    for name, slope in per_mm.items():
        reached[:, "XYZ".index(name[1])] += 1e-3 * slope * command[:, "XYZ".index(name[2])]
    return reached


# A machine whose X is off by -50 µm/m · Y (a squareness), and a short program per dialect
SQUARE = machine_file(
    "square",
    """
[squareness]
C0Y_urad = 50.0
""",
)
PROGRAMS = {
    "iso": "%\nG21 G90\nG0 X10 Y10 Z5\nG1 Y200 F500\nM2\n%\n",
    "heidenhain": "0 BEGIN PGM T MM\n1 L X+10 Y+10 Z+5 FMAX\n2 L Y+200 F500\n3 END PGM T MM\n",
    "sinumerik": "%_N_T_MPF\nG90 G71\nG0 X10 Y10 Z5\nG1 Y200 F500\nM30\n",
}


def misses(reached: np.ndarray, wanted: list[tuple[float, ...]]) -> np.ndarray:
    """For each wanted point, how far (mm) the nearest of the points `reached` (n,3) is from it."""
    return np.array([np.min(np.linalg.norm(reached - np.array(point), axis=1)) for point in wanted])
