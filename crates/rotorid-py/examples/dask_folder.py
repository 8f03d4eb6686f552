"""Identify every response CSV of a folder in parallel with dask.delayed.

    python dask_folder.py RECORDS/ --scenario table1 --method refine [--workers 2]

Each record is read and identified in its own task; rotorid releases the GIL while the
library computes, so dask's threaded scheduler runs the records on all cores without
copying them between processes. Prints one row per record: each parameter's value and
standard error [SI units], and the number of warnings.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import dask
import pandas as pd

import rotorid


def identify_one(path: Path, scenario: str, method: str, options: dict[str, Any]) -> dict[str, Any]:
    """One record's row: value and std_error of each parameter, warnings."""
    res = rotorid.identify(
        rotorid.read(path), rotorid.Scenario.load(scenario), method=method,
        input=str(path), scenario=scenario, **options,
    )
    row: dict[str, Any] = {"record": path.name}
    for name, p in res.params.iterrows():
        row[name] = p["value"]
        row[f"{name}_std"] = p["std_error"]
    row["warnings"] = len(res.warnings)
    return row


def identify_folder(
    folder: str | Path,
    scenario: str = "table1",
    method: str = "refine",
    *,
    pattern: str = "*.csv",
    workers: int | None = None,
    **options: Any,
) -> pd.DataFrame:
    """Identify every file of `folder` matching `pattern`, in parallel (dask threads).

    Args:
        folder: the records (response CSVs as ``rotorid simulate`` writes them).
        scenario: ``"table1"`` or the path of a TOML scenario (loaded in each task).
        method: ``"algebraic"``, ``"modulating"`` or ``"refine"``.
        workers: threads (default: dask's, one per core).
        options: keyword arguments of :func:`rotorid.identify` (unknowns, window, ...).

    Returns:
        DataFrame indexed by record file name.
    """
    paths = sorted(Path(folder).glob(pattern))
    if not paths:
        raise FileNotFoundError(f"no {pattern} in {folder}")
    tasks = [dask.delayed(identify_one)(p, scenario, method, options) for p in paths]
    rows = dask.compute(*tasks, scheduler="threads", num_workers=workers)
    return pd.DataFrame(list(rows)).set_index("record")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder")
    ap.add_argument("--scenario", default="table1")
    ap.add_argument("--method", default="refine", choices=rotorid.METHODS)
    ap.add_argument("--workers", type=int, default=None)
    a = ap.parse_args()
    table = identify_folder(a.folder, a.scenario, a.method, workers=a.workers)
    with pd.option_context("display.width", 200, "display.max_columns", 30):
        print(table)


if __name__ == "__main__":
    main()
