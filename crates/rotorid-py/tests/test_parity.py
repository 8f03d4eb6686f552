"""The Python package and the `rotorid` command give the same results for the same file
and options: `to_dict()` equals SUMMARY.json, `estimates` equals the estimates CSV, and
`simulate` equals `rotorid simulate`'s CSV, bit for bit."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from pandas.testing import assert_frame_equal

import rotorid
from conftest import run

RAMP_TOML = """\
[rotor]
m = 14.29
cx = 10.0
cz = 12.0
kx = 1.195e6
kz = 1.3e6
a = 2.871
m_u = 1.0e-4
d = 0.15
alpha_deg = 45.0

[speed]
kind = "ramp"
rpm0 = 600.0
accel = 40.0

[sampling]
dt = 1.0e-4
duration = 0.5

[initial]
x = 1.0e-5
"""

# (method, options) as keyword arguments; the CLI gets them as flags.
CASES = [
    ("algebraic", {}),
    ("algebraic", {"quadrature": "trapezoid", "tol": 0.05, "rcond_min": 1e-6}),
    ("algebraic", {"restart": 0.05}),
    ("modulating", {}),
    ("modulating", {"window": 0.03}),
    ("refine", {}),
    ("refine", {"unknowns": ["m", "cx", "kx", "cz", "kz", "unbalance"]}),
]


def read_estimates(path: Path) -> pd.DataFrame:
    """The CLI's estimates CSV with Python's exact float parser (empty fields: NaN)."""
    with path.open() as f:
        rows = list(csv.reader(f))
    cols = list(zip(*rows[1:])) if len(rows) > 1 else [()] * len(rows[0])
    return pd.DataFrame({
        name: np.array([float(v) if v else math.nan for v in col], dtype=np.float64)
        for name, col in zip(rows[0], cols)
    })


def flags(options: dict) -> list[str]:
    out = []
    for k, v in options.items():
        out += [f"--{k.replace('_', '-')}", ",".join(v) if isinstance(v, list) else str(v)]
    return out


@pytest.fixture(scope="module")
def records(cli: str, tmp_path_factory: pytest.TempPathFactory) -> dict[str, tuple[Path, str]]:
    """Records written by `rotorid simulate`, with the scenario argument each needs."""
    d = tmp_path_factory.mktemp("records")
    ramp = d / "ramp.toml"
    ramp.write_text(RAMP_TOML)
    noisy = d / "noisy.csv"
    run(cli, "simulate", "--scenario", "table1", "--snr-db", "40", "--seed", "1", "--out", str(noisy), "-q")
    ramped = d / "ramp.csv"
    run(cli, "simulate", "--scenario", str(ramp), "--snr-db", "50", "--seed", "2", "--out", str(ramped), "-q")
    # The same noisy record without the speed columns: the scenario's profile gives it.
    lines = noisy.read_text().splitlines()
    no_phi = d / "no_phi.csv"
    no_phi.write_text("\n".join(",".join(line.split(",")[:3]) for line in lines) + "\n")
    return {
        "noisy": (noisy, "table1"),
        "ramp": (ramped, str(ramp)),
        "no_phi": (no_phi, "table1"),
    }


@pytest.mark.parametrize("record", ["noisy", "ramp", "no_phi"])
@pytest.mark.parametrize("method,options", CASES, ids=[f"{m}{i}" for i, (m, _) in enumerate(CASES)])
def test_summary_and_estimates_equal_the_clis(cli, records, tmp_path, record, method, options):
    path, scenario = records[record]
    summary, estimates = tmp_path / "summary.json", tmp_path / "estimates.csv"
    run(cli, "identify", str(path), "--scenario", scenario, "--method", method, *flags(options),
        "--out", str(estimates), "--summary", str(summary), "-q")
    res = rotorid.identify(rotorid.read(path), rotorid.Scenario.load(scenario), method=method,
                           input=str(path), scenario=scenario, **options)
    assert res.to_dict() == json.loads(summary.read_text())
    assert_frame_equal(res.estimates, read_estimates(estimates), check_exact=True)
    assert res.warnings == [d["message"] for d in res.to_dict()["diagnostics"]]


def test_simulate_equals_the_clis_csv(cli, records, table1):
    assert_frame_equal(rotorid.simulate(table1, snr_db=40, seed=1), rotorid.read(records["noisy"][0]),
                       check_exact=True)
    ramp_csv, ramp_toml = records["ramp"]
    sc = rotorid.Scenario.from_toml(ramp_toml)
    assert_frame_equal(rotorid.simulate(sc, snr_db=50, seed=2), rotorid.read(ramp_csv), check_exact=True)


def test_a_dataframe_in_memory_gives_the_files_result(records, table1, noisy):
    path, _ = records["noisy"]
    from_file = rotorid.identify(rotorid.read(path), table1, method="refine")
    in_memory = rotorid.identify(noisy, table1, method="refine")
    assert in_memory.to_dict() == from_file.to_dict()
    as_dict = rotorid.identify({k: noisy[k].to_numpy() for k in noisy.columns}, table1, method="refine")
    assert as_dict.to_dict() == from_file.to_dict()


def test_summary_names_input_and_scenario_only_when_given(noisy, table1):
    d = rotorid.identify(noisy, table1, method="modulating").to_dict()
    assert d["input"] is None and d["scenario"] is None
    d = rotorid.identify(noisy, table1, method="modulating", input="run.csv", scenario="table1").to_dict()
    assert (d["input"], d["scenario"]) == ("run.csv", "table1")
