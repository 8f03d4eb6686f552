"""Reads the files tests/writers.rs wrote (w.npz, w.mat, w.parquet in DIR) with numpy,
scipy.io.loadmat and pyarrow, and checks them against the values the test wrote (the same
formula, recomputed here)."""
import sys

import numpy as np
import pyarrow.parquet as pq
import scipy.io

d = sys.argv[1]
n = 1000
t = np.arange(n) / 2048.0
x = 1e-5 * np.sin(2 * np.pi * 25.0 * t)
z = -1e-5 * np.cos(2 * np.pi * 25.0 * t)
z[3], z[4] = np.nan, np.inf
speed = np.resize(np.array([np.finfo(float).max, np.finfo(float).tiny, -0.0, 5e-324]), n)
want = {"t": t, "x": x, "rec.z": z, "rec.speed": speed}


def check(name, got, ref, tol):
    got = np.asarray(got, dtype=np.float64).ravel()
    assert got.shape == ref.shape, (name, got.shape)
    # Rust's sin/cos and numpy's may differ in the last bit: the formula is checked to 1e-15
    # relative, the constants and t bit for bit.
    if tol == 0:
        assert np.array_equal(got.view(np.uint64), ref.view(np.uint64)) or np.array_equal(got, ref, equal_nan=True), name
    else:
        assert np.allclose(got, ref, rtol=tol, atol=0, equal_nan=True), name


def tol(k):
    return 1e-15 if k in ("x", "rec.z") else 0


npz = np.load(f"{d}/w.npz")
assert list(npz.files) == ["t", "x", "rec.z", "rec.speed"], npz.files
for k, v in want.items():
    check(f"npz {k}", npz[k], v, tol(k))

m = scipy.io.loadmat(f"{d}/w.mat")
assert m["t"].shape == (n, 1)
check("mat t", m["t"], t, 0)
check("mat x", m["x"], x, tol("x"))
rec = m["rec"][0, 0]
check("mat rec.z", rec["z"], z, tol("rec.z"))
check("mat rec.speed", rec["speed"], speed, 0)

p = pq.read_table(f"{d}/w.parquet")
assert p.column_names == ["t", "x", "rec.z", "rec.speed"], p.column_names
for k, v in want.items():
    check(f"parquet {k}", p.column(k).to_numpy(), v, tol(k))
print("numpy, scipy.io.loadmat and pyarrow read back w.npz, w.mat, w.parquet: ok")
