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
    st.integers(-(10**6), 10**6).map(lambda n: n / 2000),
)


@given(
    values,
    st.sampled_from(
        ["1.5", "-1.5", "10.000", "0.0001", "-0.25000000", "123.45678", "+1.5", "+10.000", "+0.0001"]
    ),
)
def test_fast_format_is_the_general_one(value, written):
    style = NumberStyle.of(written)
    assert style.plain
    assert format_number(value, style) == _format_any(value, style)


def test_negative_zero_is_written_without_sign():
    assert format_number(-0.00001, NumberStyle.of("1.000")) == "0.000"
    assert format_number(-0.0005, NumberStyle.of("1.000")) == "-0.001"  # rounds away from zero: signed


styles = st.builds(
    NumberStyle,
    decimals=st.integers(0, 8),
    trailing_dot=st.booleans(),
    leading_zero=st.booleans(),
    int_width=st.sampled_from([0, 0, 3]),
    plus_sign=st.booleans(),
    comma=st.booleans(),
)


@given(styles, styles, st.integers(0, 8))
def test_resolves_like_is_equality_of_the_resolved_styles(a, b, decimals):
    assert a.resolves_like(b, decimals) == (a.at_least(decimals) == b.at_least(decimals))


def test_styles_that_drop_trailing_zeros_resolve_alike():
    """cameo.nc writes `X1.125`, `X0.` and `X-4.52`: each is another style, all written with 4 places."""
    one, dot, two = NumberStyle.of("1.125"), NumberStyle.of("0."), NumberStyle.of("-4.52")
    assert one != dot != two
    assert one.resolves_like(dot, 4) and dot.resolves_like(two, 4) and not one.resolves_like(dot, 0)
