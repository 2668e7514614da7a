"""Where the control holds a program's zeros when the program starts.

A program says its moves in program coordinates; the machine's errors are a
function of machine position.  The control adds the work offset of the
coordinate system in effect (G54-G59.3), the G92 offset and the tool length;
the program itself does not say them (unless it sets them with G10 L2/L20 or
G92) and takes the tool lengths from the control's tool table (`tools.py`).
`WorkOffsets` is what the control holds, as the operator set it: the
interpreter starts from it, so every event's `Context.offset` is the true
machine minus program position and G53 moves land where the control puts
them.

    WorkOffsets.of({"G54": (400, 350, 300), "G55": (600, 350, 300)})
    WorkOffsets.at((400, 350, 300))                 # G54 only
    WorkOffsets.from_var_file("linuxcnc.var")      # LinuxCNC's parameter file
    WorkOffsets.given({}, "linuxcnc.var", tool_table="tool.tbl")  # and its tool table
    WorkOffsets.of({"G54.1P3": (100, 50, 0)})      # a Fanuc additional work offset

Positions are machine mm (X, Y, Z).

The additional work offsets of Fanuc and Haas controls come after rs274ngc's nine systems, as
numbers `ADDITIONAL + n`: Fanuc's `G54.1 P1`-`P48` (0i-MF / 16i operator's manuals, "Additional
workpiece coordinate systems"; their zeros are the system variables #7001-#7003 for P1, 20 per
offset: "System variables for additional workpiece coordinate systems") and Haas's `G154 P1`-`P99`
(Mill Operator's Manual, "G154 Select Work Coordinates P1-P99" and the "Macros" variable table:
#14001-#14003 for P1, 20 per offset, and for P1-P20 also #7001-#7003 on, its G110-G129).  Offset
n is one place on the control whichever name selects it: `G54.1P3` and `G154P3` name the same
number.  A parameter file gives them by those variable numbers, which LinuxCNC's never holds.
"""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, replace
from pathlib import Path

from ncpp.errors import Location, NcppError, quoted
from ncpp.fileio import read_small
from ncpp.motion.tools import ToolTable

Vector = tuple[float, float, float]
SYSTEMS = ("G54", "G55", "G56", "G57", "G58", "G59", "G59.1", "G59.2", "G59.3")  # rs274ngc's numbers 1..9
UNIT_MM = {"mm": 1.0, "inch": 25.4}  # a parameter file's units (the INI's [TRAJ]LINEAR_UNITS) in mm

# LinuxCNC's parameter file (rs274ngc interp_parameter_def.hh): the systems' X at 5221 + 20 (n - 1),
# Y and Z after it, their rotation about Z (G10 L2 R, degrees) 9 after X; the system in effect at 5220; G92 at 5211-5213, applied when 5210 is 1;
# the G28 and G30 positions (machine coordinates) at 5161 and 5181.
_ACTIVE_SYSTEM, _G92_ON, _G92_X, _G28_X, _G30_X = 5220, 5210, 5211, 5161, 5181
_ROTATION_AFTER_X = 9


# Additional work offset n is system ADDITIONAL + n; Fanuc numbers P1-P48, Haas P1-P99
ADDITIONAL = 100
ADDITIONAL_CODES = {"G54.1": (54.1, 48), "G154": (154.0, 99)}  # name: the G code's value, the last n
HAAS_NUMBERED = [f"G{n}" for n in range(110, 130)]  # Haas's names of G154 P1-P20
# Their X in a Fanuc or Haas control's variables: n's at 7001 + 20 (n - 1) (Fanuc's P1-P48, Haas's
# P1-P20) and at 14001 + 20 (n - 1) (Haas's P1-P99)
_ADDITIONAL_X = ((7001, 48), (14001, 99))


def _system_x(number: int) -> int:
    return 5201 + 20 * number


@dataclass(frozen=True)
class WorkOffsets:
    """The zeros the control holds: per coordinate system (1..9: G54..G59.3) its
    machine position in mm, None when ncpp is not told it, and so per additional work
    offset (`additional`: 1, 2 ..., system ADDITIONAL + n); the system in effect at
    the program's start; the G92 offset in effect and the saved one (G92.3 applies it);
    the G28 and G30 positions; its tool table (None: not told, G43 applies length 0); per
    system its rotation about Z
    (LinuxCNC's G10 L2 R, degrees: `rotations`); and the folders it finds
    subroutine files in (LinuxCNC's [RS274NGC]SUBROUTINE_PATH: `o<name> call` of a
    subroutine the program does not define runs `name.ngc`; Fanuc's, Sinumerik's and
    Klartext's called programs too)."""

    systems: tuple[Vector | None, ...] = (None,) * 9
    active: int = 1
    g92: Vector = (0.0, 0.0, 0.0)
    g92_saved: Vector = (0.0, 0.0, 0.0)  # what G92.3 restores: LinuxCNC's #5211-#5213, applied or not
    g28: Vector = (0.0, 0.0, 0.0)
    g30: Vector = (0.0, 0.0, 0.0)
    tools: ToolTable | None = None
    subroutine_path: tuple[Path, ...] = ()
    unit_mm: float = 1.0  # the units the parameter file and tool table were read in (the header says them)
    additional: tuple[Vector | None, ...] = ()  # the additional work offsets 1, 2 ...: Fanuc, Haas
    rotations: tuple[float, ...] = (0.0,) * 9  # systems 1..9 turned about Z, degrees (LinuxCNC's #5230 ...)

    @classmethod
    def of(cls, zeros: Mapping[str, Vector], active: str = "G54") -> WorkOffsets:
        """From G word -> machine mm (`{"G54": (400, 350, 300)}`)."""
        return cls(active=system_number(active)).with_zeros(zeros)

    @classmethod
    def at(cls, zero: Vector) -> WorkOffsets:
        """G54's zero at `zero` (machine mm), the other systems not told."""
        return cls.of({"G54": zero})

    @classmethod
    def from_var_file(cls, path: str | Path, unit_mm: float = 1.0) -> WorkOffsets:
        """LinuxCNC's parameter file (`linuxcnc.var`: `number value` lines), its values in
        the machine's units (`[TRAJ]LINEAR_UNITS`: 25.4 mm for inch)."""
        entries = _var_entries(path)
        values = {number: value for number, (value, _) in entries.items()}
        systems = tuple(_from_var(values, _system_x(n), unit_mm) for n in range(1, 10))
        active = int(values.get(_ACTIVE_SYSTEM, 1.0) + 0.0001)
        zero = (0.0, 0.0, 0.0)
        saved = _from_var(values, _G92_X, unit_mm) or zero  # (G92.2 leaves them, G92.3 applies them)
        g92 = saved if values.get(_G92_ON) == 1.0 else zero
        homes = (_from_var(values, _G28_X, unit_mm) or zero, _from_var(values, _G30_X, unit_mm) or zero)
        lines = {number: line for number, (_, line) in entries.items()}
        additional = _additional_from_var(values, unit_mm, str(path), lines)
        rotations = tuple(values.get(_system_x(n) + _ROTATION_AFTER_X, 0.0) for n in range(1, 10))
        return cls(systems, active if 1 <= active <= 9 else 1, g92, saved, *homes, additional=additional,
                   rotations=rotations)  # fmt: skip

    @classmethod
    def given(
        cls,
        zeros: Mapping[str, Vector],
        var_file: str | Path | None = None,
        unit_mm: float = 1.0,
        tool_table: str | Path | None = None,
        subroutine_path: Sequence[str | Path] = (),
    ) -> WorkOffsets:
        """What a user says: a parameter file, if any (else G54 at the machine zero), with
        `zeros` (G word -> machine mm) over it, a tool table, if any (LinuxCNC's
        files are both in the machine's units, `unit_mm`), and subroutine folders.  Without a
        parameter file, the one system named is the one in effect at the start (`G55=` alone:
        the program runs in G55 until it selects another)."""
        base = cls.from_var_file(var_file, unit_mm) if var_file else AT_MACHINE_ZERO
        named = [system_number(name) for name in zeros]
        if not var_file and len(named) == 1 and named[0] <= len(base.systems):
            base = replace(base, active=named[0])
        tools = ToolTable.from_file(tool_table, unit_mm) if tool_table else None
        folders = tuple(Path(p) for p in subroutine_path)
        return replace(base.with_zeros(zeros), tools=tools, subroutine_path=folders, unit_mm=unit_mm)

    def with_zeros(self, zeros: Mapping[str, Vector]) -> WorkOffsets:
        """These systems' zeros replaced (the command line over a parameter file)."""
        systems, additional = list(self.systems), list(self.additional)
        for name, zero in zeros.items():
            number = system_number(name)
            if number > ADDITIONAL:
                additional.extend([None] * (number - ADDITIONAL - len(additional)))
                additional[number - ADDITIONAL - 1] = _vector(zero)
            else:
                systems[number - 1] = _vector(zero)
        return replace(self, systems=tuple(systems), additional=tuple(additional))

    def _zero_of(self, number: int) -> Vector | None:
        if number > ADDITIONAL:
            n = number - ADDITIONAL
            return self.additional[n - 1] if n <= len(self.additional) else None
        return self.systems[number - 1]

    def told(self, number: int) -> bool:
        """Whether system `number` (1..9, or ADDITIONAL + n) has a known zero."""
        return self._zero_of(number) is not None

    def zero(self, number: int) -> Vector:
        """System `number`'s zero in machine mm (the machine zero when not told)."""
        return self._zero_of(number) or (0.0, 0.0, 0.0)

    def told_additional(self) -> list[int]:
        """The numbers (ADDITIONAL + n) of the additional work offsets whose zeros are told."""
        return [ADDITIONAL + n for n, zero in enumerate(self.additional, 1) if zero is not None]

    def program_zero(self) -> Vector:
        """Machine mm of the program zero at the start: the system in effect plus G92
        (dialects with one program zero, Heidenhain's preset, Sinumerik's settable frame)."""
        zero = self.zero(self.active)
        return (zero[0] + self.g92[0], zero[1] + self.g92[1], zero[2] + self.g92[2])


LARGEST_ZERO_MM = 1e6


def parse_zero(text: str) -> tuple[str, Vector]:
    """`G55=600,350,300` -> ("G55", (600, 350, 300)); without `G5x=` it is G54's; `G54.1P3=`
    and `G154P3=` name an additional work offset."""
    name, _, numbers = text.rpartition("=")
    name = name.strip().upper() or "G54"
    system_number(name)
    try:
        values = tuple(float(v) for v in numbers.split(","))
    except ValueError:
        values = ()
    if len(values) != 3 or not all(math.isfinite(v) for v in values):
        raise ValueError(f"expected [G5x=]X,Y,Z in mm (three finite numbers), got {text!r}")
    check_zero(values)
    return name, values


def check_zero(values: Sequence[float]) -> None:
    """A work offset's zero within LARGEST_ZERO_MM of the machine zero, as a machine file's
    positions are (beyond, no machine reaches it, and its numbers would not fit a block)."""
    if any(abs(v) > LARGEST_ZERO_MM for v in values):
        raise ValueError(
            f"a work offset's zero must be within ±{LARGEST_ZERO_MM:,.0f} mm, not {tuple(values)}"
        )


def system_number(name: str) -> int:
    """`G55` -> 2 (rs274ngc's numbering, 1..9); `G54.1P3` or `G154 P3` -> ADDITIONAL + 3."""
    key = name.strip().upper()
    if key in SYSTEMS:
        return SYSTEMS.index(key) + 1
    code, p, n = key.replace(" ", "").partition("P")
    code = "G54.1" if code == "G54" else code  # (Fanuc's `G54 Pn` is `G54.1 Pn`)
    if p and code in ADDITIONAL_CODES and n.isdigit() and 1 <= int(n) <= ADDITIONAL_CODES[code][1]:
        return ADDITIONAL + int(n)
    if not p and code in HAAS_NUMBERED:  # (Haas's G110-G129 are G154 P1-P20)
        return ADDITIONAL + HAAS_NUMBERED.index(code) + 1
    raise ValueError(f"not a work coordinate system: {name!r} (one of {', '.join(SYSTEMS)}, "
                     f"G54.1P1-G54.1P48, G154P1-G154P99, G110-G129)")  # fmt: skip


def system_name(number: int, dialect: str = "fanuc") -> str:
    """2 -> `G55`; ADDITIONAL + 3 -> `G54.1 P3` (`G154 P3` in a Haas program)."""
    if number <= len(SYSTEMS):
        return SYSTEMS[number - 1]
    return f"{'G154' if dialect == 'haas' else 'G54.1'} P{number - ADDITIONAL}"


def read_var_file(path: str | Path) -> dict[int, float]:
    """`number value` lines; other lines are comments (as rs274ngc reads it)."""
    return {number: value for number, (value, _) in _var_entries(path).items()}


def _var_entries(path: str | Path) -> dict[int, tuple[float, int]]:
    """`read_var_file`'s values, each with the line that gives it (the last, as rs274ngc reads it)."""
    values: dict[int, tuple[float, int]] = {}
    try:
        text = read_small(path, "a parameter file").decode("latin-1")
    except OSError as err:
        raise NcppError(f"cannot read the parameter file: {err.strerror}", Location(str(path))) from None
    for n, line in enumerate(text.splitlines(), 1):
        fields = line.split()
        if len(fields) < 2 or not fields[0].isdigit():
            continue
        where = Location(str(path), n, line.index(fields[1]) + 1)
        try:
            value = float(fields[1])
        except ValueError:
            raise NcppError(f"parameter {fields[0]} has no number: {quoted(fields[1])}", where) from None
        if not math.isfinite(value):
            raise NcppError(f"parameter {fields[0]} is not a finite number: {quoted(fields[1])}", where)
        values[int(fields[0])] = (value, n)
    return values


def _from_var(values: Mapping[int, float], x: int, unit_mm: float) -> Vector | None:
    if not any(k in values for k in (x, x + 1, x + 2)):
        return None
    return (values.get(x, 0.0) * unit_mm, values.get(x + 1, 0.0) * unit_mm, values.get(x + 2, 0.0) * unit_mm)


def _additional_from_var(
    values: Mapping[int, float], unit_mm: float, path: str, lines: Mapping[int, int]
) -> tuple[Vector | None, ...]:
    """The additional work offsets a Fanuc or Haas parameter file gives (`_ADDITIONAL_X`); an offset
    given at both its numbers must be given the same (refused at the last line of the two)."""
    if not any(7001 <= k <= 15999 for k in values):
        return ()
    found: list[Vector | None] = [None] * max(count for _, count in _ADDITIONAL_X)
    for first, count in _ADDITIONAL_X:
        for n in range(1, count + 1):
            zero = _from_var(values, first + 20 * (n - 1), unit_mm)
            if zero is None:
                continue
            if found[n - 1] not in (None, zero):
                x, fanuc_x = first + 20 * (n - 1), 7001 + 20 * (n - 1)
                line = max(lines.get(k + d, 0) for k in (x, fanuc_x) for d in range(3))
                raise NcppError(f"parameters #{fanuc_x} and #{x} both give additional work offset "
                                f"P{n}, and differ", Location(path, line, 1))  # fmt: skip
            found[n - 1] = zero
    return tuple(found)


def _vector(zero) -> Vector:
    x, y, z = (float(v) for v in zero)
    return (x, y, z)


AT_MACHINE_ZERO = WorkOffsets.at((0.0, 0.0, 0.0))  # nobody said otherwise: program zero = machine zero
