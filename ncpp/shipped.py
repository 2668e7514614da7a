"""Files that ship with ncpp beside its code: the FreeCAD post, the LinuxCNC filter
set-up (`plugins/`) and the worked examples (`samples/`).

A wheel carries them inside the package (ncpp/plugins, ncpp/samples: pyproject's
force-include); a checkout keeps them at the top, beside the package.
"""

from __future__ import annotations

from importlib.resources import files
from pathlib import Path

FREECAD_POST = "plugins/freecad/ncpp_post.py"


def shipped(name: str) -> Path:
    """The shipped file or folder `name` (e.g. "samples", FREECAD_POST)."""
    package = Path(str(files("ncpp")))
    for candidate in (package / name, package.parent / name):
        if candidate.exists():
            return candidate
    raise FileNotFoundError(f"{name} is not installed with ncpp (looked in {package} and {package.parent})")


def freecad_macro_dir(home: Path, xdg_data_home: str | None = None) -> Path:
    """FreeCAD's user macro folder: FreeCAD 0.20 and later keep user data in
    $XDG_DATA_HOME/FreeCAD (~/.local/share/FreeCAD) unless an older ~/.FreeCAD is there,
    which they go on using; the one that exists, else the newer."""
    data = Path(xdg_data_home) if xdg_data_home else home / ".local/share"
    newer, older = data / "FreeCAD" / "Macro", home / ".FreeCAD" / "Macro"
    for folder in (newer, older, older.parent):
        if folder.is_dir():
            return older if folder == older.parent else folder
    return newer
