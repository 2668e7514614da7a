"""Properties of the parser, the writer and number styles (hypothesis).

* Any bytes give blocks or an NcppError that names a line -- never another exception.
* Whatever parses is written back byte for byte.
* Generated valid programs parse to the generated word values.
* format_number and NumberStyle.of are inverse to each other within a style's reach.
"""

from __future__ import annotations

import io
import os

from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from ncpp.errors import NcppError
from ncpp.program.numbers import NumberStyle, format_number
from ncpp.program.parser import parse_stream
from ncpp.program.writer import write_blocks

# A few seconds per property; NCPP_HYPOTHESIS_EXAMPLES=20000 for a deeper search.
EXAMPLES = int(os.environ.get("NCPP_HYPOTHESIS_EXAMPLES", "300"))
FAST = settings(max_examples=EXAMPLES, deadline=None, suppress_health_check=[HealthCheck.too_slow])

# -- arbitrary input ------------------------------------------------------------

# Pieces of NC syntax (and of things that break it), so that random mixes reach
# deep into the grammar instead of failing on the first character.
TOKENS = [
    "G",
    "g",
    "X",
    "x",
    "Z",
    "N",
    "O",
    "o",
    "F",
    "E",
    "e",
    "R",
    "I",
    ",",
    ",C",
    ",R",
    "@",
    "^",
    "$",
    "0",
    "1",
    "01",
    "10.",
    ".5",
    "-",
    "+",
    "2.5",
    "100",
    "*",
    "**",
    "/",
    "=",
    "#",
    "#1",
    "#<a>",
    "<",
    ">",
    "[",
    "]",
    "(",
    ")",
    ";",
    "%",
    " ",
    "\t",
    "\r",
    "\n",
    "\r\n",
    "\x00",
    "\x1a",
    "\x0c",
    "\xe9",
    "\xff",
    "sub",
    "endsub",
    "call",
    "if",
    "IF",
    "GOTO",
    "THEN",
    "WHILE",
    "DO",
    "END",
    "EQ",
    "AND",
    "MOD",
    "sin",
    "ATAN",
    "exists",
    "abs",
    "o100 ",
    "o<x> ",
    "M98",
    "M99",
    "G65",
    "P",
    "L",
    "(cmt)",
    "; c",
]
token_soup = st.lists(st.sampled_from(TOKENS), max_size=40).map(lambda ts: "".join(ts).encode("latin-1"))
latin1_text = st.text(st.characters(max_codepoint=255), max_size=80).map(lambda s: s.encode("latin-1"))
any_input = st.one_of(st.binary(max_size=120), latin1_text, token_soup)


def roundtrip(data: bytes) -> bytes:
    out = io.BytesIO()
    write_blocks(parse_stream(io.BytesIO(data), "prop.nc"), out)
    return out.getvalue()


@FAST
@given(any_input)
def test_any_input_parses_and_roundtrips_or_raises_ncpp_error(data):
    try:
        written = roundtrip(data)
    except NcppError as err:
        assert err.where.file == "prop.nc"
        assert err.where.line is not None and 1 <= err.where.line <= data.count(b"\n") + 1
        line = data.split(b"\n")[err.where.line - 1].removesuffix(b"\r")
        assert err.where.col is not None and 1 <= err.where.col <= len(line) + 1
        return
    assert written == data


# -- generated valid programs ---------------------------------------------------

LETTERS = "ABCDEFGHIJKLMNPQRSTUVWXYZ"  # no O: `O` starts program names and o-words
gap = st.sampled_from(["", "", "", " ", "  ", "\t"])


@st.composite
def number_texts(draw) -> str:
    """A decimal number as programs write it: `10`, `10.`, `010.50`, `.5`, `-0.25`, `+3`."""
    whole = draw(st.sampled_from(["", "0", "00", "1", "7", "10", "012", "123", "4096", "99999"]))
    frac = draw(st.sampled_from(["", "0", "5", "25", "1234", "0001", "999999"]))
    if not whole and not frac:
        whole = "0"
    if not frac and draw(st.booleans()):
        body = whole + "."  # trailing dot
    elif frac:
        body = f"{whole}.{frac}"
    else:
        body = whole
    return draw(st.sampled_from(["", "", "-", "+"])) + body


@st.composite
def words(draw) -> tuple[str, str, float]:
    """(text, letter, value) of one word, letter in either case, spaces allowed inside,
    between the number's digits too (rs274ngc reads `X1 5` as X15)."""
    letter = draw(st.sampled_from(LETTERS))
    number = draw(number_texts())
    sign, digits = (number[0], number[1:]) if number[0] in "+-" else ("", number)
    if draw(st.integers(0, 3)) == 0:
        digits = "".join(c + draw(gap) for c in digits[:-1]) + digits[-1]
    text = (letter if draw(st.booleans()) else letter.lower()) + draw(gap) + sign + draw(gap) + digits
    return text, letter, float(number)


comment_text = st.text(st.characters(max_codepoint=255, blacklist_characters="()\n\r"), max_size=12)


@st.composite
def lines(draw) -> tuple[str, list[tuple[str, float]]]:
    """A block of words (spaced or packed), maybe comments, block delete, leading spaces."""
    drawn = draw(st.lists(words(), max_size=6))
    text = draw(gap)
    if draw(st.integers(0, 9)) == 0:
        text += "/"
    for i, (word, _, _) in enumerate(drawn):
        text += word + draw(gap if i + 1 < len(drawn) else st.just(""))
        if draw(st.integers(0, 5)) == 0:
            text += "(" + draw(comment_text) + ")"
    if draw(st.integers(0, 4)) == 0:
        text += draw(gap) + ";" + draw(comment_text)
    return text, [(letter, value) for _, letter, value in drawn]


@st.composite
def programs(draw) -> tuple[bytes, list[list[tuple[str, float]]]]:
    body = draw(st.lists(lines(), min_size=1, max_size=12))
    tape = draw(st.booleans())
    texts = (["%"] if tape else []) + [text for text, _ in body] + (["%"] if tape else [])
    eols = [draw(st.sampled_from(["\n", "\r\n"])) for _ in texts]
    if texts[-1] and draw(st.booleans()):
        eols[-1] = ""  # no newline at the end of the file
    data = "".join(t + e for t, e in zip(texts, eols)).encode("latin-1")
    return data, [expected for _, expected in body]


@FAST
@given(programs())
def test_generated_programs_parse_to_their_word_values_and_roundtrip(program):
    data, expected = program
    blocks = list(parse_stream(io.BytesIO(data), "gen.nc"))
    if blocks and blocks[0].raw == "%":
        blocks = blocks[1:-1]
    assert [[(w.letter, w.value) for w in block.words()] for block in blocks] == expected
    assert roundtrip(data) == data


# -- number styles ------------------------------------------------------------------

values = st.floats(min_value=-1e6, max_value=1e6, allow_nan=False, allow_infinity=False)


@FAST
@given(number_texts(), values)
def test_format_number_rounds_to_the_style_decimals(text, value):
    style = NumberStyle.of(text)
    written = format_number(value, style)
    assert float(written) == round(value, style.decimals)
    assert NumberStyle.of(written).decimals == style.decimals


@FAST
@given(number_texts(), st.data())
def test_style_of_a_formatted_number_is_the_style(text, data):
    """Within the values a style can show all of itself on: no plus sign on a negative
    number, no `.5` form or zero padding for a number with more integer digits."""
    style = NumberStyle.of(text)
    bound = 1.0 if not style.leading_zero else 10.0 ** (style.int_width - 1) if style.int_width else 1e6
    low = 0.0 if style.plus_sign else -bound
    value = data.draw(st.floats(min_value=low, max_value=bound, exclude_max=True, allow_nan=False))
    written = format_number(value, style)
    assume(abs(float(written)) < bound)  # rounding may carry into one more integer digit
    assert NumberStyle.of(written) == style, (text, value, written)
