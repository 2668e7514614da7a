"""The writer's fast number format is the general one for the styles it takes it for
(signed ones, `X+1.5`, included: Klartext writes every coordinate so)."""

from __future__ import annotations

from hypothesis import given
from hypothesis import strategies as st

from ncpp.program.numbers import NumberStyle, _format_any, format_number

# Around zero (negative numbers that round to `0.000`), halves, large and non-finite values.
values = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True),
    st.floats(min_value=-1e-3, max_value=1e-3),
    st.integers(-10**6, 10**6).map(lambda n: n / 2000),
)


@given(values, st.sampled_from(["1.5", "-1.5", "10.000", "0.0001", "-0.25000000", "123.45678", "+1.5", "+10.000", "+0.0001"]))
def test_fast_format_is_the_general_one(value, written):
    style = NumberStyle.of(written)
    assert style.plain
    assert format_number(value, style) == _format_any(value, style)


def test_negative_zero_is_written_without_sign():
    assert format_number(-0.00001, NumberStyle.of("1.000")) == "0.000"
    assert format_number(-0.0005, NumberStyle.of("1.000")) == "-0.001"  # rounds away from zero: signed
