"""Helpers for the placement tests: a machine whose error is known in closed form, ncpp's
compensation for it, and LinuxCNC's rs274 (7 decimals) as the judge of where the tool lands."""

from __future__ import annotations

import io
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ncpp.errors import Warnings
from ncpp.motion.offsets import WorkOffsets
from ncpp.pipeline import ErrorSource, process
from tests import rs274 as oracle
from tests.conftest import SHARED

PATHCHECK = SHARED / "tools" / "pathcheck"
SCALE = np.array([5e-5, -4e-5, 3e-5])  # each axis's scale error: the tool lands at M * (1 + SCALE)
LIMITS = {"X": (-5.0, 800.0), "Y": (-5.0, 700.0), "Z": (-5.0, 700.0)}
CALL = re.compile(r"^\s*\d+\s+N\S*\s+([A-Z_0-9]+)\((.*)\)\s*$")


@dataclass(frozen=True)
class ScaleMap:
    """The error map of a machine with a linear scale error per axis and nothing else."""

    def deviation(self, P, direction=None, tool_offset=None):
        return np.asarray(P, dtype=float) * SCALE


def var_file(
    folder: Path,
    g54=(400.0, 350.0, 300.0),
    g28=(0.0, 0.0, 0.0),
    g30=(0.0, 0.0, 0.0),
    g55=(100.0, 120.0, 140.0),
) -> Path:
    """A LinuxCNC parameter file (inches: the stand-alone rs274's machine units) with G54's and
    G55's zeros and the G28 and G30 positions, in machine mm."""
    values = {5220: 1.0}
    for first, vector in ((5161, g28), (5181, g30), (5221, g54), (5241, g55)):
        values.update({first + i: v / 25.4 for i, v in enumerate(vector)})
    path = folder / "placement.var"
    path.write_text("".join(f"{k} {v!r}\n" for k, v in sorted(values.items())))
    return path


def compensate(data: bytes, var: Path, limits=LIMITS) -> tuple[bytes, str]:
    """(output, warnings) of `ncpp compensate` of `data` for ScaleMap, placed by `var`."""
    source = ErrorSource(ScaleMap(), "scale", "0" * 16, 0.5, dict(limits))
    said = io.StringIO()
    out = io.BytesIO()
    offsets = WorkOffsets.given({}, var_file=var, unit_mm=25.4)
    process(
        io.BytesIO(data), out, file="t.ngc", source=source, warnings=Warnings(stream=said), offsets=offsets
    )
    return out.getvalue(), said.getvalue()


def rs274(program: Path, var: Path) -> list[tuple[str, tuple[float, ...]]]:
    """rs274's canonical calls (name, numbers) of a program it must accept, 7 decimals."""
    proc = oracle.run(program, var_file=var, digits=7)
    messages = oracle.messages(proc)
    assert proc.returncode == 0 and not messages, f"rs274 refused {program.name}: {messages[:3]}"
    calls = []
    for line in proc.stdout.splitlines():
        found = CALL.match(line)
        if found:
            numbers = tuple(float(v) for v in re.findall(r"-?\d+(?:\.\d+)?", found.group(2)))
            calls.append((found.group(1), numbers))
    return calls


def machine_moves(calls) -> list[tuple[str, np.ndarray]]:
    """(call name, machine position in mm of its X Y Z end, its A B C) of each straight move, offsets
    followed as rs274 prints them (mm programs, no tool length)."""
    g5x, g92, moves = np.zeros(3), np.zeros(3), []
    for name, numbers in calls:
        if name == "SET_G5X_OFFSET":
            g5x = np.array(numbers[1:4])
        elif name == "SET_G92_OFFSET":
            g92 = np.array(numbers[:3])
        elif name in ("STRAIGHT_TRAVERSE", "STRAIGHT_FEED"):
            moves.append((name, np.concatenate([np.array(numbers[:3]) + g5x + g92, numbers[3:6]])))
    return moves


def landed(moves) -> list[tuple[str, np.ndarray]]:
    """Where the tool lands on the ScaleMap machine for each commanded move."""
    return [(name, np.concatenate([m[:3] * (1 + SCALE), m[3:]])) for name, m in moves]


def pathcheck(original: Path, rewritten: Path, var: Path, *options: str) -> str:
    """pathcheck's verdict line; fails the test when it fails."""
    proc = subprocess.run([str(PATHCHECK), str(original), str(rewritten), "--var-file", str(var), *options],
                          capture_output=True, text=True, timeout=300)  # fmt: skip
    assert proc.returncode == 0, proc.stdout + proc.stderr
    return proc.stdout


def run_both(tmp_path: Path, program: str, var: Path, limits=LIMITS):
    """Compensate `program`; rs274 on both: (output text, warnings, nominal moves, landed moves)."""
    original = tmp_path / "original.ngc"
    original.write_text(program)
    out, said = compensate(program.encode(), var, limits)
    rewritten = tmp_path / "rewritten.ngc"
    rewritten.write_bytes(out)
    nominal = machine_moves(rs274(original, var))
    actual = landed(machine_moves(rs274(rewritten, var)))
    return out.decode(), said, nominal, actual


@dataclass(frozen=True)
class BowMap:
    """A machine whose X error bows along Y (BOW mm per mm² from Y 350): lines along Y are split."""

    def deviation(self, P, direction=None, tool_offset=None):
        P = np.asarray(P, dtype=float)
        out = np.zeros_like(P)
        out[:, 0] = BOW * (P[:, 1] - 350.0) ** 2
        return out


BOW = 1e-5


def bowed(moves) -> list[tuple[str, np.ndarray]]:
    """Where the tool lands on the BowMap machine for each commanded move."""
    out = []
    for name, m in moves:
        landed_at = m.copy()
        landed_at[0] += BOW * (m[1] - 350.0) ** 2
        out.append((name, landed_at))
    return out


def compensate_with(data: bytes, model, var: Path, rotary: bool, file: str = "t.ngc") -> tuple[bytes, str]:
    """`compensate` with another map, and the machine file's rotary key (`file`: its name tells the dialect)."""
    source = ErrorSource(model, "model", "0" * 16, 0.5, dict(LIMITS), rotary)
    said, out = io.StringIO(), io.BytesIO()
    offsets = WorkOffsets.given({}, var_file=var, unit_mm=25.4)
    process(io.BytesIO(data), out, file=file, source=source, warnings=Warnings(stream=said), offsets=offsets)
    return out.getvalue(), said.getvalue()
