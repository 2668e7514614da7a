"""The Klartext writer remembers where the output is at the decimal places each block was
written with, not those of the program's first move."""

from __future__ import annotations

import io
from dataclasses import replace

from ncpp.motion.segments import Arc, Line
from ncpp.pipeline import dialect_tools
from ncpp.program.dialects import parse_program


def written(program: str, moved: dict[int, tuple[float, float, float]]) -> list[str]:
    """The program written with the moves of the blocks on the lines of `moved` shifted by it."""
    interpret, writer = dialect_tools("heidenhain")
    _, blocks = parse_program(io.BytesIO(program.encode()), "t.h", "heidenhain")
    events = []
    for event in interpret(blocks, file="t.h"):
        shift = moved.get(event.block.line) if type(event) in (Line, Arc) else None
        if shift is not None:
            event = replace(event, end=tuple(v + d for v, d in zip(event.end, shift)), changed=True)
        events.append(event)
    return "".join(writer().write(events)).splitlines()


def test_an_axis_moved_below_the_first_moves_resolution_is_written():
    """Y+0.000004 then a compensated block moving Y to 0: the output says Y+0.000000, in the
    six places the program wrote Y with (not the four of its first move, where 4 µm vanish)."""
    program = "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 R0 F500\n2 L X+10.123456 Y+0.000004\n3 L X+20.123456\n4 END PGM T MM\n"
    lines = written(program, {4: (0.000002, -0.000004, 0.0)})
    assert lines[3] == "3 L X+20.123458 Y+0.000000"


def test_an_axis_where_the_last_block_left_it_is_not_written_again():
    """A first move in six places, then blocks in one: a compensated block without Y whose Y is
    exactly where the block before left it adds no Y word (the end is compared at four places,
    as the block before wrote it, not at the first move's six)."""
    program = "0 BEGIN PGM T MM\n1 L X+0.123456 Y+0.123456 Z+0.123456 R0 F500\n2 L X+10.5 Y+5.5\n3 L X+20.5\n4 END PGM T MM\n"
    lines = written(program, {3: (0.00002, 0.00003, 0.0), 4: (0.00002, 0.00003, 0.0)})
    assert lines[2:4] == ["2 L X+10.5000 Y+5.5000", "3 L X+20.5000"]


def test_signs_teach_no_new_style_and_the_feed_keeps_its_own():
    """Klartext signs every coordinate it writes: `X+1.5` and `X-1.5` are one style, so
    the styles resolved from it are kept (not worked out again per block), and `F500`
    stays unsigned."""
    from ncpp.program.dialects.heidenhain import HeidenhainWriter
    from ncpp.program.dialects.iso import _MM

    _, blocks = parse_program(
        io.BytesIO(b"1 L X+1.500 Y-2.500 F500\n2 L X-1.500 Y+2.500\n"), "t.h", "heidenhain"
    )
    writer = HeidenhainWriter()
    first, second = blocks
    writer._learn_styles(first)
    x = writer._style("X", _MM)
    writer._learn_styles(second)
    assert (
        writer._resolved.get(("X", False)) is x and x.plus_sign and x.decimals == 4
    )  # at least the writer's 4
    assert writer.styles["X"] == writer.styles["Y"] and not writer.styles["F"].plus_sign


from hypothesis import given  # noqa: E402
from hypothesis import strategies as st  # noqa: E402

_klartext_numbers = st.builds(
    lambda sign, whole, frac: sign + whole + frac,
    st.sampled_from(["", "+", "-"]),
    st.text("0123456789", min_size=1, max_size=3),
    st.sampled_from(["", "."]).flatmap(
        lambda dot: st.text("0123456789", max_size=4).map(lambda d: dot + d if dot else "")
    ),
)


@given(st.lists(st.tuples(_klartext_numbers, _klartext_numbers), min_size=1, max_size=6))
def test_styles_learnt_per_number_pattern_are_each_numbers_own(pairs):
    """`_learn_styles` keeps what a (letter, number pattern) teaches: the style is the number's own
    (signed, but F), learnt in order, and the block's axes become known."""
    from ncpp.program.dialects.heidenhain import HeidenhainWriter, _signed
    from ncpp.program.numbers import NumberStyle

    writer = HeidenhainWriter()
    text = "".join(f"{n} L X{x} IY{y} F{y.lstrip('+-')} M3\n" for n, (x, y) in enumerate(pairs, 1))
    _, blocks = parse_program(io.BytesIO(text.encode()), "t.h", "heidenhain")
    for block, (x, y) in zip(blocks, pairs):
        writer._learn_styles(block)
        assert writer.styles["X"] == _signed(NumberStyle.of(x)) and writer.styles["IY"] == _signed(
            NumberStyle.of(y)
        )
        assert (
            writer.styles["F"] == NumberStyle.of(y.lstrip("+-"))
            and "M" not in writer.styles
            and "N" not in writer.styles
        )
    assert writer.known_axes == {"X", "Y"}


def test_a_pole_event_holds_the_cc_point_and_plane():
    """`CC X+50 Y+50` (XY plane): its Pole event says that centre, and the block runs (not skipped)."""
    from ncpp.motion.heidenhain import Pole

    interpret, _ = dialect_tools("heidenhain")
    program = "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z-2 R0 F500\n2 CC X+50 Y+50\n3 END PGM T MM\n"
    _, blocks = parse_program(io.BytesIO(program.encode()), "t.h", "heidenhain")
    (pole,) = [e for e in interpret(blocks, file="t.h") if type(e) is Pole]
    assert pole.center[:2] == (50.0, 50.0) and pole.plane == 17 and pole.skipped is False


def test_the_pole_written_back_after_an_edited_arc_is_the_programs():
    """An edited arc writes its own `CC` first; the unchanged arc after it needs the program's
    pole back, which here is the same point: no `CC` in the output names another point."""
    program = (
        "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+0 R0 F500\n2 CC X+50 Y+50\n3 L X+60 Y+50\n"
        "4 C X+50 Y+60 DR+\n5 C X+40 Y+50 DR+\n6 END PGM T MM\n"
    )
    lines = written(program, {5: (0.001, 0.0, 0.0)})  # file line 5: block 4
    poles = [line.split()[1:] for line in lines if line.split()[1:2] == ["CC"]]
    assert len(poles) >= 2  # the program's, and the edited arc's
    for words in poles:
        assert float(words[1][1:]) == 50.0 and float(words[2][1:]) == 50.0, lines
