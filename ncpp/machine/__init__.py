"""Machine error model: kinematic chain, 21 geometric errors, non-geometric effects.

    from ncpp.machine import Machine, load_machine, save_machine
    m = load_machine("samples/machines/hr5b.toml")
    m.deviation(P)            # (n,3) mm, actual minus nominal tool point vs workpiece

Conventions: `ncpp.machine.chain` (frames, signs, the product of transforms);
names and the aliases of M. Rahman, *Modeling and measurement of multi-axis machine
tools to improve positioning accuracy in a software way*, University of Oulu, 2004:
`ncpp.machine.components`; file format:
`ncpp.machine.io`; effects: `ncpp.machine.effects`.
"""

from ncpp.machine.chain import Chain
from ncpp.machine.components import (
    COMPONENTS,
    SQUARENESS,
    THESIS_NAMES,
    Component,
    Polynomial,
    Table,
    canonical_name,
)
from ncpp.machine.effects import EFFECTS, Effect, effect_from_dict
from ncpp.machine.io import dumps_machine, load_machine, loads_machine, machine_to_dict, save_machine
from ncpp.machine.model import Machine
from ncpp.machine.trajectory import Trajectory

__all__ = [
    "COMPONENTS",
    "EFFECTS",
    "SQUARENESS",
    "THESIS_NAMES",
    "Chain",
    "Component",
    "Effect",
    "Machine",
    "Polynomial",
    "Table",
    "Trajectory",
    "canonical_name",
    "dumps_machine",
    "effect_from_dict",
    "load_machine",
    "loads_machine",
    "machine_to_dict",
    "save_machine",
]
