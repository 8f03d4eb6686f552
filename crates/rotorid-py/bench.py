"""Benchmark of the Python layer: what a call costs beyond the library's own work, and
what a thread pool gains.

    python crates/rotorid-py/bench.py [--repeat 5]

For each case the same record is identified through ``rotorid.identify`` (wall time of
the Python call: DataFrame columns to arrays, the GIL released, the result's summary and
estimates handed back) and the library time is the time the Rust core spends in the same
call with no conversion (``Identification.core_seconds``, measured inside the extension
around the pipeline). Overhead = (Python call - library) / library, median over repeats.
Then records are identified serially and on a thread pool of 2 (the speed-up needs an
otherwise idle machine; CPU/wall near 2 shows both threads computing at once).
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


def speedup(name: str, records, sc, method: str, repeat: int) -> None:
    def job(df):
        return rotorid.identify(df, sc, method=method)

    serial, pooled, cpu = [], [], []
    with ThreadPoolExecutor(max_workers=2) as pool:
        for _ in range(repeat):
            start = time.perf_counter()
            for df in records:
                job(df)
            serial.append(time.perf_counter() - start)
            start, c0 = time.perf_counter(), time.process_time()
            list(pool.map(job, records))
            pooled.append(time.perf_counter() - start)
            cpu.append((time.process_time() - c0) / pooled[-1])
    s, p = statistics.median(serial), statistics.median(pooled)
    print(f"{name:36s} serial {s * 1e3:9.1f} ms   thread pool of 2 {p * 1e3:9.1f} ms   "
          f"speed-up {s / p:4.2f} (CPU/wall {statistics.median(cpu):.2f}; {os.cpu_count()} cores, "
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
    refines = [rotorid.simulate(sc, snr_db=40, seed=s) for s in range(16)]
    speedup("16 refines, 1 s at 10 kHz each", refines, sc, "refine", a.repeat)
    long = [rotorid.simulate(sc, snr_db=40, seed=s, duration=30.0) for s in range(4)]
    speedup("4 algebraic, 300 k samples each", long, sc, "algebraic", a.repeat)


if __name__ == "__main__":
    main()
