"""What the compensated program's header says about where it was compensated for.

A compensated program is right only where it was placed: at the work offsets the
control held, with the tool lengths of its tool table, in the units the files were
read in.  The header says them after its first line (`pipeline.header_text`), each
line a comment the dialect's writer writes (ISO `( )`, Heidenhain and Sinumerik `;`),
so a person can check them against the control before running the program.  The
lines hold no parentheses (rs274 allows no nesting) and stay short (rs274 reads
lines of up to 255 characters).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

from ncpp.motion.offsets import WorkOffsets, system_name
from ncpp.program.dialects import FAMILY

SYSTEMS_PER_LINE = 3  # work offsets said on one header line


def placement_lines(offsets: WorkOffsets, dialect: str) -> list[str]:
    """The header's lines after its first: zeros (machine mm), G92, rotations, tool table, units."""
    if FAMILY.get(dialect, dialect) == "iso":
        lines = _systems(offsets, dialect)
    else:  # one program zero: the system in effect with G92 (`WorkOffsets.program_zero`)
        lines = [f"ncpp program zero at {_point(offsets.program_zero())} machine mm"]
    if any(offsets.g92):
        lines.append(f"ncpp G92/G52 offset {_point(offsets.g92)} mm, from the parameter file")
    turned = [
        f"{system_name(n, dialect)} R{angle:g}" for n, angle in enumerate(offsets.rotations, 1) if angle
    ]
    if turned and dialect == "iso":  # (LinuxCNC's G10 L2 R; a Fanuc file's #5230 is no rotation)
        lines.append(f"ncpp systems turned about Z, degrees, from the parameter file: {', '.join(turned)}")
    lines.append(_tool_table(offsets))
    return lines


def _systems(offsets: WorkOffsets, dialect: str) -> list[str]:
    """The work offsets the control holds (the one in effect first, the additional ones of a Fanuc
    or Haas control last), a few to a line."""
    told = [*range(1, 10), *offsets.told_additional()]
    numbers = [offsets.active] + [n for n in told if n != offsets.active and offsets.told(n)]
    said = [
        f"{system_name(n, dialect)} {_point(offsets.zero(n))}{'' if offsets.told(n) else ' not given'}"
        for n in numbers
    ]
    lines = [", ".join(said[k : k + SYSTEMS_PER_LINE]) for k in range(0, len(said), SYSTEMS_PER_LINE)]
    active = system_name(offsets.active, dialect)
    lines[0] = f"ncpp work offsets in machine mm, {active} in effect at the start: {lines[0]}"
    return [lines[0]] + [f"ncpp work offsets: {line}" for line in lines[1:]]


def _tool_table(offsets: WorkOffsets) -> str:
    """The tool table's file and hash, the units its lengths and the parameter file's zeros
    were read in, and the units the program starts in."""
    units = "inch" if offsets.unit_mm == 25.4 else "mm"
    tools = offsets.tools
    if tools is None:
        table = "no tool table, tool lengths 0"
    else:
        table = f"tool table {Path(tools.source).name} sha256:{_digest(tools.source)}"
    return f"ncpp {table}, files read in {units}, program units mm until it says otherwise"


def _digest(path: str) -> str:
    """The file's sha256, its first 16 hex digits ('unknown' if it cannot be read again)."""
    try:
        return hashlib.sha256(Path(path).read_bytes()).hexdigest()[:16]
    except OSError:
        return "unknown"


def _point(p: tuple[float, float, float]) -> str:
    return " ".join(f"{axis}{_mm(v)}" for axis, v in zip("XYZ", p))


def _mm(value: float) -> str:
    """`value` with up to 4 decimals, trailing zeros dropped (`400`, `-12.5`)."""
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return "0" if text in ("", "-0") else text
