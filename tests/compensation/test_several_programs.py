"""`ncpp compensate -o FOLDER IN...`: each program to FOLDER under its own name, `--jobs` of
them at once; each written as one program's run writes it, a failing one reported
`file:line:col: message` while the others are written, and the exit status non-zero."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from ncpp.cli import main
from tests.conftest import ROOT

MACHINE = ROOT / "samples/machines/hr5b.toml"
PLACED = ["--machine", str(MACHINE), "--work-offset", "400,350,300"]
BAD = "G21 G90 G17\nG1 X10 Y10 F100\nG2 X20 Y10 R2\nM2\n"  # line 3: the radius cannot reach the end


def _long(k: int) -> str:
    lines = "".join(
        f"G1 X{(n * k) % 47:.3f} Y{(n * 3) % 29:.3f}\nG2 X{(n * k) % 47 + 2:.3f} Y{(n * 3) % 29:.3f} R1.5\n"
        for n in range(1500)
    )
    return f"G21 G90 G17\nG0 X0 Y0 Z5\nG1 Z-1 F300\n{lines}M2\n"


@pytest.fixture(scope="module")
def programs(tmp_path_factory) -> dict[str, Path]:
    folder = tmp_path_factory.mktemp("programs")
    texts = {
        "pocket.ngc": (ROOT / "samples/programs/pocket.ngc").read_text(),
        "one.ngc": _long(5),
        "bad.ngc": BAD,
        "two.ngc": _long(7),
    }
    for name, text in texts.items():
        (folder / name).write_text(text)
    return {name: folder / name for name in texts}


@pytest.fixture(scope="module")
def alone(programs, tmp_path_factory) -> dict[str, bytes]:
    """Each good program compensated by itself, `-o FILE` (the one-program run)."""
    folder = tmp_path_factory.mktemp("alone")
    written = {}
    for name in ("pocket.ngc", "one.ngc", "two.ngc"):
        assert main(["compensate", *PLACED, str(programs[name]), "-o", str(folder / name)]) == 0
        written[name] = (folder / name).read_bytes()
    return written


def test_two_processes_write_each_program_as_its_own_run_does_and_report_the_one_that_fails(
    programs, alone, tmp_path
):
    out = tmp_path / "out"
    order = [programs[name] for name in ("pocket.ngc", "one.ngc", "bad.ngc", "two.ngc")]
    done = subprocess.run(
        [
            sys.executable,
            "-m",
            "ncpp",
            "compensate",
            *PLACED,
            "--jobs",
            "2",
            "-o",
            str(out),
            *map(str, order),
        ],
        capture_output=True,
        text=True,
        cwd=ROOT,
    )
    assert done.returncode != 0
    assert f"{programs['bad.ngc']}:3:1: " in done.stderr and "Traceback" not in done.stderr
    assert sorted(p.name for p in out.iterdir()) == [
        "one.ngc",
        "pocket.ngc",
        "two.ngc",
    ]  # no partial or temporary file
    assert {name: (out / name).read_bytes() for name in alone} == alone


def test_one_process_does_the_same(programs, alone, tmp_path, capsys):
    out = tmp_path / "out"
    missing = programs["pocket.ngc"].parent / "missing.ngc"
    paths = [programs["bad.ngc"], missing, programs["pocket.ngc"], programs["one.ngc"], programs["two.ngc"]]
    assert main(["compensate", *PLACED, "-o", str(out), *map(str, paths)]) == 2
    said = capsys.readouterr().err
    assert f"{programs['bad.ngc']}:3:1: " in said and f"{missing}: No such file or directory" in said
    assert {name: (out / name).read_bytes() for name in alone} == alone


def test_an_existing_folder_takes_one_program_too(programs, alone, tmp_path):
    assert main(["compensate", *PLACED, "-o", str(tmp_path), str(programs["pocket.ngc"])]) == 0
    assert (tmp_path / "pocket.ngc").read_bytes() == alone["pocket.ngc"]


def test_what_would_lose_a_program_is_refused_before_any_is_written(programs, tmp_path, capsys):
    pocket = programs["pocket.ngc"]
    twin = tmp_path / "twin" / "pocket.ngc"
    twin.parent.mkdir()
    twin.write_bytes(pocket.read_bytes())
    before = pocket.read_bytes()
    assert main(["compensate", *PLACED, "-o", str(tmp_path / "out"), str(pocket), str(twin)]) == 2
    assert "would both be written to" in capsys.readouterr().err
    assert main(["compensate", *PLACED, "-o", str(pocket.parent), str(pocket), str(programs["one.ngc"])]) == 2
    assert "would replace the program itself" in capsys.readouterr().err
    assert pocket.read_bytes() == before
    assert main(["compensate", *PLACED, str(pocket), str(programs["one.ngc"])]) == 2
    assert "several programs need -o FOLDER" in capsys.readouterr().err
    assert not (tmp_path / "out").exists()
