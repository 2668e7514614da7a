"""Identification: error-model components from measurements.

    from ncpp.identify import fit_machine
    machine = fit_machine([read_measurement(p) for p in files], base=None, chain="XYFZ")

See `ncpp.identify.fit` for what each file gives and how the Abbe terms are removed,
`ncpp.identify.ballbar` for ball-bar files (regularised least squares, uncertainties,
what the data cannot separate); `identify(...)` returns the machine and that account.
"""

from ncpp.identify.ballbar import BallbarFit, account, fit_ballbar
from ncpp.identify.fit import DEFAULT_CHAIN, Source, fit_machine, fit_residuals, identify, sources_of

__all__ = [
    "DEFAULT_CHAIN", "BallbarFit", "Source", "account", "fit_ballbar", "fit_machine", "fit_residuals", "identify",
    "sources_of",
]  # fmt: skip
