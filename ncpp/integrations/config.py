"""Where the plain `ncpp` filter finds its machine file, tolerance and work offset.

The machine file, first found wins:

1. `--machine M.toml` (or `--from MEASUREMENT`) on the command line;
2. the environment variable `NCPP_MACHINE`;
3. the key `machine` of the first config file that exists, in this order:
   `./ncpp.toml`, then `$XDG_CONFIG_HOME/ncpp/config.toml`
   (`~/.config/ncpp/config.toml` when XDG_CONFIG_HOME is unset).

`tolerance` (mm) and where the program sits on the machine come from the
command line, else from that config file, else the defaults: `work_offset`
is G54's zero ([x, y, z] machine mm) or a table of zeros by G word;
`var_file` names LinuxCNC's parameter file (`var_units` "mm" or "inch", the
INI's [TRAJ]LINEAR_UNITS), which `work_offset` overrides, and `tool_table` its
tool table (the INI's [EMCIO]TOOL_TABLE, same units).  A relative `machine`,
`var_file` or `tool_table` path in a config file is relative to the file's
folder.  With no machine file anywhere the filter passes programs through
unchanged.

    # ncpp.toml
    machine = "machines/hr5b.toml"
    tolerance = 0.001
    work_offset = [400.0, 350.0, 300.0]          # or: work_offset = {G54 = [...], G55 = [...]}
    # var_file = "~/linuxcnc/configs/mill/linuxcnc.var"
    # tool_table = "~/linuxcnc/configs/mill/tool.tbl"
"""

from __future__ import annotations

import configparser
import math
import os
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from pathlib import Path

from ncpp.errors import Location, NcppError
from ncpp.fileio import read_small
from ncpp.motion.offsets import UNIT_MM, Vector, WorkOffsets, check_zero, system_number

KEYS = ("machine", "tolerance", "work_offset", "var_file", "var_units", "tool_table")
PATH_KEYS = ("machine", "var_file", "tool_table")  # relative to the config file's folder
DEFAULT_TOLERANCE = 0.001


@dataclass(frozen=True)
class Settings:
    machine: str | None = None
    tolerance: float = DEFAULT_TOLERANCE
    zeros: Mapping[str, Vector] = field(default_factory=dict)  # G word -> machine mm (work_offset)
    var_file: str | None = None
    var_units: str = "mm"
    tool_table: str | None = None
    origin: str = "defaults"  # where the machine file was named: "--machine", "NCPP_MACHINE" or a config path
    subroutine_path: tuple[
        str, ...
    ] = ()  # folders of subroutine files (LinuxCNC's [RS274NGC]SUBROUTINE_PATH)

    def offsets(self) -> WorkOffsets:
        """The zeros the control holds, as these settings say them."""
        return WorkOffsets.given(
            self.zeros, self.var_file, UNIT_MM[self.var_units], self.tool_table, self.subroutine_path
        )


def config_paths(cwd: Path | None = None, env: Mapping[str, str] | None = None) -> list[Path]:
    """The config files searched, in order."""
    env = os.environ if env is None else env
    cwd = Path.cwd() if cwd is None else cwd
    xdg = env.get("XDG_CONFIG_HOME") or str(Path(env.get("HOME") or Path.home()) / ".config")
    return [cwd / "ncpp.toml", Path(xdg) / "ncpp" / "config.toml"]


def read_config(path: Path) -> dict:
    """A config file's keys, checked; `machine` made absolute."""
    try:
        text = read_small(path, "an ncpp config file").decode("utf-8")
        from ncpp.machine.io import loads_toml

        data = loads_toml(text, str(path))
    except UnicodeDecodeError as err:
        raise NcppError("not UTF-8 text; save the config file as UTF-8", Location(str(path), 1, 1)) from err
    except tomllib.TOMLDecodeError as err:
        from ncpp.machine.io import toml_error_location

        raise NcppError(
            f"not a valid TOML config file: {err}", toml_error_location(err, text, str(path))
        ) from None
    unknown = sorted(set(data) - set(KEYS))
    if unknown:
        raise NcppError(
            f"unknown key(s) {', '.join(unknown)} (known: {', '.join(KEYS)})", Location(str(path))
        )
    config: dict = {}
    for key in PATH_KEYS:
        if key in data:
            if not isinstance(data[key], str):
                raise NcppError(f"`{key}` must be a path string", Location(str(path)))
            config[key] = str((path.parent / Path(data[key]).expanduser()).resolve())
    if "tolerance" in data:
        tolerance = data["tolerance"]
        if (
            isinstance(tolerance, bool)
            or not isinstance(tolerance, (int, float))
            or not 0 < tolerance < math.inf
        ):
            raise NcppError("`tolerance` must be a positive number of mm", Location(str(path)))
        config["tolerance"] = float(tolerance)
    if "work_offset" in data:
        config["zeros"] = _zeros(data["work_offset"], path)
    if "var_units" in data:
        if data["var_units"] not in UNIT_MM:
            raise NcppError('`var_units` must be "mm" or "inch"', Location(str(path)))
        config["var_units"] = data["var_units"]
    return config


def _zeros(value, path: Path) -> dict[str, Vector]:
    """`work_offset`: [x, y, z] (G54's) or {G54 = [x, y, z], G55 = ...}."""
    table = value if isinstance(value, dict) else {"G54": value}
    zeros = {}
    for name, zero in table.items():
        if not (
            isinstance(zero, list)
            and len(zero) == 3
            and all(
                isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v) for v in zero
            )
        ):
            raise NcppError(
                "`work_offset` must be [x, y, z] in mm (finite numbers), or a table of them by G word (G54 = [x, y, z])",
                Location(str(path)),
            )
        try:
            system_number(name)
            check_zero(zero)
        except ValueError as err:
            raise NcppError(f"`work_offset`: {err}", Location(str(path))) from None
        zeros[name.upper()] = tuple(float(v) for v in zero)
    return zeros  # type: ignore[return-value]


def find_settings(
    machine: str | None = None,
    tolerance: float | None = None,
    zeros: Mapping[str, Vector] | None = None,
    var_file: str | None = None,
    var_units: str | None = None,
    tool_table: str | None = None,
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
        zeros=zeros or config.get("zeros", {}),
        var_file=var_file or config.get("var_file"),
        var_units=var_units or config.get("var_units", "mm"),
        tool_table=tool_table or config.get("tool_table"),
        origin=origin,
    )


# [TRAJ]LINEAR_UNITS spellings LinuxCNC accepts for its machine units
_INI_UNITS = {"mm": "mm", "metric": "mm", "inch": "inch", "in": "inch", "imperial": "inch"}


def with_linuxcnc_ini(settings: Settings, ini: str | Path | None) -> Settings:
    """The settings with LinuxCNC's own files where they name none: the INI's
    [RS274NGC]PARAMETER_FILE and [EMCIO]TOOL_TABLE (relative to the INI's folder),
    in its [TRAJ]LINEAR_UNITS, and the folders of subroutine files in LinuxCNC's order:
    [DISPLAY]PROGRAM_PREFIX, [RS274NGC]SUBROUTINE_PATH, [WIZARD]WIZARD_ROOT.  LinuxCNC exports
    the INI's path as $INI_FILE_NAME to the programs it runs, the filter among them."""
    if not ini:
        return settings
    path = Path(ini)
    parser = configparser.ConfigParser(
        strict=False, interpolation=None
    )  # LinuxCNC INIs repeat keys (HALFILE)
    parser.optionxform = str  # type: ignore[assignment,method-assign]
    try:
        parser.read_string(read_small(path, "a LinuxCNC INI file").decode("latin-1"), str(path))
    except (OSError, configparser.Error) as err:
        raise NcppError(f"cannot read the LinuxCNC INI file: {err}", Location(str(path))) from None

    def named(section: str, key: str) -> str | None:
        """The file the INI names, if it exists (LinuxCNC makes a missing parameter file)."""
        value = parser.get(section, key, fallback="").strip()
        found = (path.parent / Path(value).expanduser()).resolve()
        return str(found) if value and found.is_file() else None

    var_file, tool_table = named("RS274NGC", "PARAMETER_FILE"), named("EMCIO", "TOOL_TABLE")
    folders = [parser.get("DISPLAY", "PROGRAM_PREFIX", fallback=""), *parser.get("RS274NGC", "SUBROUTINE_PATH", fallback="").split(":"),
               parser.get("WIZARD", "WIZARD_ROOT", fallback="")]  # fmt: skip
    subroutine_path = tuple(
        str((path.parent / Path(f.strip()).expanduser()).resolve()) for f in folders if f.strip()
    )
    units = _INI_UNITS.get(parser.get("TRAJ", "LINEAR_UNITS", fallback="mm").strip().lower(), "mm")
    own_units = settings.var_file or settings.tool_table  # the config's files: its units
    return replace(
        settings,
        var_file=settings.var_file or var_file,
        tool_table=settings.tool_table or tool_table,
        var_units=settings.var_units if own_units else units,
        subroutine_path=settings.subroutine_path or subroutine_path,
    )
