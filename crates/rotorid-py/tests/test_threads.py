"""The GIL is released while the library computes: refines run concurrently from a thread
pool, give the serial results, and the speed-up is reported (not asserted)."""

from __future__ import annotations

import os
import time
from concurrent.futures import ThreadPoolExecutor

import pytest

import rotorid


@pytest.fixture(scope="module")
def records(table1):
    return [rotorid.simulate(table1, snr_db=40, seed=s) for s in range(4)]


def test_two_refines_run_concurrently(records, table1, capsys):
    def job(df):
        return rotorid.identify(df, table1, method="refine").to_dict()

    start = time.perf_counter()
    serial = [job(df) for df in records]
    t_serial = time.perf_counter() - start
    with ThreadPoolExecutor(max_workers=2) as pool:
        start = time.perf_counter()
        parallel = list(pool.map(job, records))
        t_parallel = time.perf_counter() - start
    assert parallel == serial
    with capsys.disabled():
        print(f"\n[threads] 4 refines of 1 s at 10 kHz: serial {t_serial:.3f} s, thread pool of 2 "
              f"{t_parallel:.3f} s: speed-up {t_serial / t_parallel:.2f} on {os.cpu_count()} cores")


def test_the_gil_is_free_during_a_call(records, table1):
    """While a call runs in another thread, this thread keeps running Python code."""
    big = rotorid.simulate(table1, duration=20.0)  # 200001 samples: long enough a call
    ticks = 0
    with ThreadPoolExecutor(max_workers=1) as pool:
        f = pool.submit(rotorid.identify, big, table1, method="algebraic")
        while not f.done():
            ticks += 1
        f.result()
    assert ticks > 1000
