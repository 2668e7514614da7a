"""APT CL data (NX CLSF, Creo NCL, ...) -> motion events.

    from ncpp.cldata import read_cldata, motion
    with open("part.cls") as f:
        for event in motion(read_cldata(f, "part.cls")):
            ...   # ncpp.motion.segments Line / Arc / Pass

Grammar: grammar/apt.lark; records: `ncpp.cldata.reader`; APT motion
semantics (CIRCLE forms, RAPID, MULTAX): `ncpp.cldata.motion`.
"""

from ncpp.cldata.motion import motion
from ncpp.cldata.reader import KNOWN, Record, read_cldata

__all__ = ["KNOWN", "Record", "motion", "read_cldata"]
