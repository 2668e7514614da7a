"""The test tiers (tests/conftest.py TIERS) name tests that exist: a renamed test would
otherwise drop silently into the fast tier, or out of every tier."""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

from tests.conftest import TIERS

HERE = Path(__file__).parent


def names_of_tests(module: str) -> set[str]:
    tree = ast.parse((HERE / module).read_text(encoding="utf-8"))
    return {
        node.name
        for node in ast.walk(tree)
        if isinstance(node, ast.FunctionDef) and node.name.startswith("test_")
    }


@pytest.mark.parametrize("tier", sorted(TIERS))
def test_every_name_in_a_tier_is_a_test_of_its_module(tier):
    for module, names in TIERS[tier].items():
        assert (HERE / module).is_file(), (tier, module)
        missing = set(names or ()) - names_of_tests(module)
        assert not missing, (tier, module, sorted(missing))
