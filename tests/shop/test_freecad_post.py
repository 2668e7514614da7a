"""The FreeCAD post processor run by real FreeCAD (`freecadcmd`, headless):
a box, a Path Job, a profile, posted with `ncpp` from the macro directory."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import numpy as np
import pytest

from tests.conftest import ROOT
from tests.rs274 import canon, end_points


def _freecadcmd() -> str | None:
    """$NCPP_FREECADCMD (another FreeCAD, e.g. tests/shop/freecadcmd-chroot), else freecadcmd on PATH."""
    found = shutil.which(os.environ.get("NCPP_FREECADCMD") or "freecadcmd")
    return os.path.abspath(found) if found else None


FREECADCMD = _freecadcmd()
MACHINE = ROOT / "samples/machines/hr5b.toml"
pytestmark = pytest.mark.skipif(
    FREECADCMD is None,
    reason=f"{os.environ.get('NCPP_FREECADCMD') or 'freecadcmd (Debian package freecad)'} is not installed",
)


@pytest.fixture(scope="module")
def posted(tmp_path_factory):
    """(compensated, plain) programs posted by FreeCAD through ncpp_post, and FreeCAD's output."""
    tmp = tmp_path_factory.mktemp("freecad")
    home = tmp / "home"
    macros = home / ".local/share/FreeCAD/Macro"  # FreeCAD's user macro directory under $HOME
    macros.mkdir(parents=True)
    shutil.copy(ROOT / "plugins/freecad/ncpp_post.py", macros)
    ncpp = tmp / "ncpp"  # the ncpp command of this checkout (an installed one is on PATH as `ncpp`)
    ncpp.write_text(f'#!/bin/sh\nPYTHONPATH={ROOT} exec {sys.executable} -m ncpp "$@"\n')
    ncpp.chmod(0o755)
    env = {k: v for k, v in os.environ.items() if k not in ("NCPP_MACHINE", "XDG_CONFIG_HOME", "PYTHONPATH")}
    env.update(
        HOME=str(home),
        NCPP_OUT=str(tmp / "compensated.ngc"),
        NCPP=str(ncpp),  # (the user's side: never the Job's arguments)
        # (no placement guard: rs274 runs the program from its own G54 below)
        NCPP_POST_ARGS=f"--machine {MACHINE} --work-offset 400,350,300 --no-guard --precision 4 --no-comments",
        NCPP_PLAIN_OUT=str(tmp / "plain.ngc"),
        NCPP_PLAIN_ARGS="--precision 4",
        NCPP_BASE_OUT=str(tmp / "grbl.nc"),
        NCPP_BASE_ARGS=f"--base grbl --machine {MACHINE} --work-offset 400,350,300",
    )
    proc = subprocess.run(
        [FREECADCMD, str(ROOT / "tests/shop/freecad/post_job.py")],
        capture_output=True,
        text=True,
        errors="replace",
        cwd=tmp,
        env=env,
        timeout=600,
    )
    if "NCPP_POSTED" not in proc.stdout:
        pytest.fail("FreeCAD did not post:\n" + proc.stdout[-3000:] + proc.stderr[-2000:])
    return tmp / "compensated.ngc", tmp / "plain.ngc", proc.stdout


def test_freecad_posts_a_compensated_program(posted):
    compensated, _, _ = posted
    lines = compensated.read_text().splitlines()
    assert lines[0].startswith("(ncpp compensated for hr5b.toml sha256:")
    assert "(Exported by FreeCAD)" in lines[:5] and any("linuxcnc_post" in ln for ln in lines[:5])
    assert any(ln.startswith(("G2", "G3")) for ln in lines)  # the profile's corner arcs stay arcs
    assert not any(ln.startswith("(begin") for ln in lines)  # --no-comments reached linuxcnc_post
    assert not any("placement guard" in ln for ln in lines)  # --no-guard reached ncpp


def test_linuxcnc_accepts_it_and_the_path_is_corrected_by_microns(posted):
    compensated, plain, _ = posted
    plain_ends = np.array(end_points(canon(plain, timeout=300)))
    compensated_ends = np.array(end_points(canon(compensated, timeout=300)))
    assert len(plain_ends) > 10
    # Every programmed end point is reached within the correction (lines may be subdivided).
    nearest = np.array([np.abs(compensated_ends - p).max(axis=1).min() for p in plain_ends[1:]])
    assert 1e-3 < nearest.max() < 0.1


def test_without_a_machine_file_the_post_is_freecads_own(posted):
    _, plain, _ = posted
    text = plain.read_text()
    assert "ncpp compensated" not in text and text.startswith("(Exported by FreeCAD)")
    # Posted after the compensated one: its --no-comments did not stick in linuxcnc_post.
    assert "(begin preamble)" in text


def test_freecad_1_uses_the_class_and_the_legacy_script_api_agrees(posted):
    *_, output = posted
    if "NCPP_PROCESSOR" not in output:
        pytest.skip("FreeCAD before 1.0 has only the legacy export()")
    assert "NCPP_PROCESSOR Ncpp" in output  # PostProcessorFactory found the class, not WrapperPost
    assert output.count("NCPP_LEGACY_SAME True") == 2


def test_the_post_passes_every_fixture_zero_to_ncpp(tmp_path, monkeypatch):
    """A Job with two fixtures: `--work-offset` repeated (and `--var-file`, `--tool-table`)
    reach ncpp as given (the plugin needs no FreeCAD for this part)."""
    import importlib.util

    spec = importlib.util.spec_from_file_location("ncpp_post", ROOT / "plugins/freecad/ncpp_post.py")
    plugin = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(plugin)
    options, rest = plugin.parser.parse_known_args(
        [
            "--machine",
            "m.toml",
            "--work-offset",
            "250,300,300",
            "--work-offset",
            "G55=550,400,250",
            "--var-file",
            "l.var",
            "--tool-table",
            "t.tbl",
            "--no-comments",
        ]  # fmt: skip
    )
    assert plugin._ncpp_arguments(options) == [
        "--machine", "m.toml", "--var-file", "l.var", "--tool-table", "t.tbl", "--work-offset", "250,300,300", "--work-offset", "G55=550,400,250",
    ]  # fmt: skip
    assert rest == ["--no-comments"]  # for FreeCAD's linuxcnc_post
    ncpp = tmp_path / "ncpp"
    ncpp.write_text(f'#!/bin/sh\nPYTHONPATH={ROOT} exec {sys.executable} -m ncpp "$@"\n')
    ncpp.chmod(0o755)
    monkeypatch.setenv("NCPP", str(ncpp))
    program = "G21 G90 G54\nG0 X10 Y10 Z5\nG1 Z-1 F100\nG55\nG1 X20 Y20\nM2\n"
    both = f"--machine {MACHINE} --work-offset 250,300,300 --work-offset G55=550,400,250"
    text = plugin.compensate_text(program, both)
    assert "G55" in text and text.startswith("(ncpp compensated")
    only_g54 = plugin.compensate_text(program, f"--machine {MACHINE} --work-offset 250,300,300")
    body = lambda text: text[text.index("G21 G90 G54\n") :]  # noqa: E731 (after ncpp's header)

    # (up to G55 and the placement guard's check of its zero before it, where it is told)
    def before_g55(text: str) -> str:
        ends = (body(text).find("\n(ncpp placement guard: G55"), body(text).index("\nG55\n"))
        return body(text)[: min(i for i in ends if i >= 0)]

    after_g55 = lambda text: body(text)[body(text).index("\nG55\n") :]  # noqa: E731
    assert after_g55(text) != after_g55(only_g54)  # compensated where G55 really is
    assert before_g55(text) == before_g55(only_g54)
    assert "G55 X550 Y400 Z250" in text and "G55 X550" not in only_g54  # the header tells both


def test_the_post_wraps_freecads_grbl_post_with_base(posted):
    compensated, _, _ = posted
    grbl = (compensated.parent / "grbl.nc").read_text().splitlines()
    assert grbl[0].startswith("(ncpp compensated for hr5b.toml sha256:")
    assert any("grbl_post" in ln for ln in grbl[:6]) and not any("linuxcnc_post" in ln for ln in grbl[:6])
    assert any(ln.startswith(("G2", "G3")) for ln in grbl)
