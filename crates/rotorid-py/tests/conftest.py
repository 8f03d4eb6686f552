"""Shared fixtures: the `rotorid` command (ROTORID_BIN, set by test.sh) and records."""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

import pytest

import rotorid

HERE = Path(__file__).resolve().parent
EXAMPLES = HERE.parent / "examples"


@pytest.fixture(scope="session")
def cli() -> str:
    """Path of the `rotorid` binary."""
    path = os.environ.get("ROTORID_BIN")
    if not path or not Path(path).is_file():
        pytest.skip("ROTORID_BIN is not set to the built `rotorid` binary (crates/rotorid-py/test.sh sets it)")
    return path


def run(cli: str, *args: str) -> subprocess.CompletedProcess[str]:
    """Run the CLI; fail with its stderr when it fails."""
    p = subprocess.run([cli, *args], capture_output=True, text=True)
    assert p.returncode == 0, f"rotorid {' '.join(args)} failed:\n{p.stderr}"
    return p


@pytest.fixture(scope="session")
def table1() -> rotorid.Scenario:
    return rotorid.Scenario.table1()


@pytest.fixture(scope="session")
def noisy(table1: rotorid.Scenario):
    """table1, 1 s at 10 kHz, 40 dB, seed 1."""
    return rotorid.simulate(table1, snr_db=40, seed=1)


@pytest.fixture(scope="session")
def clean(table1: rotorid.Scenario):
    """table1, exact, 0.2 s."""
    return rotorid.simulate(table1, duration=0.2)
