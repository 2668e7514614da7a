"""What a pip install carries: the wheel holds the FreeCAD post, the LinuxCNC filter set-up
and the samples inside the package, and the `ncpp` commands find them there."""

from __future__ import annotations

import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

from tests.conftest import ROOT

SHIPPED = ("plugins/freecad/ncpp_post.py", "plugins/linuxcnc/filter.ini",
           "plugins/linuxcnc/ncpp-linuxcnc-filter",
           "samples/programs/pocket.cls", "samples/machines/hr5b.toml")  # fmt: skip


def _ncpp(*args: str, path: Path = ROOT, **kwargs) -> subprocess.CompletedProcess:
    """`ncpp ARGS` importing ncpp from `path` only (not the checkout the tests run from)."""
    code = f"import sys; sys.path.insert(0, {str(path)!r}); from ncpp.cli import main; sys.exit(main())"
    return subprocess.run([sys.executable, "-I", "-c", code, *args], capture_output=True, text=True, **kwargs)


@pytest.fixture(scope="module")
def installed(tmp_path_factory) -> Path:
    """The wheel built from this checkout, unpacked as pip installs it (its files under site-packages)."""
    tmp = tmp_path_factory.mktemp("wheel")
    command = [sys.executable, "-m", "pip", "wheel", str(ROOT), "-w", str(tmp), "--no-deps", "-q"]
    proc = subprocess.run(command, capture_output=True, text=True)
    if proc.returncode != 0:
        pytest.fail("pip wheel failed:\n" + proc.stderr[-2000:])
    (wheel,) = tmp.glob("ncpp-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    assert {f"ncpp/{name}" for name in SHIPPED} <= names
    site = tmp / "site-packages"
    zipfile.ZipFile(wheel).extractall(site)
    return site


def test_the_wheel_finds_its_samples_and_plugins_inside_the_package(installed, tmp_path):
    proc = _ncpp("samples", path=installed, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    found = dict(line.split(": ", 1) for line in proc.stdout.splitlines())
    assert found == {"samples": str(installed / "ncpp/samples"), "plugins": str(installed / "ncpp/plugins")}
    copy = tmp_path / "my-samples"
    assert _ncpp("samples", str(copy), path=installed, cwd=tmp_path).returncode == 0
    assert (copy / "programs/pocket.cls").read_bytes() == (ROOT / "samples/programs/pocket.cls").read_bytes()


def test_install_freecad_post_from_the_wheel(installed, tmp_path):
    macros = tmp_path / "Macro"
    proc = _ncpp("install-freecad-post", "--macro-dir", str(macros), path=installed, cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert (macros / "ncpp_post.py").read_bytes() == (ROOT / "plugins/freecad/ncpp_post.py").read_bytes()


@pytest.mark.parametrize(
    ("existing", "expected"),
    [((), ".local/share/FreeCAD/Macro"), ((".FreeCAD",), ".FreeCAD/Macro"),
     ((".FreeCAD/Macro",), ".FreeCAD/Macro"),
     ((".FreeCAD", ".local/share/FreeCAD/Macro"), ".local/share/FreeCAD/Macro")],
)  # fmt: skip
def test_install_freecad_post_finds_the_macro_folder_freecad_uses(tmp_path, existing, expected):
    home = tmp_path / "home"
    for folder in existing:
        (home / folder).mkdir(parents=True)
    env = {"HOME": str(home), "PATH": "/usr/bin:/bin"}
    proc = _ncpp("install-freecad-post", cwd=tmp_path, env=env)
    assert proc.returncode == 0, proc.stderr
    assert (home / expected / "ncpp_post.py").is_file()
