"""Where the plain `ncpp` filter finds its machine file, tolerance and work offset.

The machine file, first found wins:

1. `--machine M.toml` (or `--from MEASUREMENT`) on the command line;
2. the environment variable `NCPP_MACHINE`;
3. the key `machine` of the first config file that exists, in this order:
   `./ncpp.toml`, then `$XDG_CONFIG_HOME/ncpp/config.toml`
   (`~/.config/ncpp/config.toml` when XDG_CONFIG_HOME is unset).

`tolerance` (mm) and `work_offset` ([x, y, z] mm) come from the command
line, else from that config file, else the defaults.  A relative `machine`
path in a config file is relative to the file's folder.  With no machine
file anywhere the filter passes programs through unchanged.

    # ncpp.toml
    machine = "machines/hr5b.toml"
    tolerance = 0.001
    work_offset = [400.0, 350.0, 300.0]
"""

from __future__ import annotations

import os
import tomllib
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

from ncpp.errors import Location, NcppError

KEYS = ("machine", "tolerance", "work_offset")
DEFAULT_TOLERANCE = 0.001


@dataclass(frozen=True)
class Settings:
    machine: str | None = None
    tolerance: float = DEFAULT_TOLERANCE
    work_offset: tuple[float, float, float] | None = None
    origin: str = "defaults"  # where the machine file was named: "--machine", "NCPP_MACHINE" or a config path


def config_paths(cwd: Path | None = None, env: Mapping[str, str] | None = None) -> list[Path]:
    """The config files searched, in order."""
    env = os.environ if env is None else env
    cwd = Path.cwd() if cwd is None else cwd
    xdg = env.get("XDG_CONFIG_HOME") or str(Path(env.get("HOME") or Path.home()) / ".config")
    return [cwd / "ncpp.toml", Path(xdg) / "ncpp" / "config.toml"]


def read_config(path: Path) -> dict:
    """A config file's keys, checked; `machine` made absolute."""
    try:
        data = tomllib.loads(path.read_text(encoding="utf-8"))
    except tomllib.TOMLDecodeError as err:
        raise NcppError(f"not a valid TOML config file: {err}", Location(str(path))) from None
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise NcppError(f"unknown key(s) {', '.join(unknown)} (known: {', '.join(KEYS)})", Location(str(path)))
    config: dict = {}
    if "machine" in data:
        if not isinstance(data["machine"], str):
            raise NcppError("`machine` must be a path string", Location(str(path)))
        config["machine"] = str((path.parent / Path(data["machine"]).expanduser()).resolve())
    if "tolerance" in data:
        tolerance = data["tolerance"]
        if isinstance(tolerance, bool) or not isinstance(tolerance, (int, float)) or not tolerance > 0:
            raise NcppError("`tolerance` must be a positive number of mm", Location(str(path)))
        config["tolerance"] = float(tolerance)
    if "work_offset" in data:
        offset = data["work_offset"]
        if not (isinstance(offset, list) and len(offset) == 3 and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in offset)):
            raise NcppError("`work_offset` must be [x, y, z] in mm", Location(str(path)))
        config["work_offset"] = tuple(float(v) for v in offset)
    return config


def find_settings(
    machine: str | None = None,
    tolerance: float | None = None,
    work_offset: tuple[float, float, float] | None = None,
    *,
    cwd: Path | None = None,
    env: Mapping[str, str] | None = None,
) -> Settings:
    """Settings from the command line's values (None: not given), the environment and the first config file."""
    env = os.environ if env is None else env
    config: dict = {}
    origin = "defaults"
    for path in config_paths(cwd, env):
        if path.is_file():
            config, origin = read_config(path), str(path)
            break
    if machine:
        origin = "--machine"
    elif env.get("NCPP_MACHINE"):
        machine, origin = env["NCPP_MACHINE"], "NCPP_MACHINE"
    else:
        machine = config.get("machine")
    return Settings(
        machine=machine,
        tolerance=tolerance if tolerance is not None else config.get("tolerance", DEFAULT_TOLERANCE),
        work_offset=work_offset if work_offset is not None else config.get("work_offset"),
        origin=origin,
    )
