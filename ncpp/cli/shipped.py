"""`ncpp install-freecad-post [--macro-dir DIR]` and `ncpp samples [DEST]`: what a pip
install needs to follow the guide's integration steps (the files live inside the package)."""

from __future__ import annotations

import argparse


def register(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser(
        "install-freecad-post",
        help="copy the FreeCAD CAM post processor (ncpp_post.py) into FreeCAD's macro folder",
    )
    p.add_argument(
        "--macro-dir",
        help="FreeCAD's macro folder (default: ~/.local/share/FreeCAD/Macro, or ~/.FreeCAD/Macro if there)",
    )
    p.set_defaults(func=install_freecad_post)
    s = sub.add_parser(
        "samples", help="print where the samples and plugins are installed, or copy the samples to DEST"
    )
    s.add_argument("dest", nargs="?", help="copy the samples folder here (it must not exist yet)")
    s.set_defaults(func=samples)


def install_freecad_post(args: argparse.Namespace) -> int:
    import os
    import shutil
    from pathlib import Path

    from ncpp.shipped import FREECAD_POST, freecad_macro_dir, shipped

    folder = (
        Path(args.macro_dir)
        if args.macro_dir
        else freecad_macro_dir(Path.home(), os.environ.get("XDG_DATA_HOME"))
    )
    folder.mkdir(parents=True, exist_ok=True)
    target = folder / "ncpp_post.py"
    shutil.copyfile(shipped(FREECAD_POST), target)
    print(f'installed {target}; choose the post processor "ncpp" in the CAM Job')
    return 0


def samples(args: argparse.Namespace) -> int:
    import shutil

    from ncpp.shipped import shipped

    if args.dest is None:
        print(f"samples: {shipped('samples')}")
        print(f"plugins: {shipped('plugins')}")
        return 0
    shutil.copytree(shipped("samples"), args.dest)
    print(f"copied the samples to {args.dest}")
    return 0
