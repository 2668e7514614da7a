"""`written_apart`'s shortcut on the grid of the written decimals says what comparing
the two numbers rounded by Python's `round` says, ties and their neighbours included."""

import math

from hypothesis import example, given, settings
from hypothesis import strategies as st

from ncpp.program.dialects.iso import written_apart


def by_round(value: float, places: int, last: float, last_places: int) -> bool:
    return round(value, places) != round(last, last_places)


near_ties = st.builds(
    lambda k, places, ulps: (
        math.nextafter((k + 0.5) / 10**places, math.inf if ulps > 0 else -math.inf)
        if ulps
        else (k + 0.5) / 10**places
    ),
    st.integers(-(10**9), 10**9),
    st.integers(0, 6),
    st.integers(-2, 2),
)
values = st.one_of(st.floats(-1e5, 1e5, allow_nan=False), near_ties)


@settings(max_examples=1000, deadline=None)
@given(
    value=values,
    last=values,
    places=st.integers(0, 9),
    other_places=st.integers(0, 9),
    same_places=st.booleans(),
)
@example(value=0.00005, last=0.00015, places=4, other_places=4, same_places=True)
@example(value=2.675, last=2.665, places=2, other_places=2, same_places=True)
@example(value=-0.5, last=0.5, places=0, other_places=0, same_places=True)
def test_as_round_says(value, last, places, other_places, same_places):
    last_places = places if same_places else other_places
    assert written_apart(value, places, last, last_places) == by_round(value, places, last, last_places)
    # and a value a grid step or less from the other
    near = last + (value % 1) / 10**places
    assert written_apart(near, places, last, last_places) == by_round(near, places, last, last_places)
