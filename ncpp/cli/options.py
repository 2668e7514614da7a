"""Types of command-line options: each turns the text into a number or refuses it.

argparse reports a refusal as `ncpp CMD: error: argument --OPT: ...` with exit status 2,
before any file is read; nan and inf are refused everywhere since they would pass
into output files and numerical models.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable


def finite(text: str) -> float:
    """A finite number (nan and inf would pass into output files)."""
    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def positive(text: str) -> float:
    value = finite(text)
    if not value > 0:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def non_negative(text: str) -> float:
    value = finite(text)
    if value < 0:
        raise argparse.ArgumentTypeError(f"expected a number >= 0, got {text!r}")
    return value


def between(low: float, high: float, ends: str = "[]") -> Callable[[str], float]:
    """A number from low to high; `ends` tells which are included: "[]" both, "()" neither, "(]"..."""

    def parse(text: str) -> float:
        value = finite(text)
        above = low < value if ends[0] == "(" else low <= value
        below = value < high if ends[1] == ")" else value <= high
        if not (above and below):
            raise argparse.ArgumentTypeError(
                f"expected a number in {ends[0]}{low:g}, {high:g}{ends[1]}, got {text!r}"
            )
        return value

    return parse


def at_least(low: int) -> Callable[[str], int]:
    """A whole number >= low."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
        if value < low:
            raise argparse.ArgumentTypeError(f"expected a whole number >= {low}, got {text!r}")
        return value

    return parse
