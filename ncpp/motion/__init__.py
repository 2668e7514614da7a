"""Motion: blocks -> segments (Line, Arc) and pass-through events, as LinuxCNC reads them."""

from ncpp.motion.interpreter import interpret
from ncpp.motion.segments import Arc, Context, Event, Line, Pass, Segment

__all__ = ["Arc", "Context", "Event", "Line", "Pass", "Segment", "interpret"]
