"""Compensation passes: plain functions `(events, context) -> events`.

Composed in one tuple, like sqlglot's optimizer rules, and run by every
front end (the filter, `ncpp compensate`, the CL-data postprocessor, the
FreeCAD post and the LinuxCNC filter) through `run_passes`.

Each pass lives in its own module (`ncpp.passes.replace_arcs.replace_arcs`).  The
package binds the modules, not the functions, under those names: a function bound
here would hide its module, and `ncpp.passes.replace_arcs.BATCH_ARCS = ...` would
set an attribute of the function and change nothing.

A pass that reads events in batches hands on the events it holds when an earlier
stage refuses a line (`geometry.chunked`, `replace_arcs._batches`).  A pass that refuses a
line of a batch deals with the batch's lines before it first: `replace_arcs` hands them
on compensated (a later pass may refuse one of those), `apply_error_map` solves them
again (it checks a chunk's line ends before its reversal steps).  So the fault reported
is the program's first, whatever the batch sizes; `NcppError.locate` then names its column.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Iterator

from ncpp.motion.segments import Event
from ncpp.passes import apply_error_map, replace_arcs, rotary, subdivide
from ncpp.passes.context import ErrorMap, PassContext

Pass = Callable[[Iterable[Event], PassContext], Iterator[Event]]

# Order matters: refuse what turns rotary axes where it cannot be compensated, split lines
# on the nominal path, replace arcs by compensated arcs, then move every remaining line end point.
PASSES: tuple[Pass, ...] = (
    rotary.refuse_rotary,
    subdivide.subdivide_lines,
    replace_arcs.replace_arcs,
    apply_error_map.apply_error_map,
)


def run_passes(
    events: Iterable[Event], ctx: PassContext, passes: tuple[Pass, ...] = PASSES
) -> Iterator[Event]:
    for step in passes:
        events = step(events, ctx)
    return iter(events)


__all__ = ["PASSES", "ErrorMap", "Pass", "PassContext", "run_passes"]
