"""The FreeCAD post and the LinuxCNC filter run only what the user installed."""

from __future__ import annotations

import importlib.util
import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import SHARED

ROOT = Path(__file__).resolve().parents[2]


def _freecad_post():
    spec = importlib.util.spec_from_file_location("ncpp_post", ROOT / "plugins/freecad/ncpp_post.py")
    plugin = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plugin)
    return plugin


def test_the_freecad_post_never_runs_a_program_the_document_names(tmp_path, monkeypatch):
    """The Job's arguments are saved in the .FCStd: `--ncpp` there would run any program."""
    plugin = _freecad_post()
    planted = tmp_path / "planted"
    planted.write_text(f"#!/bin/sh\ntouch {tmp_path / 'ran'}\n")
    planted.chmod(0o755)
    monkeypatch.setenv("NCPP", "/bin/cat")  # the user's choice, which a document cannot override
    with pytest.raises(RuntimeError, match="--ncpp in the Job's arguments is refused"):
        plugin.compensate_text("G0 X1\nM2\n", f"--ncpp {planted}")
    assert not (tmp_path / "ran").exists()
    assert plugin.compensate_text("G0 X1\nM2\n", "") == "G0 X1\nM2\n"  # NCPP's program ran


def test_the_linuxcnc_filter_imports_nothing_from_the_working_folder(tmp_path):
    """`python3 -m` puts the working folder first on the import path: a `numpy.py` there ran.
    (ncpp is imported as installed in this Python.)"""
    (tmp_path / "numpy.py").write_text(f"open({str(tmp_path / 'ran')!r}, 'w').close()\n")
    program = tmp_path / "p.ngc"
    program.write_text("G21 G1 X1 F100\nM2\n")
    machine = SHARED / "machines/wide.toml"
    if not machine.exists():
        pytest.skip("no shared machine file")
    env = {**os.environ, "NCPP_PYTHON": sys.executable, "NCPP_MACHINE": str(machine), "NCPP_CACHE": ""}
    env.pop("PYTHONPATH", None)
    done = subprocess.run(
        [str(ROOT / "plugins/linuxcnc/ncpp-linuxcnc-filter"), str(program)],
        cwd=tmp_path,
        capture_output=True,
        env=env,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    assert not (tmp_path / "ran").exists()
