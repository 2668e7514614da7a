"""Identification: error-model components from measurements.

    from ncpp.identify import fit_machine
    machine = fit_machine([read_measurement(p) for p in files], base=None, chain="XYFZ")

See `ncpp.identify.fit` for what each file gives and how the Abbe terms are removed.
"""

from ncpp.identify.fit import DEFAULT_CHAIN, Source, fit_machine, fit_residuals, sources_of

__all__ = ["DEFAULT_CHAIN", "Source", "fit_machine", "fit_residuals", "sources_of"]
