"""Chunks of whole windows of input lines: where a chunk ends depends on the program,
not on where the stream started (what the directional solve settles together)."""

from __future__ import annotations

from types import SimpleNamespace

from hypothesis import given
from hypothesis import strategies as st

from ncpp.passes.geometry import line_chunks


def _events(lines: list[int]) -> list[SimpleNamespace]:
    """Stand-ins for events: each knows its block's line, as an event does."""
    return [SimpleNamespace(block=SimpleNamespace(line=n), k=k) for k, n in enumerate(lines)]


# events in line order, several to a line (a block's pieces) and lines without any
_LINES = st.lists(st.integers(0, 6), max_size=300).map(
    lambda steps: [sum(steps[: i + 1]) for i in range(len(steps))]
)


@given(_LINES, st.integers(1, 40), st.integers(1, 50))
def test_every_event_once_in_order_each_chunk_in_one_window(lines, window, cap):
    events = _events(lines)
    chunks = list(line_chunks(events, window, cap))
    assert [e for chunk in chunks for e in chunk] == events
    for chunk in chunks:
        assert 1 <= len(chunk) <= cap
        assert len({e.block.line // window for e in chunk}) == 1


@given(_LINES, st.integers(1, 40), st.data())
def test_a_stream_started_at_a_window_chunks_the_rest_alike(lines, window, data):
    events = _events(lines)
    start = data.draw(st.integers(0, max(lines, default=0) // window + 1)) * window
    whole = [[e.k for e in chunk] for chunk in line_chunks(events, window, 10_000)]
    later = [
        [e.k for e in chunk]
        for chunk in line_chunks([e for e in events if e.block.line >= start], window, 10_000)
    ]
    assert later == [chunk for chunk in whole if events[chunk[0]].block.line >= start]
