"""Comparable snapshots of an interpreter's state (`Interpreter.state`, `Flow.state`).

Two processes compare what they hold at a program line (`ncpp/parts.py`): a
snapshot is made of plain values (tuples, numbers, strings) that pickle and
compare by value, taken from every attribute but those named as not state, so
that an attribute added later is compared without anyone remembering to."""

from __future__ import annotations

from typing import Any

from ncpp.program.blocks import Block, Item


def comparable(value: Any) -> Any:
    """`value` as nested tuples of plain values: a block is its line number, an item its
    fields, an object its attributes; callables (callbacks) are left out as None."""
    kind = type(value)
    if value is None or kind in (bool, int, float, str, bytes):
        return value
    if kind is list or kind is tuple:
        return tuple(comparable(v) for v in value)
    if kind is dict:
        return tuple(sorted(((repr(k), comparable(v)) for k, v in value.items()), key=lambda kv: kv[0]))
    if kind is set or kind is frozenset:
        return tuple(sorted((comparable(v) for v in value), key=repr))
    if isinstance(value, Block):
        return ("block", value.line)
    if isinstance(value, Item):
        return (kind.__name__, comparable(value._fields()))
    if callable(value):
        return None
    if hasattr(value, "__dict__"):
        return (kind.__name__, attributes(value))
    slots = [name for cls in kind.__mro__ for name in getattr(cls, "__slots__", ())]
    return (kind.__name__, tuple((name, comparable(getattr(value, name, None))) for name in slots))


def attributes(obj: object, leave_out: frozenset[str] = frozenset()) -> tuple:
    """(name, comparable value) of each of `obj`'s attributes not in `leave_out`, by name."""
    return tuple((name, comparable(value)) for name, value in sorted(vars(obj).items()) if name not in leave_out)
