"""The parser cache unpickles only what the user alone could have written."""

from __future__ import annotations

import os

import pytest

from ncpp.cache import cached_build
from tests.program.test_cache import build_counting, load


def _planted(folder, name="g") -> list:
    """Build once into `folder`, then replace the entry with a planted one; what loads?"""
    calls: list = []
    cached_build(name, "source", build_counting(calls), load)
    (entry,) = folder.glob(f"{name}-*.pickle")
    return entry


@pytest.fixture
def cache(tmp_path, monkeypatch):
    folder = tmp_path / "cache"
    monkeypatch.setenv("NCPP_CACHE", str(folder))
    return folder


def test_an_entry_others_may_write_is_not_read(cache):
    entry = _planted(cache)
    entry.write_bytes(b"ok planted")
    os.chmod(entry, 0o666)
    calls: list = []
    assert cached_build("g", "source", build_counting(calls), load).value == b"ok built"
    assert calls == [1]


def test_an_entry_in_a_folder_others_may_write_is_not_read(cache):
    entry = _planted(cache)
    entry.write_bytes(b"ok planted")
    os.chmod(cache, 0o777)
    calls: list = []
    assert cached_build("g", "source", build_counting(calls), load).value == b"ok built"
    assert calls == [1]


@pytest.mark.skipif(os.geteuid() != 0, reason="giving a file to another user takes root")
def test_an_entry_of_another_user_is_not_read(cache):
    entry = _planted(cache)
    entry.write_bytes(b"ok planted")
    os.chown(entry, 65534, 65534)
    calls: list = []
    assert cached_build("g", "source", build_counting(calls), load).value == b"ok built"
    assert calls == [1]


def test_a_link_in_place_of_an_entry_is_not_followed(cache, tmp_path):
    entry = _planted(cache)
    elsewhere = tmp_path / "elsewhere.pickle"
    elsewhere.write_bytes(b"ok planted")
    entry.unlink()
    entry.symlink_to(elsewhere)
    calls: list = []
    assert cached_build("g", "source", build_counting(calls), load).value == b"ok built"


def test_the_users_own_entry_is_read(cache):
    entry = _planted(cache)
    entry.write_bytes(b"ok mine")
    calls: list = []
    assert cached_build("g", "source", build_counting(calls), load).value == b"ok mine" and calls == []
