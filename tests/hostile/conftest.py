"""Running the `ncpp` command on hostile input, as a user would: in a subprocess."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PYTHON = sys.executable


def run_ncpp(
    *args: str,
    timeout: float = 60,
    stdin: bytes | None = None,
    env: dict | None = None,
    memory_mb: int | None = None,
    cwd: str | None = None,
) -> subprocess.CompletedProcess:
    """`python -m ncpp ARGS` with this checkout first on the path; `memory_mb` caps the
    address space (RLIMIT_AS), so a run past it fails instead of swapping."""
    environment = {**os.environ, "PYTHONPATH": str(ROOT), **(env or {})}

    def limit() -> None:
        if memory_mb is not None:
            import resource

            resource.setrlimit(resource.RLIMIT_AS, (memory_mb << 20, memory_mb << 20))

    return subprocess.run(
        [PYTHON, "-m", "ncpp", *args],
        input=stdin,
        capture_output=True,
        timeout=timeout,
        env=environment,
        preexec_fn=limit,
        cwd=cwd,
    )


@pytest.fixture
def ncpp():
    return run_ncpp
