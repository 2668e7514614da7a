"""Number style: write a new value the way the program writes its numbers.

`X10.` `X010.500` `X.5` `X+1.25` `X+10,5`: decimal places, trailing dot,
leading zero before the point, zero padding, explicit plus sign and decimal
comma (Heidenhain) are read from the number text as written, and
`format_number` applies them to a new value.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import lru_cache


@dataclass(frozen=True, slots=True)
class NumberStyle:
    decimals: int = 4  # digits after the point
    trailing_dot: bool = False  # `10.` for a whole number with no decimals
    leading_zero: bool = True  # `0.5` rather than `.5`
    int_width: int = 0  # zero-padded integer digits (`X010.5` -> 3)
    plus_sign: bool = False
    comma: bool = False  # `10,5`: a decimal comma instead of the point
    # `z.4f` (`+z.4f` signed) when `format(v, spec)` writes the style exactly (the common case), else '':
    # set once, read per number.  `z` (Python 3.11) writes a number that rounds to zero without a minus.
    spec: str = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        plain = self.decimals > 0 and self.leading_zero and not (self.int_width or self.comma)
        object.__setattr__(
            self, "spec", f"{'+' if self.plus_sign else ''}z.{self.decimals}f" if plain else ""
        )

    @classmethod
    def of(cls, number: str) -> NumberStyle:
        """The style of a number as written (sign included, letter excluded)."""
        return _style_of(style_pattern(number))  # read once per pattern

    @classmethod
    def _read(cls, number: str) -> NumberStyle:
        plus = number.startswith("+")
        digits = number.lstrip("+-").lstrip(" \t")
        comma = "," in digits
        whole, dot, frac = digits.partition("," if comma else ".")
        padded = len(whole) > 1 and whole.startswith("0")
        return cls(
            decimals=len(frac),
            trailing_dot=bool(dot) and not frac,
            leading_zero=bool(whole) or not dot,
            int_width=len(whole) if padded else 0,
            plus_sign=plus,
            comma=comma,
        )

    @property
    def plain(self) -> bool:
        """`-12.345`, `+12.345`: what one `format` spec writes (the writer's fast path)."""
        return bool(self.spec)

    def at_least(self, decimals: int) -> NumberStyle:
        """The same style with at least `decimals` places (never lose resolution)."""
        if decimals <= self.decimals:
            return self
        return NumberStyle(decimals, False, self.leading_zero, self.int_width, self.plus_sign, self.comma)

    def resolves_like(self, other: NumberStyle, decimals: int) -> bool:
        """`self.at_least(decimals) == other.at_least(decimals)`, without making either."""
        return (
            max(self.decimals, decimals) == max(other.decimals, decimals)
            and (self.trailing_dot and self.decimals >= decimals)
            == (other.trailing_dot and other.decimals >= decimals)
            and (self.leading_zero, self.int_width, self.plus_sign, self.comma)
            == (other.leading_zero, other.int_width, other.plus_sign, other.comma)
        )


_NONZERO_DIGITS = str.maketrans("23456789", "11111111")


def style_pattern(number: str) -> str:
    """What a number's style is read from: its signs, point and zeros (the other digits as 1)."""
    return number.translate(_NONZERO_DIGITS)


@lru_cache(maxsize=4096)
def _style_of(pattern: str) -> NumberStyle:
    style = NumberStyle._read(pattern)
    return _INTERNED.setdefault(style, style)


# One instance per distinct style read from numbers: equal styles read are the same object,
# so a writer tells a changed style by identity (`X10.5` then `X12.5`: no change)
_INTERNED: dict[NumberStyle, NumberStyle] = {}


def format_number(value: float, style: NumberStyle) -> str:
    if style.spec:  # the common style: Python's own fixed-point format is exactly it
        return format(value, style.spec)
    return _format_any(value, style)


def _format_any(value: float, style: NumberStyle) -> str:
    """`format_number` for every style."""
    text = f"{abs(value):.{style.decimals}f}"
    if float(text) == 0.0:
        value = 0.0  # no `-0.000`
    whole, _, frac = text.partition(".")
    if style.int_width:
        whole = whole.zfill(style.int_width)
    if whole == "0" and frac and not style.leading_zero:
        whole = ""
    point = "," if style.comma else "."
    body = f"{whole}{point}{frac}" if frac else (f"{whole}{point}" if style.trailing_dot else whole)
    sign = "-" if value < 0 else ("+" if style.plus_sign else "")
    return sign + body
