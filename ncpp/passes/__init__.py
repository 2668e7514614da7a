"""Compensation passes: plain functions `(events, context) -> events`.

Composed in one tuple, like sqlglot's optimizer rules, and run by every
front end (the filter, `ncpp compensate`, the CL-data postprocessor, the
FreeCAD post and the LinuxCNC filter) through `run_passes`.

The functions imported below take their modules' names here: `ncpp.passes.replace_arcs`
is the function, and `import ncpp.passes.replace_arcs as m` binds the function too.  A
module's constants are reached through `sys.modules["ncpp.passes.replace_arcs"]` (or
`importlib.import_module`); setting them on the function changes nothing.
"""

from __future__ import annotations

from typing import Callable, Iterable, Iterator

from ncpp.motion.segments import Event
from ncpp.passes.apply_error_map import apply_error_map
from ncpp.passes.context import ErrorMap, PassContext
from ncpp.passes.replace_arcs import replace_arcs
from ncpp.passes.subdivide import subdivide_lines

Pass = Callable[[Iterable[Event], PassContext], Iterator[Event]]

# Order matters: split lines on the nominal path, replace arcs by compensated
# arcs, then move every remaining line end point.
PASSES: tuple[Pass, ...] = (subdivide_lines, replace_arcs, apply_error_map)


def run_passes(events: Iterable[Event], ctx: PassContext, passes: tuple[Pass, ...] = PASSES) -> Iterator[Event]:
    for step in passes:
        events = step(events, ctx)
    return iter(events)


__all__ = ["PASSES", "ErrorMap", "Pass", "PassContext", "run_passes", "apply_error_map", "replace_arcs", "subdivide_lines"]
