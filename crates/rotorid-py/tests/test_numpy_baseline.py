"""The numpy/pandas identifier of bench/numpy_identify.py (the baseline of the speed
comparison) against rotorid's algebraic identifier with the same quadrature: two
independent implementations of docs/method.md section 3 agree, so the benchmark compares
like with like."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np

import rotorid

ROOT = Path(__file__).resolve().parents[3]


def _baseline():
    spec = importlib.util.spec_from_file_location("numpy_identify", ROOT / "bench" / "numpy_identify.py")
    mod = importlib.util.module_from_spec(spec)
    assert spec.loader is not None
    spec.loader.exec_module(mod)
    return mod


def test_the_numpy_identifier_equals_rotorid_with_the_trapezoid_rule():
    sc = rotorid.Scenario.table1()
    for snr in (None, 40.0):
        df = rotorid.simulate(sc, snr_db=snr, seed=3)
        res = rotorid.identify(df, sc, method="algebraic", quadrature="trapezoid")
        est = res.estimates
        r = _baseline().identify(
            df["t"].to_numpy(), df["x"].to_numpy(), df["z"].to_numpy(), df["phi"].to_numpy(),
            df["phi_dot"].to_numpy(), df["phi_ddot"].to_numpy(),
            2.871, 1e-4 * 0.15, np.pi / 4,
        )
        # from 10 ms on (the first instants are singular or ill-conditioned)
        keep = est["t"].to_numpy() >= 0.01
        for d, cols in (("x", ("m_x", "c_x", "k_x")), ("z", ("m_z", "c_z", "k_z"))):
            for j, c in enumerate(cols):
                ours = est[c].to_numpy()[keep]
                theirs = r[d][keep, j]
                ok = np.isfinite(ours)
                assert ok.mean() > 0.9, (snr, c)
                rel = np.abs(ours[ok] - theirs[ok]) / np.abs(theirs[ok])
                # clean: round-off only; noisy: the same noise through the same equations
                # (the damping, a small term of the 3x3 systems, loses more digits)
                tol = 1e-5 if c.startswith("c") else 1e-7
                assert np.max(rel) < tol, (snr, c, np.max(rel))
