"""The user cache of built things (ncpp/cache.py) and the grammars' parsers kept in it."""

from __future__ import annotations

import os
import stat

import lark
import pytest

from ncpp.cache import cache_folder, cached_build
from ncpp.program.parser import _LARK_OPTIONS, grammar_text, lalr_parser


class Saved:
    """Something with save(file), like a Lark parser."""

    def __init__(self, value: bytes):
        self.value = value

    def save(self, f) -> None:
        f.write(self.value)


def load(f) -> Saved:
    data = f.read()
    if not data.startswith(b"ok"):
        raise ValueError("not ours")
    return Saved(data)


def build_counting(calls: list, value: bytes = b"ok built"):
    def build() -> Saved:
        calls.append(1)
        return Saved(value)

    return build


def test_built_once_then_loaded(tmp_path, monkeypatch):
    monkeypatch.setenv("NCPP_CACHE", str(tmp_path))
    calls: list = []
    first = cached_build("thing", "source", build_counting(calls), load)
    second = cached_build("thing", "source", build_counting(calls), load)
    assert calls == [1] and first.value == second.value == b"ok built"
    assert [p.suffix for p in tmp_path.iterdir()] == [".pickle"]  # no temporary file left


def test_another_source_is_another_entry(tmp_path, monkeypatch):
    monkeypatch.setenv("NCPP_CACHE", str(tmp_path))
    calls: list = []
    cached_build("thing", "source", build_counting(calls), load)
    cached_build("thing", "changed source", build_counting(calls), load)
    assert calls == [1, 1] and len(list(tmp_path.iterdir())) == 2


def test_an_unreadable_entry_is_built_again_and_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv("NCPP_CACHE", str(tmp_path))
    cached_build("thing", "source", build_counting([]), load)
    (entry,) = tmp_path.iterdir()
    entry.write_bytes(b"garbage")
    calls: list = []
    assert cached_build("thing", "source", build_counting(calls), load).value == b"ok built"
    assert calls == [1] and entry.read_bytes() == b"ok built"


def test_empty_setting_turns_the_cache_off(tmp_path, monkeypatch):
    monkeypatch.setenv("NCPP_CACHE", "")
    assert cache_folder() is None
    calls: list = []
    cached_build("thing", "source", build_counting(calls), load)
    cached_build("thing", "source", build_counting(calls), load)
    assert calls == [1, 1]


def test_default_folder_is_the_users_own(monkeypatch, tmp_path):
    monkeypatch.delenv("NCPP_CACHE", raising=False)
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path))
    assert cache_folder() == tmp_path / "ncpp"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_a_read_only_folder_still_builds(tmp_path, monkeypatch):
    folder = tmp_path / "ro"
    folder.mkdir()
    folder.chmod(stat.S_IRUSR | stat.S_IXUSR)
    monkeypatch.setenv("NCPP_CACHE", str(folder))
    try:
        assert cached_build("thing", "source", build_counting([]), load).value == b"ok built"
        assert list(folder.iterdir()) == []
    finally:
        folder.chmod(stat.S_IRWXU)


def test_a_folder_that_cannot_be_made_still_builds(tmp_path, monkeypatch):
    blocker = tmp_path / "file"
    blocker.write_text("not a folder")
    monkeypatch.setenv("NCPP_CACHE", str(blocker / "cache"))
    assert cached_build("thing", "source", build_counting([]), load).value == b"ok built"


@pytest.mark.parametrize(
    "name, line",
    [
        ("iso", "G1 X#<a>*2 Y[1+2] (c)"),
        ("fanuc", ":1000 (PART)"),
        ("heidenhain", "L X+1.5 R0 FMAX"),
        ("sinumerik", "N10 G1 X=R1+2 Y20"),
        ("apt", "GOTO/1,2,3"),
    ],
)
def test_a_grammar_loaded_from_the_cache_parses_as_the_built_one(name, line, tmp_path, monkeypatch):
    monkeypatch.setenv("NCPP_CACHE", str(tmp_path))
    built = lark.Lark(grammar_text(name), **_LARK_OPTIONS)
    lalr_parser.cache_clear()
    try:
        lalr_parser(name)  # builds and saves
        lalr_parser.cache_clear()
        loaded = lalr_parser(name)
    finally:
        lalr_parser.cache_clear()
    assert len(list(tmp_path.iterdir())) == 1
    assert [t.name for t in loaded.terminals] == [t.name for t in built.terminals]
    assert loaded.parse(line) == built.parse(line)
    assert [(t.start_pos, t.end_pos) for t in loaded.parse(line).scan_values(lambda v: True)] == [
        (t.start_pos, t.end_pos) for t in built.parse(line).scan_values(lambda v: True)
    ]
