"""Shared test fixtures: where the third-party corpus and the oracle live."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SHARED = Path(os.environ.get("NCPP_SHARED", ROOT.parent / "shared"))
CORPUS = SHARED / "corpus"
RS274 = SHARED / "tools" / "rs274"

# Files that are data or oracles beside programs, not programs.
NOT_PROGRAMS = ("expected", "README", ".tbl", "__expect__stdout", "__expect__stderr", ".csv", "MANIFEST.tsv")


def corpus_files(*folders: str) -> list[Path]:
    """Program files under the given corpus folders, sorted, oracles excluded."""
    found: list[Path] = []
    for folder in folders:
        for path in sorted((CORPUS / folder).rglob("*")):
            if path.is_file() and not any(path.name.endswith(s) or s in path.name for s in NOT_PROGRAMS):
                found.append(path)
    return found


def corpus_id(path: Path) -> str:
    return str(path.relative_to(CORPUS))


@pytest.fixture(scope="session")
def corpus() -> Path:
    if not CORPUS.is_dir():
        pytest.skip(f"corpus not found at {CORPUS}")
    return CORPUS


def expected_signature(items) -> str | None:
    """`Block.signature` of a plain line's items: its word letters in order, each G word
    with its number as written; None when a word has two letters (`,R`)."""
    from ncpp.program.blocks import Word

    words = [i for i in items if type(i) is Word]
    if any(len(w.letter) > 1 for w in words):
        return None
    return "".join(w.letter + w.number * (w.letter == "G") for w in words)
