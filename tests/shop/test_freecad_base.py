"""The FreeCAD post's `--base NAME` against stand-ins for FreeCAD's own posts, laid out as
FreeCAD 0.20/0.21 (`PathScripts.post.NAME_post`) and 1.x (`Path.Post.scripts.NAME_post`) ship
them: what the chosen post writes is what reaches ncpp (tests/shop/test_freecad_post.py runs the
real FreeCAD)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from tests.conftest import ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
# A stand-in for one of FreeCAD's script posts: export(objects, filename, argstring) writes G code
# that names the post and the arguments it was given.
FAKE_POST = """
def export(objectslist, filename, argstring):
    text = "(Exported by {name})\\n(args: " + argstring + ")\\n"
    text += "G21 G90 G54\\nG0 X10 Y10 Z5\\nG1 Z-1 F100\\nG1 X40 Y20\\nM2\\n"
    with open(filename, "w") as f:
        f.write(text)
    return text
"""
LAYOUTS = {"0.20": "PathScripts/post", "1.0": "Path/Post/scripts"}


def _fake_freecad(root: Path, layout: str, names: tuple[str, ...]) -> None:
    folder = root / layout
    folder.mkdir(parents=True)
    for part in range(1, len(Path(layout).parts) + 1):
        (root.joinpath(*Path(layout).parts[:part]) / "__init__.py").write_text("")
    for name in names:
        (folder / f"{name}_post.py").write_text(FAKE_POST.replace("{name}", f"{name}_post"))


def _post(tmp_path: Path, version: str, argstring: str) -> subprocess.CompletedProcess:
    freecad = tmp_path / "freecad"
    _fake_freecad(freecad, LAYOUTS[version], ("linuxcnc", "grbl", "fanuc"))
    ncpp = tmp_path / "ncpp"
    ncpp.write_text(f'#!/bin/sh\nPYTHONPATH={ROOT} exec {sys.executable} -m ncpp "$@"\n')
    ncpp.chmod(0o755)
    out = tmp_path / "out.nc"
    code = (
        f"import sys; sys.path[:0] = [{str(freecad)!r}, {str(ROOT / 'plugins/freecad')!r}]\n"
        f"import ncpp_post\nncpp_post.export([], {str(out)!r}, {argstring!r})\n"
    )
    env = {**os.environ, "NCPP": str(ncpp)}  # where the post finds the ncpp command
    proc = subprocess.run([sys.executable, "-I", "-c", code], capture_output=True, text=True, cwd=tmp_path,
                          env=env)  # fmt: skip
    proc.stdout = out.read_text() if out.exists() else ""
    return proc


@pytest.mark.parametrize("version", sorted(LAYOUTS))
@pytest.mark.parametrize("base", ["grbl", "fanuc"])
def test_base_names_the_freecad_post_that_writes_the_program(tmp_path, version, base):
    proc = _post(
        tmp_path, version, f"--base {base} --machine {MACHINE} --work-offset 400,350,300 --precision 4"
    )
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith("(ncpp compensated for hr5b.toml")
    assert f"(Exported by {base}_post)" in lines
    # ncpp's own arguments stay with ncpp; the rest reach the base post
    args = next(ln for ln in lines if ln.startswith("(args:"))
    assert "--precision 4" in args and "--machine" not in args and "--base" not in args


def test_the_default_base_is_linuxcnc(tmp_path):
    proc = _post(tmp_path, "1.0", f"--machine {MACHINE} --work-offset 400,350,300")
    assert proc.returncode == 0, proc.stderr
    assert "(Exported by linuxcnc_post)" in proc.stdout.splitlines()


def test_an_unknown_base_is_refused_by_name(tmp_path):
    proc = _post(tmp_path, "0.20", "--base heidenhain_klartext")
    assert proc.returncode != 0
    assert (
        "--base heidenhain_klartext: expected one of linuxcnc, grbl, fanuc, mach3_mach4, centroid"
        in proc.stderr
    )
