"""Machine files (TOML): `load_machine`, `save_machine`.

Units are in the key names; inside the model everything is mm and rad.
A complete example::

    [machine]
    name = "Mitsui Seiki HR5B"
    chain = "XZFY"                 # workpiece ... F ... tool

    [offsets]
    tool = [0.0, 0.0, -200.0]      # tool point in the tool carriage, mm, with no tool length
                                   # offset (G49); G43's offset T puts the tip at tool - T
    work = [0.0, 0.0, 0.0]         # work point in the workpiece carriage, mm

    [offsets.reference]            # axis reference points (where measured), mm
    X = [0.0, 350.0, 100.0]
    Y = [0.0, 0.0, -200.0]
    Z = [0.0, 350.0, -200.0]

    [limits]                       # travel, mm
    X = [0.0, 800.0]
    Y = [0.0, 700.0]
    Z = [0.0, 700.0]

    [errors.EXX]                   # positioning of X, µm
    kind = "table"
    positions = [0.0, 100.0, 200.0]
    values_um = [0.0, 2.1, 3.9]
    values_um_minus = [1.5, 3.4, 5.6]   # optional: travel in − direction
    interpolation = "smooth"       # "linear" (default) | "smooth" (monotone cubic)

    [errors.EBX]                   # pitch of X, µrad
    kind = "table"
    positions = [0.0, 400.0, 800.0]
    values_urad = [0.0, 4.2, 7.9]

    [errors.EYX]                   # straightness as a polynomial
    kind = "polynomial"
    coefficients_um = [0.0, 0.01, -1.2e-5]  # term i in µm/mm^i
    reference_mm = 400.0           # polynomial in (x − reference_mm); default 0
    range_mm = [0.0, 800.0]        # optional: hold the end values outside

    [squareness]                   # µrad, same number as µm/m
    C0Y_urad = 25.0                # or C0Y_um_per_m
    B0Z_urad = -12.0
    A0Z_urad = 8.0

    [[effects]]                    # non-geometric effects, see effects.py
    kind = "backlash"
    axis = "X"
    um = 4.0

    [compensation]
    max_correction_mm = 0.5        # refuse corrections larger than this
    rotary_xyz_are_axis_positions = false  # true: the programmed X Y Z are the linear axes'
                                   # positions also while A, B or C turn (the control runs no
                                   # tool-centre-point kinematics), so such moves are compensated
                                   # (their pieces each turn their share); false (default): refused
    kinematics_m_codes = [428, 429]  # M codes the control is set up to switch its kinematics with
                                   # (a LinuxCNC remap to tool-centre-point control): refused

    [meta]                         # free-form, kept as is
    source = "laser 2004-03-02"

Component names may be ISO (EXX, EBX, C0Y) or those of M. Rahman, *Modeling
and measurement of multi-axis machine tools to improve positioning accuracy in a
software way*, University of Oulu, 2004 (xx, Xxx, bx, kxy); the file is written
back with ISO names.  The format, key by key: docs/machine-file.md.  The file is
UTF-8 (a byte order mark is skipped); every number in it must be finite (no nan or inf, [meta]
aside), and angles small (within ±10000 µrad, where the model's rotation series
are exact).  Errors point at the file and line, and name the key.
"""

from __future__ import annotations

import math
import os
import re
import sys
import tomllib
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import tomli_w

from ncpp.errors import Location, NcppError
from ncpp.fileio import read_small, write_text_atomic
from ncpp.machine.chain import SMALL_ANGLE
from ncpp.machine.components import AXES, COMPONENTS, SQUARENESS, Polynomial, Table, canonical_name
from ncpp.machine.effects import LARGEST_ERROR, LARGEST_LENGTH_MM, effect_from_dict, is_finite_number
from ncpp.machine.model import Machine, Vec3

SECTIONS = {"machine", "offsets", "limits", "errors", "squareness", "effects", "compensation", "meta"}
SCALE = {"um": 1e-3, "urad": 1e-6}  # file unit -> model unit (mm, rad)
MULTI_LINE_QUOTES = ('"""', "'''")
NUMBERS = {2: "two", 3: "three"}  # how many, in messages


class _Locator:
    """Line numbers for TOML sections and keys, for error messages."""

    def __init__(self, text: str, file: str):
        self.lines = text.splitlines()
        self.file = file

    def _header(self, section: str, nth: int = 0) -> int | None:
        parts = [re.escape(p) + r'|"' + re.escape(p) + '"' for p in section.split(".")]
        pattern = re.compile(r"^\s*\[\[?\s*" + r"\s*\.\s*".join(f"(?:{p})" for p in parts) + r"\s*\]\]?")
        hits = [i for i, line in enumerate(self.lines) if pattern.match(line)]
        return hits[nth] if nth < len(hits) else None

    def where(self, section: str | None = None, key: str | None = None, nth: int = 0) -> Location:
        start = 0
        if section is not None:
            found = self._header(section, nth)
            if found is None and "." in section:  # dotted keys inside the parent table
                parent, key = section.rsplit(".", 1)[0], key or section.rsplit(".", 1)[1]
                found = self._header(parent)
            if found is None:  # (no line: the table is not written in the file)
                return Location(self.file, None)
            start = found
        if key is not None:
            key_re = re.compile(r"^\s*(?:[\w.\"]*\.)?\"?" + re.escape(key) + r"\"?\s*=")
            for i in range(start + (1 if section else 0), len(self.lines)):
                if section and i > start and re.match(r"^\s*\[", self.lines[i]):
                    break
                if key_re.match(self.lines[i]):
                    return self._at_line(i)
        return self._at_line(start)

    def _at_line(self, index: int) -> Location:
        """The first character written on line `index` (0-based) of the file."""
        line = self.lines[index] if index < len(self.lines) else ""
        return Location(self.file, index + 1, len(line) - len(line.lstrip()) + 1)

    def item(self, key: str, nth: int, inner: str | None = None) -> Location | None:
        """Where item `nth` of a top-level array ``key = [...]`` begins, or its key `inner`
        (an inline table is on one line); None if there is no such array or item."""
        opening = re.compile(r"^\s*\"?" + re.escape(key) + r"\"?\s*=\s*\[")
        ends = (
            i for i, line in enumerate(self.lines) if opening.match(line) or line.lstrip().startswith("[")
        )
        row = next(ends, None)
        if row is None or not opening.match(self.lines[row]):  # top-level keys come before the first table
            return None
        for n, (line, col) in enumerate(_array_items(self.lines, row)):
            if n == nth:
                found = inner and re.compile(r"\b" + re.escape(inner) + r"\s*=").search(self.lines[line], col)
                return Location(self.file, line + 1, (found.start() if found else col) + 1)
        return None


def _array_items(lines: list[str], start: int) -> Iterator[tuple[int, int]]:
    """(line, column), 0-based, where each item of the array opened after the `=` on
    line `start` begins; stops at the array's end or at a multi-line string (rare in
    a machine file: not worth following)."""
    depth, quote, expect = 0, "", False
    for row in range(start, len(lines)):
        line, col = lines[row], (lines[start].index("=") + 1 if row == start else 0)
        while col < len(line):
            c = line[col]
            if quote:
                if c == quote:
                    quote = ""
                elif c == "\\" and quote == '"':
                    col += 1  # an escaped character
            elif c == "#":
                break
            elif not c.isspace():
                if depth == 1 and expect and c != "]":
                    yield row, col
                    expect = False
                if line.startswith(MULTI_LINE_QUOTES, col):
                    return
                if c in "\"'":
                    quote = c
                elif c in "[{":
                    depth += 1
                    expect = depth == 1
                elif c in "]}":
                    depth -= 1
                    if depth == 0:
                        return
                elif c == "," and depth == 1:
                    expect = True
            col += 1


def toml_error_location(err: tomllib.TOMLDecodeError, text: str, file: str) -> Location:
    m = re.search(r"at line (\d+), column (\d+)", str(err))
    if m:
        return Location(file, int(m.group(1)), int(m.group(2)))
    lines = text.splitlines()
    if "at end of document" in str(err):  # a truncated file: the end of its last line
        return Location(file, max(1, len(lines)), len(lines[-1]) + 1 if lines else 1)
    return Location(file, 1, 1)


def load_machine(path: str | os.PathLike[str]) -> Machine:
    """Read a machine file; NcppError with file:line for anything wrong."""
    file = str(path)
    try:
        data = read_small(path, "a machine file")
    except OSError as err:
        raise NcppError(f"cannot read machine file: {err.strerror}", Location(file)) from err
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError as err:
        raise _not_utf8(data, file) from err
    return loads_machine(text, file)


def _not_utf8(data: bytes, file: str) -> NcppError:
    """The first byte that is not UTF-8, at its line and column (read again whole: the
    text reader decodes in chunks, so the offset in its error is not the file's)."""
    try:
        data.decode("utf-8")
        return NcppError("not UTF-8 text; save the machine file as UTF-8", Location(file))
    except UnicodeDecodeError as err:
        start = err.start
    line_start = data.rfind(b"\n", 0, start) + 1
    where = Location(file, data.count(b"\n", 0, start) + 1, len(data[line_start:start].decode("utf-8")) + 1)
    return NcppError(f"not UTF-8 text (byte 0x{data[start]:02x}); save the machine file as UTF-8", where)


# Arrays and inline tables nested deeper than this are refused before tomllib, which reads them
# recursively (a machine file nests three: a table's rows of numbers)
MAX_TOML_NESTING = 32


def loads_toml(text: str, file: str) -> dict:
    """`tomllib.loads`, refusing nesting past MAX_TOML_NESTING at its place."""
    depth, line, line_start, quote = 0, 1, 0, ""
    for at, char in enumerate(text):
        if char == "\n":
            line, line_start, quote = line + 1, at + 1, ""
        elif quote:
            quote = "" if char == quote else quote
        elif char in "\"'":
            quote = char
        elif char == "#":
            quote = "\n"  # (a comment: to the end of the line)
        elif char in "[{":
            depth += 1
            if depth > MAX_TOML_NESTING:
                where = Location(file, line, at - line_start + 1)
                raise NcppError(f"arrays or tables nested deeper than {MAX_TOML_NESTING}", where)
        elif char in "]}":
            depth = max(depth - 1, 0)
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        raise
    except ValueError:  # (an integer of more digits than Python converts: sys.get_int_max_str_digits)
        most = sys.get_int_max_str_digits()
        found = re.search(rf"[0-9_]{{{most + 1},}}", text)
        at = found.start() if found is not None else 0
        line_start = text.rfind("\n", 0, at) + 1
        where = Location(file, text.count("\n", 0, at) + 1, at - line_start + 1)
        raise NcppError(f"a number of more than {most:,} digits", where) from None


def loads_machine(text: str, file: str = "<string>") -> Machine:
    text = text.removeprefix("\ufeff")  # a byte order mark, as some Windows editors write: not TOML
    try:
        data = loads_toml(text, file)
    except tomllib.TOMLDecodeError as err:
        msg = re.sub(r"\s*\(at (?:line \d+, column \d+|end of document)\)", "", str(err))
        raise NcppError(f"not valid TOML: {msg}", toml_error_location(err, text, file)) from err
    loc = _Locator(text, file)
    return _machine_from_dict(data, loc, default_name=Path(file).stem)


def _fail(message: str, where: Location) -> NcppError:
    """The error at `where`; at the file's start when what it is about is not written in the file."""
    return NcppError(message, where if where.line is not None else Location(where.file, 1, 1))


def _get_table(data: dict, name: str, loc: _Locator) -> dict:
    value = data.get(name, {})
    if not isinstance(value, dict):
        raise _fail(f"[{name}] must be a table", loc.where(key=name))
    return value


def _check_keys(table: dict, allowed: set[str], section: str, loc: _Locator) -> None:
    for key in table:
        if key not in allowed:
            raise _fail(
                f"unknown key {key!r} in [{section}]; expected one of {', '.join(sorted(allowed))}",
                loc.where(section, key),
            )


def _machine_from_dict(data: dict, loc: _Locator, default_name: str) -> Machine:
    for key in data:
        if key not in SECTIONS:
            raise _fail(f"unknown section [{key}]; expected {', '.join(sorted(SECTIONS))}", loc.where(key))
    _refuse_non_finite(data, loc)
    head = _get_table(data, "machine", loc)
    _check_keys(head, {"name", "chain", "description"}, "machine", loc)
    if "chain" not in head:
        raise _fail('[machine] needs chain, e.g. chain = "XZFY"', loc.where("machine"))
    offsets = _get_table(data, "offsets", loc)
    _check_keys(offsets, {"tool", "work", "reference"}, "offsets", loc)
    given = {k: v for k, v in offsets.items() if k != "reference"}
    tool_work = {k: _xyz(v) for k, v in _vectors(given, "offsets", "x, y, z", loc).items()}
    limits = _get_table(data, "limits", loc)
    _check_keys(limits, set(AXES), "limits", loc)
    travel = {k: _span(v) for k, v in _vectors(limits, "limits", "lo, hi", loc).items()}
    comp = _get_table(data, "compensation", loc)
    _check_keys(
        comp,
        {"max_correction_mm", "rotary_xyz_are_axis_positions", "kinematics_m_codes"},
        "compensation",
        loc,
    )
    kinematics = comp.get("kinematics_m_codes", [])
    if not isinstance(kinematics, list) or not all(type(m) is int and m >= 0 for m in kinematics):
        raise _fail("compensation: kinematics_m_codes must be a list of M numbers, as [428, 429]",
                    loc.where("compensation", "kinematics_m_codes"))  # fmt: skip
    rotary = comp.get("rotary_xyz_are_axis_positions", False)
    if not isinstance(rotary, bool):
        raise _fail("compensation: rotary_xyz_are_axis_positions must be true or false",
                    loc.where("compensation", "rotary_xyz_are_axis_positions"))  # fmt: skip
    try:
        return Machine(
            name=str(head.get("name", default_name)),
            chain=str(head["chain"]),
            tool=tool_work.get("tool", (0.0, 0.0, 0.0)),
            work=tool_work.get("work", (0.0, 0.0, 0.0)),
            references=_references(offsets, loc),
            limits=travel,
            components=_components(_get_table(data, "errors", loc), travel, loc),
            squareness=_squareness(_get_table(data, "squareness", loc), loc),
            effects=_effects(data, loc),
            max_correction_mm=_max_correction(comp, loc),
            meta=_meta(head, data, loc),
            rotary_xyz_are_axis_positions=rotary,
            kinematics_m_codes=tuple(kinematics),
        )
    except (ValueError, TypeError) as err:
        raise _fail(str(err), _where_for_machine_error(str(err), loc)) from err


def _non_finite(value: Any, path: tuple = ()) -> Iterator[tuple[tuple, float]]:
    """(path, value) of each NaN or infinite number in a parsed TOML value."""
    if isinstance(value, float) and not math.isfinite(value):
        yield path, value
    items = value.items() if isinstance(value, dict) else enumerate(value) if isinstance(value, list) else ()
    for key, item in items:
        yield from _non_finite(item, (*path, key))


def _refuse_non_finite(data: dict, loc: _Locator) -> None:
    """NaN or infinity (TOML's nan and inf, or a literal beyond 1.8e308) would come out
    as NaN commands: refuse it at its key.  [meta] is free-form and not computed with;
    a top-level value of the wrong shape is left to the check that names its shape."""
    for path, value in _non_finite({k: v for k, v in data.items() if k != "meta"}):
        last = max(i for i, p in enumerate(path) if isinstance(p, str))
        if last == 0:
            continue
        table, key, items = path[:last], path[last], path[last + 1 :]
        name = "".join(f" #{p + 1}" if isinstance(p, int) else f".{p}" for p in table)[1:]
        what = (
            f"finite numbers, not {value} (item {items[0] + 1})" if items else f"a finite number, not {value}"
        )
        if table[0] == "effects" and len(table) == 2:
            where = _effect_where(loc, table[1], key)
        else:
            where = loc.where(".".join(p for p in table if isinstance(p, str)), key)
        raise _fail(f"{name}: {key} must be {what}", where)


def _vectors(table: dict, section: str, names: str, loc: _Locator) -> dict[str, list[float]]:
    """Each key's array of numbers in mm, as many as `names` names ("lo, hi")."""
    out = {}
    for key, value in table.items():
        try:
            out[key] = _vector(value, key, names)
        except ValueError as err:
            raise _fail(f"{section}: {err}", loc.where(section, key)) from err
    return out


def _vector(value: Any, key: str, names: str) -> list[float]:
    size = names.count(",") + 1
    if not (isinstance(value, list) and len(value) == size and all(map(is_finite_number, value))):
        raise ValueError(
            f"{key} must be {NUMBERS.get(size, size)} numbers [{names}] in mm, not {_shown(value)}"
        )
    if any(abs(v) > LARGEST_LENGTH_MM for v in value):
        raise ValueError(f"{key} must be within ±{LARGEST_LENGTH_MM:g} mm (a kilometre), not {_shown(value)}")
    return [float(v) for v in value]


def _xyz(vector: list[float]) -> Vec3:
    """A `_vector` of "x, y, z" as the point it is."""
    x, y, z = vector
    return x, y, z


def _span(vector: list[float]) -> tuple[float, float]:
    """A `_vector` of "lo, hi" as the interval it is."""
    lo, hi = vector
    return lo, hi


def _references(offsets: dict, loc: _Locator) -> dict[str, Vec3]:
    refs = offsets.get("reference", {})
    if not isinstance(refs, dict):
        message = "offsets: reference must be a table of axis reference points, e.g. reference.X = [0.0, 350.0, 100.0]"
        raise _fail(message, loc.where("offsets", "reference"))
    _check_keys(refs, set(AXES), "offsets.reference", loc)
    return {k: _xyz(v) for k, v in _vectors(refs, "offsets.reference", "x, y, z", loc).items()}


def _components(
    errors: dict, travel: dict[str, tuple[float, float]], loc: _Locator
) -> dict[str, Table | Polynomial]:
    components: dict[str, Table | Polynomial] = {}
    names: dict[str, str] = {}  # ISO name: the name the file gave
    for name, spec in errors.items():
        try:
            iso = canonical_name(name)
            if iso in SQUARENESS:
                raise ValueError(f"{name} is a squareness; put it in [squareness] as {iso}_urad")
            if iso in names:  # a Rahman 2004 name and the ISO one: the second would silently win
                raise ValueError(f"{iso} is given twice, as {names[iso]} and {name}")
            components[iso] = _component_from_dict(iso, spec, travel.get(COMPONENTS[iso].axis))
            names[iso] = name
        except (ValueError, TypeError) as err:
            key = _key_named_in(str(err), spec)
            raise _fail(f"errors.{name}: {err}", loc.where(f"errors.{name}", key)) from err
    return components


def _squareness(table: dict, loc: _Locator) -> dict[str, float]:
    angles: dict[str, float] = {}
    keys: dict[str, str] = {}  # ISO name: the key the file gave
    for key, value in table.items():
        try:
            base, unit = _split_unit(key, ("_urad", "_um_per_m"))
            iso = canonical_name(base)
            if iso not in SQUARENESS:
                raise ValueError(f"{base} is not a squareness (C0Y, B0Z, A0Z)")
            if iso in keys:  # in µrad and in µm/m: the second would silently win
                raise ValueError(f"{iso} is given twice, as {keys[iso]} and {key}")
            angles[iso], keys[iso] = _number(value, key) * 1e-6, key
            _small_angles([angles[iso]], key)
        except ValueError as err:
            raise _fail(f"squareness: {err}", loc.where("squareness", key)) from err
    return angles


def _small_angles(angles: Any, key: str) -> None:
    """Angles (rad) past SMALL_ANGLE leave the rotation series the model is exact with."""
    worst = float(np.max(np.abs(angles), initial=0.0))
    if not worst < SMALL_ANGLE:
        limit = f"±{SMALL_ANGLE * 1e6:g} µrad (the model's small angles)"
        raise ValueError(f"{key} must be within {limit}, not {worst * 1e6:g}")


def _small_lengths(errors: Any, key: str) -> None:
    """Linear errors (mm) past LARGEST_ERROR µm are a typing error, not a machine's."""
    worst = float(np.max(np.abs(errors), initial=0.0)) * 1e3
    if not worst <= LARGEST_ERROR:
        raise ValueError(f"{key} must be within ±{LARGEST_ERROR:g} µm (a metre), not {worst:g}")


def _effects(data: dict, loc: _Locator) -> tuple:
    effects = data.get("effects", [])
    if not isinstance(effects, list):
        raise _fail("effects must be an array of tables: [[effects]]", loc.where(key="effects"))
    parsed = []
    for n, spec in enumerate(effects):
        try:
            parsed.append(effect_from_dict(spec))
        except (ValueError, TypeError) as err:
            raise _fail(
                f"effects #{n + 1}: {err}", _effect_where(loc, n, _key_named_in(str(err), spec))
            ) from err
    return tuple(parsed)


def _effect_where(loc: _Locator, n: int, key: str | None) -> Location:
    """Effect n's [[effects]] table (at `key`), else its item in ``effects = [...]``."""
    where = loc.where("effects", key, nth=n)
    return where if where.line is not None else loc.item("effects", n, key) or loc.where(key="effects")


def _max_correction(comp: dict, loc: _Locator) -> float:
    try:
        return _number(comp.get("max_correction_mm", 0.5), "max_correction_mm")
    except ValueError as err:
        raise _fail(f"compensation: {err}", loc.where("compensation", "max_correction_mm")) from err


def _key_named_in(message: str, spec: Any) -> str | None:
    """The key of `spec` an error message talks about (longest match), if any: the keys it lists
    as expected (after `; expected`) only when it names none before them."""
    keys = sorted(spec, key=len, reverse=True) if isinstance(spec, dict) else []
    said, _, _ = message.partition("; expected")
    return next((k for k in keys if k in said), None) or next((k for k in keys if k in message), None)


def _meta(head: dict, data: dict, loc: _Locator) -> dict:
    meta = dict(_get_table(data, "meta", loc))
    if "description" in head:
        meta["description"] = head["description"]
    return meta


def _where_for_machine_error(message: str, loc: _Locator) -> Location:
    if "chain" in message:
        return loc.where("machine", "chain")
    for axis in "XYZ":
        if f"limits of {axis}" in message or f"limits for unknown axis '{axis}'" in message:
            return loc.where("limits", axis)
        if f"reference point of {axis}" in message:
            return loc.where("offsets.reference", axis)
    for key in ("tool", "work"):
        if f"{key} offset" in message:
            return loc.where("offsets", key)
    if "max_correction_mm" in message:
        return loc.where("compensation", "max_correction_mm")
    return Location(loc.file, 1, 1)


def _split_unit(key: str, units: tuple[str, ...]) -> tuple[str, str]:
    for unit in units:
        if key.endswith(unit):
            return key[: -len(unit)], unit
    raise ValueError(f"{key!r} must end in a unit: {' or '.join(units)}")


def _shown(value: Any, width: int = 60) -> str:
    """A value for a message, cut short (a table can hold hundreds of numbers)."""
    text = repr(value)
    return text if len(text) <= width else text[: width - 3] + "..."


def _number(value: Any, key: str) -> float:
    if not is_finite_number(value):
        raise ValueError(f"{key} must be a finite number, not {_shown(value)}")
    return float(value)


def _component_from_dict(iso: str, spec: Any, travel: tuple[float, float] | None) -> Table | Polynomial:
    if not isinstance(spec, dict):
        raise ValueError('must be a table with kind = "table" or "polynomial"')
    unit = COMPONENTS[iso].unit
    other = "urad" if unit == "um" else "um"
    for key in spec:
        if other in key.split("_"):
            raise ValueError(
                f"{key}: {iso} is {'an angle' if unit == 'urad' else 'a length'}, give values in {unit}"
            )
    kind = spec.get("kind", "polynomial" if f"coefficients_{unit}" in spec else "table")
    if kind == "table":
        return _table(spec, unit)
    if kind == "polynomial":
        return _polynomial(spec, unit, travel)
    raise ValueError(f'kind must be "table" or "polynomial", not {kind!r}')


def _table(spec: dict, unit: str) -> Table:
    allowed = {"kind", "positions", f"values_{unit}", f"values_{unit}_minus", "interpolation"}
    _require(spec, allowed, {"positions", f"values_{unit}"})
    scale, minus = SCALE[unit], spec.get(f"values_{unit}_minus")
    table = Table(
        tuple(_numbers(spec["positions"], "positions")),
        tuple(v * scale for v in _numbers(spec[f"values_{unit}"], f"values_{unit}")),
        None if minus is None else tuple(v * scale for v in _numbers(minus, f"values_{unit}_minus")),
        spec.get("interpolation", "linear"),
    )
    # both interpolations stay within the tabulated values (PCHIP keeps their shape)
    if unit == "urad":
        _small_angles(table.values + (table.values_minus or ()), f"values_{unit}")
    else:
        _small_lengths(table.values + (table.values_minus or ()), f"values_{unit}")
    return table


def _polynomial(spec: dict, unit: str, travel: tuple[float, float] | None) -> Polynomial:
    key = f"coefficients_{unit}"
    _require(spec, {"kind", key, "reference_mm", "range_mm"}, {key})
    poly = Polynomial(
        tuple(c * SCALE[unit] for c in _numbers(spec[key], key)),
        _number(spec.get("reference_mm", 0.0), "reference_mm"),
        None if "range_mm" not in spec else _span(_vector(spec["range_mm"], "range_mm", "lo, hi")),
    )
    span = poly.limits or travel  # where it is evaluated; with neither, anywhere: nothing to check
    if span is not None:
        with np.errstate(all="ignore"):
            values = poly(np.linspace(*span, 101))
        if not np.all(np.isfinite(values)):
            raise ValueError(f"{key} overflow between {span[0]:g} and {span[1]:g} mm: they are too large")
        (_small_angles if unit == "urad" else _small_lengths)(
            values, f"{key} between {span[0]:g} and {span[1]:g} mm"
        )
    return poly


def _require(spec: dict, allowed: set[str], required: set[str]) -> None:
    unknown = sorted(set(spec) - allowed)
    if unknown:
        raise ValueError(f"unknown key(s) {', '.join(unknown)}; expected {', '.join(sorted(allowed))}")
    missing = sorted(required - set(spec))
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")


def _numbers(values: Any, key: str) -> list[float]:
    if not isinstance(values, list):
        raise ValueError(f"{key} must be a list of numbers, not {_shown(values)}")
    return [_number(v, key) for v in values]


# ------------------------------------------------------------------ writing
def _clean(value: float, scale: float) -> float:
    """Model units back to file units, without binary noise (0.1 stays 0.1)."""
    return float(f"{value / scale:.12g}")


def _component_to_dict(iso: str, comp) -> dict:
    unit = COMPONENTS[iso].unit
    scale = SCALE[unit]
    if isinstance(comp, Table):
        out: dict[str, Any] = {
            "kind": "table",
            "positions": list(comp.positions),
            f"values_{unit}": [_clean(v, scale) for v in comp.values],
        }
        if comp.values_minus is not None:
            out[f"values_{unit}_minus"] = [_clean(v, scale) for v in comp.values_minus]
        out["interpolation"] = comp.interpolation
        return out
    out = {"kind": "polynomial", f"coefficients_{unit}": [_clean(c, scale) for c in comp.coefficients]}
    if comp.reference:
        out["reference_mm"] = comp.reference
    if comp.limits is not None:
        out["range_mm"] = list(comp.limits)
    return out


def machine_to_dict(m: Machine) -> dict[str, Any]:
    """The TOML document (as a dict) for a machine."""
    head: dict[str, Any] = {"name": m.name, "chain": m.chain}
    meta = dict(m.meta)
    if "description" in meta:
        head["description"] = meta.pop("description")
    doc: dict[str, Any] = {
        "machine": head,
        "offsets": {
            "tool": list(m.tool),
            "work": list(m.work),
            "reference": {a: list(r) for a, r in m.references.items()},
        },
    }
    limits = {a: list(lim) for a, lim in m.limits.items() if all(math.isfinite(v) for v in lim)}
    if limits:
        doc["limits"] = limits
    if m.components:
        doc["errors"] = {iso: _component_to_dict(iso, c) for iso, c in m.components.items()}
    squareness = {f"{k}_urad": _clean(v, 1e-6) for k, v in m.squareness.items() if v}
    if squareness:
        doc["squareness"] = squareness
    if m.effects:
        doc["effects"] = [e.to_dict() for e in m.effects]
    doc["compensation"] = {"max_correction_mm": m.max_correction_mm}
    if m.rotary_xyz_are_axis_positions:
        doc["compensation"]["rotary_xyz_are_axis_positions"] = True
    if m.kinematics_m_codes:
        doc["compensation"]["kinematics_m_codes"] = list(m.kinematics_m_codes)
    if meta:
        doc["meta"] = meta
    return doc


_NUMBER_ARRAY = re.compile(r"\[\n((?:[ \t]+[-+0-9.eEinfa]+,\n)+)[ \t]*\]")


def _compact_arrays(text: str) -> str:
    """tomli_w puts every array item on its own line; put numbers ten a line."""

    def join(match: re.Match) -> str:
        items = [line.strip().rstrip(",") for line in match.group(1).splitlines()]
        if len(items) <= 10:
            return "[" + ", ".join(items) + "]"
        rows = [", ".join(items[i : i + 10]) for i in range(0, len(items), 10)]
        return "[\n    " + ",\n    ".join(rows) + ",\n]"

    return _NUMBER_ARRAY.sub(join, text)


def dumps_machine(m: Machine) -> str:
    """The machine file text."""
    doc = machine_to_dict(m)
    text = _compact_arrays(tomli_w.dumps(doc))
    if tomllib.loads(text) != tomllib.loads(tomli_w.dumps(doc)):  # never trade meaning for looks
        text = tomli_w.dumps(doc)
    return text


def save_machine(m: Machine, path: str | os.PathLike[str]) -> None:
    """Write a machine file atomically; `load_machine` reads it back equal."""
    write_text_atomic(path, dumps_machine(m))
