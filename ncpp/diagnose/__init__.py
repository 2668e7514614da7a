"""Diagnosis: where simulation and measurement disagree, which missing effect
explains it, the updated model (`ncpp diagnose`).

    from ncpp.diagnose import diagnose
    d = diagnose(machine, [read_measurement(p) for p in paths])
    d.steps, d.gap_before, d.gap_after, d.updated, d.report("...")
"""

from ncpp.diagnose.workflow import Diagnosis, Gap, Step, diagnose

__all__ = ["Diagnosis", "Gap", "Step", "diagnose"]
