"""Benchmark of the Python layer: what a call costs beyond the library's own work, and
what a thread pool gains.

    python crates/rotorid-py/bench.py [--repeat 5]

For each case the same record is identified through ``rotorid.identify`` (wall time of
the Python call: DataFrame columns to arrays, the GIL released, the result's summary and
estimates handed back) and the library time is the time the Rust core spends in the same
call with no conversion (``Identification.core_seconds``, measured inside the extension
around the pipeline). Overhead = (Python call - library) / library, median over repeats.
Then 8 refines run serially and on a thread pool of 2.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from concurrent.futures import ThreadPoolExecutor

import rotorid


def overhead(name: str, df, sc, method: str, repeat: int, estimates: bool) -> None:
    calls, cores, with_table = [], [], []
    for _ in range(repeat):
        start = time.perf_counter()
        res = rotorid.identify(df, sc, method=method)
        calls.append(time.perf_counter() - start)
        if estimates:
            _ = res.estimates  # the per-sample DataFrame, built on first access
            with_table.append(time.perf_counter() - start)
        cores.append(res.core_seconds)
    call, core = statistics.median(calls), statistics.median(cores)
    line = (f"{name:36s} library {core * 1e3:9.2f} ms   Python call {call * 1e3:9.2f} ms   "
            f"overhead {100 * (call - core) / core:5.2f} %")
    if estimates:
        table = statistics.median(with_table)
        line += f"   (+ estimates DataFrame: {100 * (table - core) / core:5.2f} %)"
    print(line)


def speedup(sc, repeat: int) -> None:
    records = [rotorid.simulate(sc, snr_db=40, seed=s) for s in range(8)]

    def job(df):
        return rotorid.identify(df, sc, method="refine").core_seconds

    serial, pooled = [], []
    with ThreadPoolExecutor(max_workers=2) as pool:
        for _ in range(repeat):
            start = time.perf_counter()
            for df in records:
                job(df)
            serial.append(time.perf_counter() - start)
            start = time.perf_counter()
            list(pool.map(job, records))
            pooled.append(time.perf_counter() - start)
    s, p = statistics.median(serial), statistics.median(pooled)
    print(f"{'8 refines (1 s at 10 kHz)':36s} serial {s * 1e3:9.1f} ms   thread pool of 2 "
          f"{p * 1e3:9.1f} ms   speed-up {s / p:4.2f} ({os.cpu_count()} cores; "
          f"load average {os.getloadavg()[0]:.1f})")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=5)
    a = ap.parse_args()
    sc = rotorid.Scenario.table1()
    million = rotorid.simulate(sc, snr_db=40, seed=1, duration=99.9999)  # 1 000 000 samples
    assert len(million) == 1_000_000, len(million)
    second = rotorid.simulate(sc, snr_db=40, seed=1)
    overhead("algebraic, 1 M samples", million, sc, "algebraic", a.repeat, estimates=True)
    overhead("refine, 1 s at 10 kHz", second, sc, "refine", a.repeat, estimates=False)
    overhead("modulating, 1 M samples", million, sc, "modulating", a.repeat, estimates=False)
    speedup(sc, a.repeat)


if __name__ == "__main__":
    main()
