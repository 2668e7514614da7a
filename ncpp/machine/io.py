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

    [meta]                         # free-form, kept as is
    source = "laser 2004-03-02"

Component names may be ISO (EXX, EBX, C0Y) or the thesis's (xx, Xxx, bx,
kxy); the file is written back with ISO names.  Errors point at the file and
line.
"""

from __future__ import annotations

import math
import os
import re
import tomllib
from pathlib import Path
from typing import Any

import tomli_w

from ncpp.errors import Location, NcppError
from ncpp.fileio import write_text_atomic
from ncpp.machine.components import COMPONENTS, SQUARENESS, Polynomial, Table, canonical_name
from ncpp.machine.effects import effect_from_dict
from ncpp.machine.model import Machine

SECTIONS = {"machine", "offsets", "limits", "errors", "squareness", "effects", "compensation", "meta"}
SCALE = {"um": 1e-3, "urad": 1e-6}  # file unit -> model unit (mm, rad)


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
            if found is None:
                return Location(self.file, None)
            start = found
        if key is not None:
            key_re = re.compile(r"^\s*(?:[\w.\"]*\.)?\"?" + re.escape(key) + r"\"?\s*=")
            for i in range(start + (1 if section else 0), len(self.lines)):
                if section and i > start and re.match(r"^\s*\[", self.lines[i]):
                    break
                if key_re.match(self.lines[i]):
                    return Location(self.file, i + 1)
        return Location(self.file, start + 1)


def _parse_error_location(err: tomllib.TOMLDecodeError, file: str) -> Location:
    m = re.search(r"at line (\d+), column (\d+)", str(err))
    return Location(file, int(m.group(1)), int(m.group(2))) if m else Location(file)


def load_machine(path: str | os.PathLike[str]) -> Machine:
    """Read a machine file; NcppError with file:line for anything wrong."""
    file = str(path)
    try:
        text = Path(path).read_text(encoding="utf-8")
    except OSError as err:
        raise NcppError(f"cannot read machine file: {err.strerror}", Location(file)) from err
    return loads_machine(text, file)


def loads_machine(text: str, file: str = "<string>") -> Machine:
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as err:
        msg = re.sub(r"\s*\(at line \d+, column \d+\)", "", str(err))
        raise NcppError(f"not valid TOML: {msg}", _parse_error_location(err, file)) from err
    loc = _Locator(text, file)
    return _machine_from_dict(data, loc, default_name=Path(file).stem)


def _fail(message: str, where: Location) -> NcppError:
    return NcppError(message, where)


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
    head = _get_table(data, "machine", loc)
    _check_keys(head, {"name", "chain", "description"}, "machine", loc)
    if "chain" not in head:
        raise _fail("[machine] needs chain, e.g. chain = \"XZFY\"", loc.where("machine"))
    offsets = _get_table(data, "offsets", loc)
    _check_keys(offsets, {"tool", "work", "reference"}, "offsets", loc)
    references = offsets.get("reference", {})
    components, squareness = {}, {}
    errors = _get_table(data, "errors", loc)
    for name, spec in errors.items():
        try:
            iso = canonical_name(name)
            if iso in SQUARENESS:
                raise ValueError(f"{name} is a squareness; put it in [squareness] as {iso}_urad")
            components[iso] = _component_from_dict(iso, spec)
        except (ValueError, TypeError) as err:
            key = _key_named_in(str(err), spec)
            raise _fail(f"errors.{name}: {err}", loc.where(f"errors.{name}", key)) from err
    for key, value in _get_table(data, "squareness", loc).items():
        try:
            base, unit = _split_unit(key, ("_urad", "_um_per_m"))
            iso = canonical_name(base)
            if iso not in SQUARENESS:
                raise ValueError(f"{base} is not a squareness (C0Y, B0Z, A0Z)")
            squareness[iso] = _number(value, key) * 1e-6
        except ValueError as err:
            raise _fail(f"squareness: {err}", loc.where("squareness", key)) from err
    effects = data.get("effects", [])
    if not isinstance(effects, list):
        raise _fail("effects must be an array of tables: [[effects]]", loc.where(key="effects"))
    parsed_effects = []
    for n, spec in enumerate(effects):
        try:
            parsed_effects.append(effect_from_dict(spec))
        except (ValueError, TypeError) as err:
            key = _key_named_in(str(err), spec)
            raise _fail(f"effects #{n + 1}: {err}", loc.where("effects", key, nth=n)) from err
    comp = _get_table(data, "compensation", loc)
    _check_keys(comp, {"max_correction_mm"}, "compensation", loc)
    try:
        return Machine(
            name=str(head.get("name", default_name)),
            chain=str(head["chain"]),
            tool=offsets.get("tool", (0.0, 0.0, 0.0)),
            work=offsets.get("work", (0.0, 0.0, 0.0)),
            references=references,
            limits=_get_table(data, "limits", loc),
            components=components,
            squareness=squareness,
            effects=tuple(parsed_effects),
            max_correction_mm=comp.get("max_correction_mm", 0.5),
            meta=_meta(head, data),
        )
    except (ValueError, TypeError) as err:
        raise _fail(str(err), _where_for_machine_error(str(err), loc)) from err


def _key_named_in(message: str, spec: Any) -> str | None:
    """The key of `spec` an error message talks about (longest match), if any."""
    keys = sorted(spec, key=len, reverse=True) if isinstance(spec, dict) else []
    return next((k for k in keys if k in message), None)


def _meta(head: dict, data: dict) -> dict:
    meta = dict(data.get("meta", {}))
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
    return Location(loc.file)


def _split_unit(key: str, units: tuple[str, ...]) -> tuple[str, str]:
    for unit in units:
        if key.endswith(unit):
            return key[: -len(unit)], unit
    raise ValueError(f"{key!r} must end in a unit: {' or '.join(units)}")


def _number(value: Any, key: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{key} must be a finite number")
    return float(value)


def _component_from_dict(iso: str, spec: Any):
    if not isinstance(spec, dict):
        raise ValueError("must be a table with kind = \"table\" or \"polynomial\"")
    unit = COMPONENTS[iso].unit
    other = "urad" if unit == "um" else "um"
    for key in spec:
        if other in key.split("_"):
            raise ValueError(f"{key}: {iso} is {'an angle' if unit == 'urad' else 'a length'}, give values in {unit}")
    scale = SCALE[unit]
    kind = spec.get("kind", "polynomial" if f"coefficients_{unit}" in spec else "table")
    if kind == "table":
        allowed = {"kind", "positions", f"values_{unit}", f"values_{unit}_minus", "interpolation"}
        _require(spec, allowed, {"positions", f"values_{unit}"})
        minus = spec.get(f"values_{unit}_minus")
        return Table(
            spec["positions"],
            [v * scale for v in _numbers(spec[f"values_{unit}"], f"values_{unit}")],
            None if minus is None else [v * scale for v in _numbers(minus, f"values_{unit}_minus")],
            spec.get("interpolation", "linear"),
        )
    if kind == "polynomial":
        allowed = {"kind", f"coefficients_{unit}", "reference_mm", "range_mm"}
        _require(spec, allowed, {f"coefficients_{unit}"})
        coeffs = [c * scale for c in _numbers(spec[f"coefficients_{unit}"], f"coefficients_{unit}")]
        return Polynomial(coeffs, spec.get("reference_mm", 0.0), spec.get("range_mm"))
    raise ValueError(f"kind must be \"table\" or \"polynomial\", not {kind!r}")


def _require(spec: dict, allowed: set[str], required: set[str]) -> None:
    unknown = sorted(set(spec) - allowed)
    if unknown:
        raise ValueError(f"unknown key(s) {', '.join(unknown)}; expected {', '.join(sorted(allowed))}")
    missing = sorted(required - set(spec))
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")


def _numbers(values: Any, key: str) -> list[float]:
    if not isinstance(values, list):
        raise ValueError(f"{key} must be a list of numbers")
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
