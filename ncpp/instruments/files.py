"""Measurement files of the contract (shared/spec/measurement-files.md).

Every instrument writes the same common form::

    # instrument: laser            metadata, `# key: value`, keys lower case
    # axis: X
    target_mm,run,direction,deviation_um      one CSV header row
    0,1,+,0.0                                 comma separated rows

UTF-8, blank lines and CRLF allowed, trailing newline optional.  A file is read
into one `Measurement`: the instrument name, the other metadata as strings
(unknown keys kept), and the columns as numpy arrays (floats; `run` as ints;
`direction` as strings).  Typed views (`axis`, `fixed`, `center_mm`, ...)
interpret the metadata on demand, so that what was read is written back
unchanged: ``read_measurement(write_measurement(m, p)) == m``.

Instruments and columns (`?` marks an optional column):

========== ===================================================== ==========================
instrument columns                                                metadata needed
========== ===================================================== ==========================
laser      target_mm, run, direction(+/-), deviation_um |         quantity (position,
           deviation_urad (angles: pitch, yaw, roll)              straightness_x|_y|_z, ...)
comparator target_mm, run, direction(+/-), linear_um,             (axis, transverse)
           transverse_um?
level      position_mm, inclination_um_per_m                      (axis, quantity roll|pitch)
ballbar    direction(CW/CCW), angle_deg in [0,360), deviation_um  radius_mm (plane, default XY)
grid       direction(CW/CCW)?, s_mm, <p>_mm, <q>_mm,               plane (default XY)
           dev_<p>_um, dev_<q>_um
cutting    angle_deg in [0,360), radius_dev_um                    radius_mm (plane)
========== ===================================================== ==========================

Our own two, in the same common form:

* ``instrument: grid`` -- a grid encoder (Heidenhain KGM type) path test in a
  plane.  `<p>`, `<q>` are the plane's first and second axes in lower case
  (XY: ``x_mm,y_mm,dev_x_um,dev_y_um``; YZ: ``y_mm,z_mm,...``; ZX:
  ``z_mm,x_mm,...``).  Each row is a nominal path point (command coordinates,
  mm), its path length `s_mm` from the start, and the measured 2-D deviation
  actual minus nominal (µm).  A circular test adds ``radius_mm`` and
  ``center_mm`` and may carry a `direction` column (CW/CCW); it is then also
  evaluated to ISO 230-4.
* ``instrument: cutting`` -- a circle cut in the plane and measured on a CMM:
  `angle_deg` of the probed point about the circle centre (from the plane's
  first axis towards its second) and `radius_dev_um`, measured radius minus
  nominal radius.  Metadata ``radius_mm``, ``plane``, optionally ``center_mm``,
  ``feed_mm_min``, ``direction`` (CW/CCW of the cut) and ``tool_diameter_mm``.

A metadata value is kept verbatim (stripped).  The typed views ignore a
trailing parenthesised remark, as in the contract's own examples
(``# quantity: position   (position | pitch ...)``); the header row likewise.
"""

from __future__ import annotations

import math
import os
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from ncpp.errors import Location, NcppError, quoted
from ncpp.fileio import read_small, write_text_atomic

PLANES = {"XY": ("X", "Y"), "YZ": ("Y", "Z"), "ZX": ("Z", "X")}
LASER_QUANTITIES = ("position", "straightness_x", "straightness_y", "straightness_z", "pitch", "yaw", "roll")
ANGULAR_QUANTITIES = ("pitch", "yaw", "roll")
LEVEL_QUANTITIES = ("roll", "pitch")

# Runs of a positioning test: ISO 230-2 asks for 5; the diagnosis simulates every run up to the file's last
MAX_RUNS = 1000
# Targets are matched, and readings evaluated, to 1 µm: beyond 2**53 µm a double cannot hold 1 µm.
MAX_LENGTH_UM = 2.0**53
# An angle past half a turn is no angular error: a rotation vector beyond π names a smaller turn.
MAX_ANGLE_URAD = math.pi * 1e6
_RANGES = {  # column name ending: (largest magnitude, unit, what lies beyond)
    "_mm": (MAX_LENGTH_UM / 1e3, "mm", "a number no longer resolves 1 µm"),
    "_um": (MAX_LENGTH_UM, "µm", "a number no longer resolves 1 µm"),
    "_urad": (MAX_ANGLE_URAD, "µrad", "(half a turn) a reading is no angular error"),
    "_um_per_m": (MAX_ANGLE_URAD, "µm/m", "(half a turn) a reading is no angular error"),
}

_KEY_LINE = re.compile(r"#\s*([A-Za-z][A-Za-z0-9_]*)\s*:(.*)$")
_REMARK = re.compile(r"\s+\(.*\)\s*$")


@dataclass(frozen=True, slots=True)
class Schema:
    """Which columns an instrument's file has; `one_of` groups need exactly one member."""

    required: tuple[str, ...]
    optional: tuple[str, ...] = ()
    one_of: tuple[str, ...] = ()
    directions: tuple[str, ...] = ()  # allowed values of the `direction` column


def _grid_columns(plane: str) -> tuple[str, ...]:
    p, q = (a.lower() for a in PLANES[plane])
    return ("s_mm", f"{p}_mm", f"{q}_mm", f"dev_{p}_um", f"dev_{q}_um")


def schema_for(instrument: str, meta: Mapping[str, str]) -> Schema | None:
    """The column schema of `instrument` (None if ncpp does not know it)."""
    if instrument == "laser":
        return Schema(
            ("target_mm", "run", "direction"),
            one_of=("deviation_um", "deviation_urad"),
            directions=("+", "-"),
        )
    if instrument == "comparator":
        return Schema(
            ("target_mm", "run", "direction", "linear_um"), ("transverse_um",), directions=("+", "-")
        )
    if instrument == "level":
        return Schema(("position_mm", "inclination_um_per_m"))
    if instrument == "ballbar":
        return Schema(("direction", "angle_deg", "deviation_um"), directions=("CW", "CCW"))
    if instrument == "grid":
        return Schema(_grid_columns(_plane_of(meta)), ("direction",), directions=("CW", "CCW"))
    if instrument == "cutting":
        return Schema(("angle_deg", "radius_dev_um"))
    return None


def _plane_of(meta: Mapping[str, str]) -> str:
    plane = strip_remark(meta.get("plane", "XY")).upper()
    return plane if plane in PLANES else "XY"


def strip_remark(value: str) -> str:
    """A metadata value without a trailing `(remark)`."""
    return _REMARK.sub("", value).strip()


@dataclass(frozen=True, eq=False)
class Measurement:
    """One measurement file: instrument, metadata (strings) and columns (numpy arrays).

    `columns` keeps the file's column order.  `source` names the file it came
    from (for messages); it takes no part in equality.
    """

    instrument: str
    meta: Mapping[str, str]
    columns: Mapping[str, np.ndarray]
    source: str = field(default="<memory>", compare=False)
    meta_lines: Mapping[str, int] = field(default_factory=dict, compare=False)  # key -> its line in the file

    def __eq__(self, other: object) -> bool:
        if not isinstance(other, Measurement):
            return NotImplemented
        return (
            self.instrument == other.instrument
            and dict(self.meta) == dict(other.meta)
            and list(self.columns) == list(other.columns)
            and all(np.array_equal(self.columns[k], other.columns[k]) for k in self.columns)
        )

    __hash__ = None  # type: ignore[assignment]

    def at(self, key: str = "instrument") -> Location:
        """Where metadata `key` is written in the file (its instrument line: what a whole-file
        problem points at), else its first line."""
        return Location(self.source, self.meta_lines.get(key, 1), 1)

    def __len__(self) -> int:
        return len(next(iter(self.columns.values()))) if self.columns else 0

    def __getitem__(self, column: str) -> np.ndarray:
        return self.columns[column]

    # -- typed views of the metadata -------------------------------------
    def text(self, key: str, default: str | None = None) -> str | None:
        """Metadata value without a trailing remark, or `default`."""
        return strip_remark(self.meta[key]) if key in self.meta else default

    def number(self, key: str, default: float | None = None) -> float | None:
        value = self.text(key)
        return default if value is None else _meta_float(self, key, value)

    def vector(self, key: str) -> np.ndarray | None:
        """`x,y,z` metadata (e.g. `offset_mm`, `center_mm`) as a 3-vector."""
        value = self.text(key)
        if value is None:
            return None
        parts = [p for p in re.split(r"[,\s]+", value) if p]
        if len(parts) != 3:
            raise NcppError(f"{key} needs three numbers x,y,z, got {quoted(value)}", self.at(key))
        return np.array([_meta_float(self, key, p) for p in parts])

    @property
    def axis(self) -> str | None:
        value = self.text("axis")
        return value.upper() if value else None

    @property
    def quantity(self) -> str:
        """Laser/level quantity; a laser file without one measures position."""
        value = self.text("quantity")
        if value:
            return value.lower()
        return "position" if self.instrument != "level" else "roll"

    @property
    def plane(self) -> str:
        return _plane_of(self.meta)

    @property
    def plane_axes(self) -> tuple[str, str]:
        return PLANES[self.plane]

    @property
    def radius_mm(self) -> float | None:
        return self.number("radius_mm")

    @property
    def feed_mm_min(self) -> float | None:
        return self.number("feed_mm_min")

    @property
    def center_mm(self) -> np.ndarray | None:
        return self.vector("center_mm")

    @property
    def offset_mm(self) -> np.ndarray:
        vec = self.vector("offset_mm")
        return np.zeros(3) if vec is None else vec

    @property
    def fixed(self) -> dict[str, float]:
        """`fixed: X=0 Y=-200 Z=350` as {'X': 0.0, 'Y': -200.0, 'Z': 350.0}."""
        value = self.text("fixed") or ""
        out: dict[str, float] = {}
        for word in re.split(r"[,\s]+", value.strip()):
            if not word:
                continue
            name, sep, number = word.partition("=")
            if not sep or not name.isalpha():
                raise NcppError(f"fixed: expected AXIS=value words, got {quoted(word)}", self.at("fixed"))
            out[name.upper()] = _meta_float(self, "fixed", number)
        return out

    @property
    def deviation_column(self) -> str:
        """The column holding the laser reading (`deviation_um` or `deviation_urad`)."""
        return "deviation_urad" if "deviation_urad" in self.columns else "deviation_um"


def _meta_float(m: Measurement, key: str, text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise NcppError(f"{key}: {quoted(text)} is not a number", m.at(key)) from None
    if not math.isfinite(value):
        raise NcppError(f"{key}: {quoted(text)} is not a finite number", m.at(key))
    return value


# -- reading -----------------------------------------------------------------


def read_measurement(path: str | os.PathLike[str]) -> Measurement:
    """Read a measurement file; a malformed file raises NcppError at its line."""
    name = os.fspath(path)
    try:
        raw = read_small(name, "a measurement file")
    except OSError as err:
        raise NcppError(f"cannot read: {err.strerror or err}", Location(name)) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as err:
        line_start = raw.rfind(b"\n", 0, err.start) + 1
        col = len(raw[line_start : err.start].decode("utf-8", "replace")) + 1
        raise NcppError("not UTF-8 text", Location(name, raw[: err.start].count(b"\n") + 1, col)) from None
    return parse_measurement(text, name)


def parse_measurement(text: str, source: str = "<string>") -> Measurement:
    """Parse the text of a measurement file (see the module docstring)."""
    meta: dict[str, str] = {}
    meta_lines: dict[str, int] = {}
    lines = text.splitlines()
    header_at = None
    for number, line in enumerate(lines, 1):
        stripped = line.strip()
        if not stripped:
            continue
        if stripped.startswith("#"):
            match = _KEY_LINE.match(stripped)
            if match:  # other '#' lines are free comments
                meta[match.group(1).lower()] = match.group(2).strip()
                meta_lines[match.group(1).lower()] = number
            continue
        header_at = number
        break
    instrument = strip_remark(meta.pop("instrument", "")).lower()
    if not instrument:
        raise NcppError("missing '# instrument: ...' metadata line", Location(source, header_at or 1, 1))
    if header_at is None:
        raise NcppError("no CSV header row", Location(source, len(lines) or 1, 1))
    header_line = _REMARK.sub("", lines[header_at - 1])
    names = [cell.strip() for cell in header_line.split(",")]
    schema = schema_for(instrument, meta)
    _check_header(names, schema, instrument, source, header_at, header_line)
    cells: list[list[str]] = []
    where: list[int] = []
    for number in range(header_at + 1, len(lines) + 1):
        line = lines[number - 1]
        if not line.strip() or line.lstrip().startswith("#"):
            continue
        row = line.split(",")
        if len(row) != len(names):
            raise NcppError(
                f"expected {len(names)} columns ({','.join(names)}), found {len(row)}",
                Location(source, number, 1),
            )
        cells.append(row)
        where.append(number)
    columns = {
        name: _convert_column(
            name, [row[i] for row in cells], [lines[n - 1] for n in where], where, i, schema, source
        )
        for i, name in enumerate(names)
    }
    measurement = Measurement(instrument, meta, columns, source, meta_lines)
    _check_meta(measurement, header_at, meta_lines)
    return measurement


def _check_header(
    names: list[str], schema: Schema | None, instrument: str, source: str, line: int, text: str
) -> None:
    for i, name in enumerate(names):
        if not name:
            raise NcppError("empty column name in header", Location(source, line, _cell_col(text, i)))
        if names.index(name) != i:
            raise NcppError(
                f"column {quoted(name)} appears twice", Location(source, line, _cell_col(text, i))
            )
    if schema is None:
        return
    allowed = set(schema.required) | set(schema.optional) | set(schema.one_of)
    for i, name in enumerate(names):
        if name not in allowed:
            raise NcppError(
                f"unknown column {quoted(name)} for instrument {instrument} (expected {', '.join(schema.required + schema.optional + schema.one_of)})",
                Location(source, line, _cell_col(text, i)),
            )
    missing = [n for n in schema.required if n not in names]
    if missing:
        raise NcppError(f"{instrument} file lacks column(s) {', '.join(missing)}", Location(source, line, 1))
    if schema.one_of and sum(n in names for n in schema.one_of) != 1:
        raise NcppError(
            f"{instrument} file needs exactly one of the columns {', '.join(schema.one_of)}",
            Location(source, line, 1),
        )


def _cell_col(line: str, index: int) -> int:
    """1-based column where cell `index` of a comma separated line starts (after blanks)."""
    start = 0
    for _ in range(index):
        start = line.index(",", start) + 1
    while start < len(line) and line[start] in " \t":
        start += 1
    return start + 1


def _convert_column(
    name: str,
    raw: list[str],
    lines: list[str],
    where: list[int],
    index: int,
    schema: Schema | None,
    source: str,
) -> np.ndarray:
    values = [cell.strip() for cell in raw]

    def fail(k: int, message: str) -> NcppError:
        return NcppError(message, Location(source, where[k], _cell_col(lines[k], index)))

    if name == "direction":
        allowed = schema.directions if schema and schema.directions else ("+", "-", "CW", "CCW")
        out = []
        for k, value in enumerate(values):
            norm = value.upper()
            if norm not in allowed:
                raise fail(k, f"direction must be {' or '.join(allowed)}, got {quoted(value)}")
            out.append(norm)
        return np.array(out, dtype="<U3")
    if name == "run":
        runs = []
        for k, value in enumerate(values):
            try:
                run = int(value)
            except ValueError:
                raise fail(k, f"run must be a whole number counting from 1, got {quoted(value)}") from None
            if not 1 <= run <= MAX_RUNS:
                raise fail(k, f"run counts from 1 to {MAX_RUNS} (ISO 230-2 asks for 5), got {value}")
            runs.append(run)
        return np.array(runs, dtype=np.int64)
    numbers = np.empty(len(values))
    limit, unit, beyond = _range_of(name)
    for k, value in enumerate(values):
        try:
            numbers[k] = float(value)
        except ValueError:
            raise fail(k, f"{name}: {quoted(value)} is not a number") from None
        if not math.isfinite(numbers[k]):
            raise fail(k, f"{name}: {quoted(value)} is not a finite number")
        if name == "angle_deg" and not 0.0 <= numbers[k] < 360.0:
            raise fail(k, f"angle_deg must be in [0, 360), got {value}")
        if abs(numbers[k]) > limit:
            raise fail(k, f"{name}: {value} is out of range: beyond ±{limit:.4g} {unit} {beyond}")
    return numbers


def _range_of(name: str) -> tuple[float, str, str]:
    """(largest magnitude, unit, what lies beyond) of a length or angle column; no limit for others."""
    return next((r for ending, r in _RANGES.items() if name.endswith(ending)), (math.inf, "", ""))


def _check_meta(m: Measurement, header_line: int, meta_lines: Mapping[str, int]) -> None:
    """Check the metadata an evaluation depends on; errors point at the metadata line
    (or at the header when the line is missing)."""
    where = Location(m.source, header_line, 1)

    def at(key: str) -> Location:
        return Location(m.source, meta_lines[key], 1) if key in meta_lines else where

    if m.instrument == "laser":
        quantity = m.quantity
        if quantity not in LASER_QUANTITIES:
            raise NcppError(
                f"laser quantity must be one of {', '.join(LASER_QUANTITIES)}, got {quoted(quantity)}",
                at("quantity"),
            )
        wanted = "deviation_urad" if quantity in ANGULAR_QUANTITIES else "deviation_um"
        if wanted not in m.columns:
            raise NcppError(f"a laser {quantity} file has the column {wanted}", where)
        component, angles = m.text("component"), [f"E{r}{m.axis or 'X'}" for r in "ABC"]
        if quantity in ANGULAR_QUANTITIES and component and component.upper() not in angles:
            raise NcppError(
                f"component must be an angle of the axis, {', '.join(angles)}; got {quoted(component)}",
                at("component"),
            )
    if m.instrument == "level" and m.quantity not in LEVEL_QUANTITIES:
        raise NcppError(f"level quantity must be roll or pitch, got {quoted(m.quantity)}", at("quantity"))
    if m.instrument in ("ballbar", "grid", "cutting"):
        plane = m.text("plane")
        if plane is not None and plane.upper() not in PLANES:
            raise NcppError(f"plane must be XY, YZ or ZX, got {quoted(plane)}", at("plane"))
    if m.instrument in ("ballbar", "cutting"):
        try:
            radius = m.radius_mm
        except NcppError as err:
            raise NcppError(err.message, at("radius_mm")) from None
        if radius is None or radius <= 0:
            raise NcppError(f"a {m.instrument} file needs '# radius_mm: R' (R > 0)", at("radius_mm"))
    for key in ("center_mm", "offset_mm", "fixed", "feed_mm_min"):  # properties that read the metadata
        try:
            getattr(m, key)
        except NcppError as err:
            raise NcppError(err.message, at(key)) from None


# -- writing -----------------------------------------------------------------


def format_measurement(m: Measurement) -> str:
    """The contract's text form of `m` (numbers written to round-trip exactly)."""
    lines = [f"# instrument: {m.instrument}"]
    lines += [f"# {key}: {value}" for key, value in m.meta.items()]
    lines.append(",".join(m.columns))
    cols = [_format_column(v) for v in m.columns.values()]
    lines += [",".join(row) for row in zip(*cols)]
    return "\n".join(lines) + "\n"


def _format_column(values: np.ndarray) -> list[str]:
    if values.dtype.kind in "iu":
        return [str(int(v)) for v in values]
    if values.dtype.kind == "f":
        return [_format_float(float(v)) for v in values]
    return [str(v) for v in values]


def _format_float(value: float) -> str:
    text = repr(value)
    return text[:-2] if text.endswith(".0") and "e" not in text else text


def write_measurement(m: Measurement, path: str | os.PathLike[str]) -> None:
    """Write `m` atomically in the contract's form."""
    write_text_atomic(path, format_measurement(m))


def make_measurement(
    instrument: str, meta: Mapping[str, object], columns: Mapping[str, object], source: str = "<memory>"
) -> Measurement:
    """Build a Measurement from plain values (numbers -> str metadata, lists -> arrays)."""
    text_meta = {k: _meta_text(v) for k, v in meta.items()}
    arrays: dict[str, np.ndarray] = {}
    for name, values in columns.items():
        if name == "direction":
            arrays[name] = np.asarray(values, dtype="<U3")
        elif name == "run":
            arrays[name] = np.asarray(values, dtype=np.int64)
        else:
            arrays[name] = np.asarray(values, dtype=float)
    lengths = {len(a) for a in arrays.values()}
    if len(lengths) > 1:
        raise ValueError(f"columns differ in length: {sorted(lengths)}")
    return Measurement(instrument, text_meta, arrays, source)


def _meta_text(value: object) -> str:
    if isinstance(value, str):
        return value
    if isinstance(value, float):
        return _format_float(value)
    if isinstance(value, dict):
        return " ".join(f"{k}={_format_float(float(v))}" for k, v in value.items())
    if isinstance(value, (list, tuple, np.ndarray)):
        return ",".join(_format_float(float(v)) for v in value)
    return str(value)
