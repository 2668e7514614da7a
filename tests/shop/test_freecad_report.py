"""The FreeCAD post tells ncpp's summary, warnings and errors in FreeCAD's Report view
(`FreeCAD.Console`), naming lines of the posted program; no FreeCAD needed: its console is stubbed."""

from __future__ import annotations

import importlib.util
import sys
import types

import pytest

from tests.conftest import ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
PROGRAM = "G21 G90 G54\nG0 X10 Y10 Z5 M3\nG1 X40 F300\no100 repeat [2]\nG1 X50 Y50\nX60\no100 endrepeat\nG0 Z5\nM2\n"


@pytest.fixture
def plugin(tmp_path, monkeypatch):
    """The post module with a FreeCAD whose console records (kind, text), and an ncpp command."""
    said: list[tuple[str, str]] = []
    console = types.SimpleNamespace(
        **{
            kind: (lambda text, kind=kind: said.append((kind, text)))
            for kind in ("PrintMessage", "PrintWarning", "PrintError")
        }
    )
    monkeypatch.setitem(sys.modules, "FreeCAD", types.SimpleNamespace(Console=console))
    for name in ("NCPP_MACHINE", "XDG_CONFIG_HOME"):
        monkeypatch.delenv(name, raising=False)
    monkeypatch.setenv("HOME", str(tmp_path))
    monkeypatch.chdir(tmp_path)
    spec = importlib.util.spec_from_file_location("ncpp_post", ROOT / "plugins/freecad/ncpp_post.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    ncpp = tmp_path / "ncpp"
    ncpp.write_text(f'#!/bin/sh\nPYTHONPATH={ROOT} exec {sys.executable} -m ncpp "$@"\n')
    ncpp.chmod(0o755)
    monkeypatch.setenv("NCPP", str(ncpp))  # (the user's side: never the Job's arguments)
    return module, "", said


def test_the_summary_and_warnings_reach_the_report_view_with_the_posted_line(plugin):
    module, ncpp, said = plugin
    text = module.compensate_text(PROGRAM, f"{ncpp} --machine {MACHINE} --work-offset 400,350,300")
    assert text.startswith("(ncpp compensated")
    warnings = [t for kind, t in said if kind == "PrintWarning"]
    assert len(warnings) == 1 and warnings[0].startswith(
        "ncpp_post: line 5 of the posted program (G1 X50 Y50): warning: loop or subroutine"
    )
    messages = [t for kind, t in said if kind == "PrintMessage"]
    assert (
        len(messages) == 1
        and "compensated 3 moves" in messages[0]
        and "4 moves in loops or subroutines (lines 5-7)" in messages[0]
    )


def test_without_a_machine_file_the_report_view_warns_that_nothing_was_compensated(plugin):
    module, ncpp, said = plugin
    assert module.compensate_text(PROGRAM, ncpp) == PROGRAM
    assert [kind for kind, _ in said] == ["PrintWarning"] and "nothing was compensated" in said[0][1]


def test_a_failure_is_an_error_in_the_report_view(plugin):
    module, ncpp, said = plugin
    with pytest.raises(RuntimeError):
        module.compensate_text("G21 G90\nG0 X5000 Y0 Z0\nM2\n", f"{ncpp} --machine {MACHINE}")
    assert [kind for kind, _ in said] == ["PrintError"]
    assert "line 2 of the posted program (G0 X5000 Y0 Z0): command X5000" in said[0][1]
