"""Lines the LALR parser reads are parsed once per layout: a line of a layout read
before is built from that line's tree with its own token texts.  It must build
exactly what a parse of its own would."""

from __future__ import annotations

import io
import re

import pytest

from ncpp.errors import NcppError
from ncpp.program.blocks import UNREADABLE
from ncpp.program.parser import (
    LineParser,
    _Cut,
    _digits_named,
    _flatten,
    _TreeLayouts,
    lalr_parser,
    parse_stream,
)
from tests.conftest import corpus_files

DIALECT_FOLDERS = {
    "iso": ("iso_gcode", "malformed"),
    "heidenhain": ("heidenhain",),
    "sinumerik": ("sinumerik",),
}

# Lines whose layouts differ only where a grammar tells digits apart, and expression lines.
LINES = {
    "iso": [
        "N120Y[#<yscale>*-56.12]Z[#<zscale>*-27.725]",
        "#1 = [#2 + 3.5] (set)",
        "o100 sub",
        "o<a1> call [1] [2.5]",
        "G1 X[1+2] Y#3 F[#<f>*10]",
        "O1000",
        "X[ATAN[1]/[2]] ; c",
    ],
    "heidenhain": [
        "4 L X+1.5 Y+2 R0 F800",
        "5 L X+1.5 Y+2 R1 F800",
        "6 TOOL CALL 1 Z S5000 DR+0.1",
        "7 TOOL CALL 1 Z S5000 DR2+0.1",
        "8 L X+Q1 Y-Q22 RL F MAX",
        "9 CC X+25 Y+25",
        "10 C X+50 Y+25 DR- R0",
    ],
    "sinumerik": [
        "N10 G1 X=1.5+R1 Y2",
        "R1=R2*3",
        "N20 G1 X=IC(1.5) Z-2 ; c",
        "DEF REAL A1=3",
        "G2 X10 Y0 CR=5.5",
    ],
}


def fresh(parser: LineParser, raw: str) -> tuple | type:
    """The line's items from its own parse (or the error class it raises)."""
    try:
        return tuple(_flatten(parser.dialect.builder().transform(parser._lark.parse(raw))))
    except Exception as err:  # noqa: BLE001 - compared, not hidden
        return type(err)


def replayed(parser: LineParser, raw: str) -> tuple | type:
    try:
        return parser._parse_lalr(raw, 1, "t")
    except NcppError:
        return NcppError


def variants(raw: str) -> list[str]:
    """The line, then with all its digits made 7, 0, 2 and 1 in turn: layouts that
    coincide for a grammar blind to digits."""
    return [raw, *(re.sub(r"[0-9]", d, raw) for d in "7021")]


@pytest.mark.parametrize("dialect", sorted(LINES))
def test_replayed_lines_build_what_their_own_parse_builds(dialect):
    parser, checked = LineParser(dialect), 0
    for raw in LINES[dialect]:
        for line in variants(raw):
            want = fresh(parser, line)
            got = replayed(parser, line)
            if isinstance(want, tuple):
                assert got == want, line
                checked += 1
            else:
                assert not isinstance(got, tuple), line
    assert checked >= 3 * len(LINES[dialect])
    assert parser._trees is not None and parser._trees.known  # layouts were learnt


@pytest.mark.parametrize("dialect", sorted(DIALECT_FOLDERS))
def test_replay_agrees_with_the_lalr_parser_on_corpus(corpus, dialect):
    parser, checked, replays, cuts = LineParser(dialect), 0, 0, 0
    for path in corpus_files(*DIALECT_FOLDERS[dialect]):
        try:
            blocks = list(parse_stream(io.BytesIO(path.read_bytes()), str(path), dialect))
        except NcppError:
            continue
        for block in blocks:
            if block.verbatim or parser._scan_plain(block.raw) is not None:
                continue
            known = parser._trees.known.get(parser._trees.layout(block.raw))
            replays += known is not None
            cuts += type(known) is _Cut
            want, got = fresh(parser, block.raw), replayed(parser, block.raw)
            assert got == want if isinstance(want, tuple) else not isinstance(got, tuple), (path, block.line)
            checked += 1
    assert checked > {"iso": 5000, "heidenhain": 200, "sinumerik": 100}[dialect]
    assert (
        replays > {"iso": 10000, "heidenhain": 50, "sinumerik": 15}[dialect]
    )  # lines built by the replay itself
    assert (
        cuts >= {"iso": 60, "heidenhain": 4, "sinumerik": 10}[dialect]
    )  # and of those, cut from the line (82, 4, 12)


def test_plain_klartext_blocks_are_cut_from_the_line():
    """`L X+1.5 Y+2 R0 F800`: the items are the constant ones (`L`, `R0`) and plain words;
    numbers with a decimal comma are left to the builder's own reading (the replay)."""
    parser = LineParser("heidenhain")
    lines = [
        "4 L X+1.5 Y+2 R0 F800",
        "5 L X-2.5 Y+7 R0 F900",
        "6 L X+10,5 Y+2 R0 F800",
        "7 L X+11,5 Y+3 R0 F800",
        "8 L X+1.5 Y+2 R1 F800",
    ]
    for line in lines:
        assert replayed(parser, line) == fresh(parser, line), line
    kinds = [type(parser._trees.known[parser._trees.layout(line)]).__name__ for line in lines]
    assert kinds == ["_Cut", "_Cut", "_Replay", "_Replay", "_Cut"]
    assert (
        replayed(parser, "9 L X+1.5 Y+2 R1 F800")[4] == fresh(parser, "9 L X+1.5 Y+2 R1 F800")[4]
    )  # R1 kept: not R0's items


def test_grammars_name_digits_only_right_after_a_letter():
    """ISO and Sinumerik terminals treat every digit alike; Heidenhain's name `DR2` and
    `R0` (a digit right after a letter, which its layouts keep).  A terminal naming a
    digit anywhere else would turn the replay off (None), never make it wrong."""
    from ncpp.program.dialects import get_dialect

    kinds = {}
    for name in DIALECT_FOLDERS:
        terminals = lalr_parser(get_dialect(name).grammar).terminals
        kinds[name] = {t.name for t in terminals if _digits_named(t.pattern.to_regexp())}
        assert _TreeLayouts.of(lalr_parser(get_dialect(name).grammar)) is not None
    assert kinds == {"iso": set(), "sinumerik": set(), "heidenhain": {"WORD", "QWORD", "RADIUS_COMP"}}
    for pattern, named in [("R[0LR]", True), (r"\d+[.,]\d*", False), ("[A-Za-z0-9_]+", False), (r"\d{2}", False),
                           ("[1-9]", None), ("R?2", None), (r"\s2", None), (r"[^\]0]", None)]:  # fmt: skip
        assert _digits_named(pattern) is named, pattern


def test_layouts_keep_digits_after_letters_only_where_the_grammar_names_them():
    from ncpp.program.dialects import get_dialect

    iso = _TreeLayouts.of(lalr_parser(get_dialect("iso").grammar))
    heidenhain = _TreeLayouts.of(lalr_parser(get_dialect("heidenhain").grammar))
    assert iso.layout("N120 R0 Y[#<y2>*-5.6]") == "N111 R1 Y[#<y1>*-1.1]"
    assert heidenhain.layout("5 L X+12.5 R0 DR2-0.5 F800") == "1 L X+11.1 R0 DR2-1.1 F811"


def test_a_replayed_line_with_an_error_is_reported_as_its_own_parse_reports_it():
    parser = LineParser("iso")
    parser.parse("G1 X[1+2]", "", 1, "t.ngc")
    (unreadable,) = parser.parse("G1 X[1+2", "", 7, "t.ngc").items  # (an error where the line runs)
    assert unreadable.kind == UNREADABLE and unreadable.node[0].where.line == 7
